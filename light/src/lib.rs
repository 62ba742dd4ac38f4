//! Producing the light a baked file is shaded with ([`trisort_format::Environment`]): an
//! equirectangular HDR image prefiltered for the GGX specular lobe, with its diffuse
//! irradiance projected onto order-2 spherical harmonics ([`from_equirect`]), and the built-in
//! procedural photo studio ([`studio`]).
//!
//! Readers of a baked file need only the stored light and the evaluation functions of
//! `trisort-format` (texel lookups, [`Environment::irradiance`]); this crate is for what makes
//! one: the pipeline, the HDR loader of `trisort-scene`, and the validator, which compares a
//! file's claimed studio with the studio made anew. It depends on `trisort-format` alone, so
//! none of them pulls in the glTF importer for it.
//!
//! [`from_equirect`] resamples the image to [`WORKING_WIDTH`] × [`WORKING_HEIGHT`], prefilters
//! [`LEVELS`] levels and projects the irradiance (`image.rs`: the working image; `prefilter.rs`:
//! GGX importance sampling; `sh.rs`: the projection's deringing; `studio.rs`: the studio).
#![deny(missing_docs)]

mod image;
mod prefilter;
mod sh;
mod studio;

use trisort_format::Environment;

pub use studio::studio;

use image::Image;
use prefilter::{level_plan, prefilter};
use sh::dering;

/// Width of level 0 of an environment made by [`from_equirect`].
pub const WORKING_WIDTH: u32 = 128;
/// Height of level 0 of an environment made by [`from_equirect`].
pub const WORKING_HEIGHT: u32 = 64;
/// Levels of an environment made by [`from_equirect`]: perceptual roughness 0,
/// 0.2, …, 1; the last is 4 × 2 texels.
pub const LEVELS: usize = 6;
/// Brightest texel [`from_equirect`] accepts: sums of 2^26 of them stay finite.
const MAX_RADIANCE: f32 = 1e30;
/// Largest finite binary16: brighter texels are stored as this.
pub(crate) const HALF_MAX: f32 = 65504.0;
/// binary16 bits of 1.0.
pub(crate) const HALF_ONE: u16 = 0x3c00;

/// An environment from an equirectangular linear-RGB image of `width` × `height` texels
/// (`rgb`: 3 floats per texel, row 0 at the zenith, column x at `φ = 2π (x + 0.5) / width`,
/// the layout described on [`Environment`]), named `name`, with no sun and exposure 1.
///
/// The image is resampled (box filter) to [`WORKING_WIDTH`] × [`WORKING_HEIGHT`], which
/// is level 0; level k (1 ≤ k < [`LEVELS`]) is the radiance prefiltered for perceptual
/// roughness `k / (LEVELS − 1)` by GGX importance sampling (normal = view = reflection,
/// Hammersley points, each sample read from a mip of level 0 whose texels match the
/// sample's solid angle, weighted by N·L); [`Environment::sh`] is the cosine-convolved
/// irradiance of level 0, deringed where a concentrated source (a sun) would make it dip
/// below the darkest texel. Texels brighter than binary16's largest value (65504) are stored
/// as that. The result is the same bytes on every run on one platform (one thread, fixed
/// order; `sin`, `acos`… come from the platform's math library, which may round the last
/// bit differently elsewhere).
///
/// Fails, saying why, on an empty image, a length that is not `width × height × 3`, or a
/// texel that is NaN, infinite, negative or above 10³⁰.
pub fn from_equirect(
    name: &str,
    width: u32,
    height: u32,
    rgb: &[f32],
) -> Result<Environment, String> {
    if width == 0 || height == 0 {
        return Err(format!("the image is empty ({width}×{height} texels)"));
    }
    let expected = width as u64 * height as u64 * 3;
    if rgb.len() as u64 != expected {
        return Err(format!(
            "the image has {} values, but {width}×{height} RGB texels are {expected}",
            rgb.len()
        ));
    }
    if let Some(i) = rgb
        .iter()
        .position(|v| !(v.is_finite() && (0.0..=MAX_RADIANCE).contains(v)))
    {
        let texel = i as u64 / 3;
        let what = match rgb[i] {
            v if v.is_nan() => "NaN".to_string(),
            v if v.is_infinite() => "infinite".to_string(),
            v if v < 0.0 => format!("negative ({v})"),
            v => format!("{v:e}, above {MAX_RADIANCE:e} (sums of it would overflow)"),
        };
        return Err(format!(
            "texel ({}, {}) has a {} channel that is {what}: an environment needs finite, \
             non-negative radiance",
            texel % width as u64,
            texel / width as u64,
            ["red", "green", "blue"][i % 3]
        ));
    }
    let base = Image::resample(width, height, rgb, WORKING_WIDTH, WORKING_HEIGHT);
    let mips = base.mip_chain();
    let mut levels = vec![base.to_half()];
    for k in 1..LEVELS {
        let roughness = k as f32 / (LEVELS - 1) as f32;
        let w = (WORKING_WIDTH >> k).max(1);
        let h = (WORKING_HEIGHT >> k).max(1);
        // Each stored texel averages the filtered light over its area (a texel at its
        // centre's value alone would brighten the coarse levels: a 4 × 2 level's top row,
        // at 45°, sees the overhead light better than its hemisphere does).
        let (fw, fh, samples) = level_plan(k);
        let mut level = prefilter(&mips, roughness, fw, fh, samples);
        while level.width > w || level.height > h {
            level = level.half();
        }
        levels.push(level.to_half());
    }
    Ok(Environment {
        name: name.to_string(),
        width: WORKING_WIDTH,
        height: WORKING_HEIGHT,
        levels,
        sh: dering(base.irradiance_sh(), base.min_radiance()),
        sun: None,
        exposure: 1.0,
    })
}

