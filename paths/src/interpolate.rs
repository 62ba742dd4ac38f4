//! Keyframe tracks of the TOML path format: values at (possibly fractional) frame positions,
//! interpolated by one of four modes. Every mode reproduces the key values exactly at the key
//! positions and holds the first / last value before the first / after the last key.

use serde::Deserialize;

/// How a keyframe track moves between its keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum Interpolation {
    /// Straight lines between keys: constant speed, a kink at every key.
    #[default]
    Linear,
    /// A Catmull-Rom spline through the keys (cubic Hermite with tangents
    /// `(p[k+1] − p[k−1]) / (t[k+1] − t[k−1])`, one-sided at the ends): smooth through every
    /// key, may overshoot between keys whose neighbours differ.
    CatmullRom,
    /// Each segment eased with smoothstep `3s² − 2s³`: stops at every key, never overshoots.
    EaseInOut,
    /// Holds each key's value until the next key.
    Step,
}

/// A track of `N`-component values at strictly ascending positions (frames).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Track<const N: usize> {
    /// (position, value), positions strictly ascending; never empty.
    keys: Vec<(f64, [f64; N])>,
    mode: Interpolation,
}

impl<const N: usize> Track<N> {
    /// A track through `keys`. Requires at least one key and strictly ascending, finite
    /// positions (the TOML reader sorts keys and rejects duplicates before calling this).
    pub(crate) fn new(keys: Vec<(f64, [f64; N])>, mode: Interpolation) -> Self {
        debug_assert!(!keys.is_empty(), "a track needs a key");
        debug_assert!(
            keys.windows(2).all(|w| w[0].0 < w[1].0),
            "key positions must ascend strictly"
        );
        Track { keys, mode }
    }

    /// The position of the last key.
    pub(crate) fn last_position(&self) -> f64 {
        self.keys[self.keys.len() - 1].0
    }

    /// The value at position `t`. O(log keys).
    pub(crate) fn sample(&self, t: f64) -> [f64; N] {
        let keys = &self.keys;
        let n = keys.len();
        if t <= keys[0].0 {
            return keys[0].1;
        }
        if t >= keys[n - 1].0 {
            return keys[n - 1].1;
        }
        // Segment k: keys[k].0 <= t < keys[k + 1].0 (so a key position selects the segment that
        // starts there, and s = 0 exactly).
        let k = keys.partition_point(|key| key.0 <= t) - 1;
        let (t0, p0) = keys[k];
        let (t1, p1) = keys[k + 1];
        let dt = t1 - t0;
        let s = (t - t0) / dt;
        match self.mode {
            Interpolation::Step => p0,
            Interpolation::Linear => lerp(&p0, &p1, s),
            Interpolation::EaseInOut => lerp(&p0, &p1, s * s * (3.0 - 2.0 * s)),
            Interpolation::CatmullRom => {
                let m0 = self.tangent(k);
                let m1 = self.tangent(k + 1);
                let mut out = [0.0; N];
                let (s2, s3) = (s * s, s * s * s);
                let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
                let h10 = s3 - 2.0 * s2 + s;
                let h01 = -2.0 * s3 + 3.0 * s2;
                let h11 = s3 - s2;
                for c in 0..N {
                    out[c] = h00 * p0[c] + h10 * dt * m0[c] + h01 * p1[c] + h11 * dt * m1[c];
                }
                out
            }
        }
    }

    /// Catmull-Rom tangent (per frame) at key `k`.
    fn tangent(&self, k: usize) -> [f64; N] {
        let keys = &self.keys;
        let (a, b) = (k.saturating_sub(1), (k + 1).min(keys.len() - 1));
        let dt = keys[b].0 - keys[a].0;
        let mut m = [0.0; N];
        for (c, m) in m.iter_mut().enumerate() {
            *m = (keys[b].1[c] - keys[a].1[c]) / dt;
        }
        m
    }
}