/// binary16 bits of `v` (round to nearest even; overflow to infinity).
pub(crate) fn half_bits(v: f32) -> u16 {
    half::f16::from_f32(v).to_bits()
}

/// `v` scaled to unit length.
pub(crate) fn normalize(v: [f32; 3]) -> [f32; 3] {
    let l = dot(v, v).sqrt();
    v.map(|c| c / l)
}

/// The dot product of `a` and `b`.
pub(crate) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use trisort_format::environment::{row_solid_angle, texel_direction};

    use super::*;
    use crate::studio::studio_radiance;

    fn close(a: f32, b: f32, rel: f32) -> bool {
        (a - b).abs() <= rel * b.abs().max(1e-6)
    }

    /// Directions spread over the sphere (including the poles and the seam at φ = 0).
    fn directions() -> Vec<[f32; 3]> {
        let mut d = vec![
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, -1.0],
        ];
        for i in 0..40 {
            let t = (i as f32 + 0.5) / 40.0;
            let (theta, phi) = ((1.0 - 2.0 * t).acos(), i as f32 * 2.399_963);
            d.push([
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ]);
        }
        d
    }

    /// An image of `w` × `h` texels with radiance `f(direction)`.
    fn image(w: u32, h: u32, f: impl Fn([f32; 3]) -> [f32; 3]) -> Vec<f32> {
        let mut rgb = Vec::new();
        for y in 0..h {
            for x in 0..w {
                rgb.extend(f(texel_direction(x, y, w, h)));
            }
        }
        rgb
    }

    #[test]
    fn uniform_stays_uniform_at_every_level_and_in_the_sh() {
        let rgb = image(300, 150, |_| [0.7, 1.5, 3.0]);
        let env = from_equirect("grey", 300, 150, &rgb).unwrap();
        env.check_structure().unwrap();
        for k in 0..LEVELS {
            let (w, h) = env.level_size(k);
            for y in 0..h {
                for x in 0..w {
                    let t = env.texel(k, x, y);
                    // binary16 holds these within 1/2048.
                    for (got, want) in t.iter().zip([0.7, 1.5, 3.0]) {
                        assert!(close(*got, want, 1e-3), "level {k} ({x}, {y}): {t:?}");
                    }
                }
            }
        }
        for n in directions() {
            let e = env.irradiance(n);
            for (got, want) in e.iter().zip([0.7, 1.5, 3.0]) {
                assert!(close(*got, want, 2e-3), "normal {n:?}: {e:?}");
            }
        }
        // The one-texel uniform environment agrees.
        let u = Environment::uniform(0.7);
        assert!(close(u.irradiance([0.3, -0.8, 0.52])[0], 0.7, 1e-5));
    }

    #[test]
    fn sky_brighter_above_gives_more_irradiance_upwards() {
        // Radiance 2 above the horizon, 0.5 below. Irradiance / π at angle θ from the zenith
        // is 0.5 + 1.5 (1 + cos θ) / 2 exactly, linear in cos θ, so SH9 holds it (the step's
        // band-2 part is zero) up to the discretisation of the image.
        let rgb = image(128, 64, |d| if d[1] > 0.0 { [2.0; 3] } else { [0.5; 3] });
        let env = from_equirect("sky", 128, 64, &rgb).unwrap();
        let up = env.irradiance([0.0, 1.0, 0.0])[0];
        let side = env.irradiance([1.0, 0.0, 0.0])[0];
        let down = env.irradiance([0.0, -1.0, 0.0])[0];
        assert!(
            up > side && side > down,
            "up {up}, side {side}, down {down}"
        );
        assert!(close(up, 2.0, 0.01), "up {up}");
        assert!(close(side, 1.25, 0.01), "side {side}");
        assert!(close(down, 0.5, 0.02), "down {down}");
        // The prefiltered levels keep the sky above brighter than the floor below.
        for k in 0..LEVELS {
            let (w, h) = env.level_size(k);
            assert!(
                env.texel(k, 0, 0)[0] > env.texel(k, w - 1, h - 1)[0],
                "level {k}"
            );
        }
    }

    #[test]
    fn a_sun_does_not_ring_the_irradiance_below_the_sky() {
        let sun = normalize([0.5, 0.5, 0.2]);
        let sky = |d: [f32; 3]| {
            if dot(d, sun) > 0.999 {
                [20000.0, 18000.0, 15000.0]
            } else {
                [0.5, 0.6, 0.8]
            }
        };
        let rgb = image(512, 256, sky);
        let env = from_equirect("sun", 512, 256, &rgb).unwrap();
        // Without deringing SH9 gives about −1.2 facing away from this sun.
        let floor = [0.5, 0.6, 0.8];
        for d in directions() {
            let e = env.irradiance(d);
            for c in 0..3 {
                assert!(
                    e[c] >= floor[c] * 0.99 - 0.01 * env.sh[0][c] * 0.282_094_8,
                    "{d:?}: {e:?}"
                );
            }
        }
        assert!(env.irradiance(sun)[0] > 2.0 * env.irradiance(sun.map(|c| -c))[0]);
        // The mean (band 0) is kept.
        let m0 = env.level_mean(0);
        for (sh, mean) in env.sh[0].iter().zip(m0) {
            assert!(close(sh * 0.282_094_8, mean, 0.01));
        }
    }

    #[test]
    fn level_sizes_and_bytes() {
        let env = studio();
        env.check_structure().unwrap();
        assert_eq!((env.width, env.height), (WORKING_WIDTH, WORKING_HEIGHT));
        assert_eq!(env.levels.len(), LEVELS);
        let sizes: Vec<_> = (0..LEVELS).map(|k| env.level_size(k)).collect();
        assert_eq!(
            sizes,
            [(128, 64), (64, 32), (32, 16), (16, 8), (8, 4), (4, 2)]
        );
        for (k, l) in env.levels.iter().enumerate() {
            let (w, h) = sizes[k];
            assert_eq!(l.len(), (w * h * 4) as usize);
            assert!(l.chunks_exact(4).all(|t| t[3] == HALF_ONE), "alpha 1");
        }
        // (8192 + 2048 + 512 + 128 + 32 + 8) texels × 8 bytes.
        assert_eq!(env.texel_bytes(), 10_920 * 8);
        // A tiny input is resampled to the same working size.
        let tiny = from_equirect("tiny", 1, 1, &[0.25, 0.5, 1.0]).unwrap();
        assert_eq!(tiny.levels.len(), LEVELS);
        assert_eq!(tiny.texel_bytes(), env.texel_bytes());
        assert!(close(tiny.texel(5, 3, 1)[2], 1.0, 1e-3));
    }

    #[test]
    fn prefiltering_keeps_the_energy() {
        // A small bright source on a dim background is the hard case (the filtered mips
        // spread it; importance sampling alone would miss or over-count it).
        let sun = normalize([0.3, 0.6, -0.7]);
        let rgb = image(256, 128, |d| {
            let v = if dot(d, sun) > 0.99 { 200.0 } else { 0.2 };
            [v, v * 0.5, 0.2]
        });
        for (name, env) in [
            ("small source", from_equirect("s", 256, 128, &rgb).unwrap()),
            ("studio", studio()),
        ] {
            let m0 = env.level_mean(0);
            for k in 1..LEVELS {
                // Measured: within 0.7 % up to level 4, 2.5 % at the 4 × 2 level 5.
                let m = env.level_mean(k);
                for c in 0..3 {
                    assert!(
                        close(m[c], m0[c], 0.04),
                        "{name} level {k}: {m:?} vs {m0:?}"
                    );
                }
            }
            // The SH's constant term is the mean radiance (irradiance/π of a uniform light).
            for (sh, mean) in env.sh[0].iter().zip(m0) {
                assert!(close(sh * 0.282_094_8, mean, 0.01), "{name}");
            }
        }
    }

    /// The GGX-filtered radiance along `n` by brute force: every texel of `base` weighted by
    /// the filter's kernel, D(h) · N·L · solid angle, h = normalize(n + l) (what importance
    /// sampling estimates).
    fn brute_force(base: &Image, n: [f32; 3], roughness: f32) -> [f32; 3] {
        let a2 = roughness.powi(4);
        let (mut sum, mut weight) = ([0.0f64; 3], 0.0f64);
        for y in 0..base.height {
            let omega = row_solid_angle(y, base.width, base.height);
            for x in 0..base.width {
                let l = texel_direction(x, y, base.width, base.height);
                let n_dot_l = dot(n, l);
                if n_dot_l <= 0.0 {
                    continue;
                }
                let h = normalize([n[0] + l[0], n[1] + l[1], n[2] + l[2]]);
                let c = dot(n, h);
                let denom = c * c * (a2 - 1.0) + 1.0;
                let w = (a2 / (PI * denom * denom) * n_dot_l * omega) as f64;
                let t = base.at(x, y);
                for i in 0..3 {
                    sum[i] += t[i] as f64 * w;
                }
                weight += w;
            }
        }
        sum.map(|s| (s / weight) as f32)
    }

    #[test]
    fn prefiltering_agrees_with_brute_force() {
        let sun = normalize([0.3, 0.6, -0.7]);
        let small = image(256, 128, |d| {
            [if dot(d, sun) > 0.99 { 200.0 } else { 0.2 }; 3]
        });
        let (w, h) = (2 * WORKING_WIDTH, 2 * WORKING_HEIGHT);
        let studio = image(w, h, studio_radiance);
        for (name, w, h, rgb) in [("small source", 256, 128, small), ("studio", w, h, studio)] {
            let base = Image::resample(w, h, &rgb, WORKING_WIDTH, WORKING_HEIGHT);
            let mips = base.mip_chain();
            for k in 1..LEVELS {
                let r = k as f32 / (LEVELS - 1) as f32;
                let filtered = prefilter(&mips, r, 16, 8, level_plan(k).2);
                let (mut worst, mut sq) = (0.0f32, 0.0f32);
                for y in 0..8 {
                    for x in 0..16 {
                        let want = brute_force(&base, texel_direction(x, y, 16, 8), r)[0];
                        let got = filtered.at(x, y)[0];
                        let rel = (got - want).abs() / want;
                        worst = worst.max(rel);
                        sq += rel * rel;
                    }
                }
                let rms = (sq / 128.0).sqrt();
                // Measured: rms 1–3 % and worst 3–12 % from roughness 0.4 up. At 0.2 the lobe
                // is about a texel of level 0 wide, so the brute force (a sum over texels) is
                // itself coarse: rms 5–10 % there.
                let (worst_max, rms_max) = if k == 1 { (1.0, 0.15) } else { (0.15, 0.05) };
                assert!(
                    worst < worst_max && rms < rms_max,
                    "{name} roughness {r}: worst {worst}, rms {rms}"
                );
            }
        }
    }

    #[test]
    fn rougher_levels_are_smoother() {
        let env = studio();
        // Contrast (max / min over the level) falls with roughness.
        let contrast = |k: usize| {
            let (w, h) = env.level_size(k);
            let v: Vec<f32> = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| env.texel(k, x, y)[1])
                .collect();
            v.iter().cloned().fold(0.0, f32::max) / v.iter().cloned().fold(f32::MAX, f32::min)
        };
        for k in 1..LEVELS {
            assert!(contrast(k) < contrast(k - 1), "level {k}");
        }
    }

    #[test]
    fn studio_reads_well_and_is_deterministic() {
        let env = studio();
        assert_eq!(env.name, "studio");
        assert_eq!(env.exposure, 1.0);
        let sun = env.sun.expect("the studio has a sun");
        assert!(close(dot(sun.direction, sun.direction), 1.0, 1e-5));
        assert!(sun.direction[1] > 0.5 && sun.direction[0] < 0.0 && sun.direction[2] > 0.0);
        // Lit from above: up more than sideways more than down, all of it neutral enough.
        let up = env.irradiance([0.0, 1.0, 0.0]);
        let side = env.irradiance([0.0, 0.0, 1.0]);
        let down = env.irradiance([0.0, -1.0, 0.0]);
        assert!(
            up[1] > side[1] && side[1] > down[1] && down[1] > 0.0,
            "{up:?} {side:?} {down:?}"
        );
        // The same bytes when computed again from scratch (not the cached copy).
        let (w, h) = (2 * WORKING_WIDTH, 2 * WORKING_HEIGHT);
        let rgb = image(w, h, studio_radiance);
        let again = from_equirect("studio", w, h, &rgb).unwrap();
        assert_eq!(again.levels, env.levels);
        assert_eq!(again.sh, env.sh);
    }

    #[test]
    fn bad_images_are_refused() {
        let mut rgb = vec![1.0f32; 4 * 2 * 3];
        rgb[3 * 5 + 1] = f32::NAN;
        let e = from_equirect("x", 4, 2, &rgb).unwrap_err();
        assert!(
            e.contains("texel (1, 1)") && e.contains("green") && e.contains("NaN"),
            "{e}"
        );
        rgb[3 * 5 + 1] = f32::INFINITY;
        let e = from_equirect("x", 4, 2, &rgb).unwrap_err();
        assert!(e.contains("infinite"), "{e}");
        rgb[3 * 5 + 1] = -0.5;
        let e = from_equirect("x", 4, 2, &rgb).unwrap_err();
        assert!(e.contains("negative (-0.5)"), "{e}");
        rgb[3 * 5 + 1] = 3e38;
        let e = from_equirect("x", 4, 2, &rgb).unwrap_err();
        assert!(e.contains("3e38, above 1e30"), "{e}");
        rgb[3 * 5 + 1] = 1e30;
        from_equirect("x", 4, 2, &rgb)
            .unwrap()
            .check_structure()
            .unwrap();
        let e = from_equirect("x", 4, 2, &rgb[..5]).unwrap_err();
        assert!(e.contains("has 5 values"), "{e}");
        let e = from_equirect("x", 0, 2, &[]).unwrap_err();
        assert!(e.contains("empty"), "{e}");
    }

    #[test]
    fn brighter_than_half_is_clamped_not_infinite() {
        let rgb = image(8, 4, |_| [1e6, 1.0, 0.0]);
        let env = from_equirect("hot", 8, 4, &rgb).unwrap();
        env.check_structure().unwrap();
        assert_eq!(env.texel(0, 0, 0)[0], HALF_MAX);
        assert!(env.sh[0][0].is_finite() && env.sh[0][0] > 1e6);
    }
}