/// `(1 − s)·a + s·b`, exact at s = 0 and s = 1.
fn lerp<const N: usize>(a: &[f64; N], b: &[f64; N], s: f64) -> [f64; N] {
    let mut out = [0.0; N];
    for c in 0..N {
        out[c] = (1.0 - s) * a[c] + s * b[c];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const MODES: [Interpolation; 4] = [
        Interpolation::Linear,
        Interpolation::CatmullRom,
        Interpolation::EaseInOut,
        Interpolation::Step,
    ];

    fn track(mode: Interpolation) -> Track<2> {
        Track::new(
            vec![
                (0.0, [0.1, -3.0]),
                (3.0, [0.7, 2.5]),
                (4.5, [-1.3, 0.3]),
                (10.0, [2.0, 2.0]),
            ],
            mode,
        )
    }

    #[test]
    fn every_mode_hits_keys_exactly_and_holds_outside() {
        for mode in MODES {
            let t = track(mode);
            for (pos, value) in &t.keys {
                assert_eq!(t.sample(*pos), *value, "{mode:?} at {pos}");
            }
            assert_eq!(t.sample(-5.0), [0.1, -3.0], "{mode:?}");
            assert_eq!(t.sample(11.0), [2.0, 2.0], "{mode:?}");
        }
    }

    #[test]
    fn modes_differ_between_keys() {
        let lin = track(Interpolation::Linear).sample(1.0);
        let ease = track(Interpolation::EaseInOut).sample(1.0);
        let cr = track(Interpolation::CatmullRom).sample(1.0);
        let step = track(Interpolation::Step).sample(1.0);
        assert!((lin[0] - 0.3).abs() < 1e-12, "{lin:?}");
        // smoothstep(1/3) = 7/27
        assert!(
            (ease[0] - (0.1 + 0.6 * 7.0 / 27.0)).abs() < 1e-12,
            "{ease:?}"
        );
        assert_eq!(step, [0.1, -3.0]);
        assert!(cr != lin && cr != ease, "{cr:?}");
    }

    #[test]
    fn ease_in_out_stops_at_keys_and_stays_within_them() {
        let t = track(Interpolation::EaseInOut);
        let eps = 1e-4;
        let v0 = t.sample(3.0)[0];
        let v1 = t.sample(3.0 + eps)[0];
        assert!((v1 - v0).abs() < 1e-6, "zero velocity at a key");
        for i in 0..=300 {
            let p = 3.0 + 1.5 * i as f64 / 300.0;
            let v = t.sample(p)[0];
            assert!((-1.3..=0.7).contains(&v), "{p}: {v}");
        }
    }

    #[test]
    fn catmull_rom_is_smooth_and_linear_on_collinear_keys() {
        // Collinear keys with uneven spacing: the finite-difference tangents are the slope, so
        // the spline is the line itself.
        let t = Track::new(
            vec![(0.0, [0.0]), (1.0, [2.0]), (4.0, [8.0]), (5.0, [10.0])],
            Interpolation::CatmullRom,
        );
        for i in 0..=50 {
            let p = i as f64 * 0.1;
            assert!((t.sample(p)[0] - 2.0 * p).abs() < 1e-12, "{p}");
        }
        // C¹ at an interior key: left and right difference quotients agree.
        let t = track(Interpolation::CatmullRom);
        let h = 1e-6;
        let left = (t.sample(3.0)[0] - t.sample(3.0 - h)[0]) / h;
        let right = (t.sample(3.0 + h)[0] - t.sample(3.0)[0]) / h;
        assert!((left - right).abs() < 1e-4, "{left} {right}");
    }

    #[test]
    fn single_key_holds() {
        for mode in MODES {
            let t = Track::new(vec![(2.0, [5.0])], mode);
            assert_eq!(t.sample(0.0), [5.0]);
            assert_eq!(t.sample(2.0), [5.0]);
            assert_eq!(t.sample(9.0), [5.0]);
            assert_eq!(t.last_position(), 2.0);
        }
    }
}
