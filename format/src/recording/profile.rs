//! What a recording assumes about the rasterizer that plays its bake: the raster profile
//! and how far beyond the recorded sample pattern the recording looks ([`Robust`]).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::{RecordSettings, SettingsError};
use crate::options::{option_enum, OptionValue, ParseOptionError};

/// How far beyond the recorded sample pattern a recording looks (`record --raster-profile
/// NAME`, `--robust N`, `--conservative`, `--robust-tolerance PX`).
///
/// A triangle belongs to V_f when it wins a sample of the recorded pattern. On another
/// rasterizer (other sub-pixel precision, other tie rules, depth taken elsewhere), or with
/// the pattern moved by a fraction of a pixel, a triangle that won no sample can win one; if
/// the frame does not draw it, what lies behind shows through (a hole). Robust recording
/// widens V_f (and E_f, so the extra triangles are ordered) towards "wins a sample on any
/// rasterizer of the [`RasterProfile`]", whose sample placement is the recorded one moved
/// within `tolerance` pixels:
/// - `patterns` N: the union over N sample patterns, the recorded one and N − 1 moved by
///   offsets within ±`tolerance` ([`Robust::offsets`]), for phase 1 (visibility) and phase 2
///   (covered sets, edges, ties; edge weights add up over the patterns);
/// - `conservative`: phase 1 also keeps every triangle whose footprint, grown by
///   `tolerance` in x and y, reaches a sample at a depth (its nearest over the profile's depth
///   box, for corners snapped to the profile's sub-pixel grids) not behind a bound on the
///   nearest opaque surface over that box (the recorder's envelope bound; devices that cannot
///   capture estimate it from the samples nearby), and phase 2 adds the edges of the grown
///   triangles' layers that close no new cycle.
///
/// The recorded pattern stays one of the patterns, so a robust bake is still exact at it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Robust {
    /// Sample patterns unioned (1: the recorded one only).
    pub patterns: u32,
    /// Tolerance in pixels: the jitter of the extra patterns, and how far (in x and y) a
    /// player's sample may lie from the recorded one relative to the exact geometry, besides
    /// the snapping of corners, which the conservative recording adds from the profile (half a
    /// step of its coarsest grid: corners are taken to be rounded to the nearest grid point).
    pub tolerance: f32,
    /// Conservative visibility (grown coverage against the opaque surface's farthest depth
    /// over the profile's depth box) and the grown peel's edges.
    pub conservative: bool,
    /// What the bake assumes about the rasterizer that plays it, besides the tolerance.
    pub profile: RasterProfile,
}

option_enum! {
    /// The named raster profiles (`record --raster-profile NAME`): what a bake assumes about
    /// the rasterizer that plays it ([`RasterProfile`], [`Robust::profile_named`]).
    pub enum ProfileName: "raster profile" {
        /// The recorded pattern only (`--conservative=false`): exact where played as recorded,
        /// and only there.
        Exact = "exact",
            "the recorded pattern only: exact where played as recorded (--conservative=false)";
        /// A conformant GPU (the default): the standard sample locations, corners snapped to
        /// 8 sub-pixel bits (what Mesa's lavapipe reports and its llvmpipe-GL measures; the
        /// player checks any other device at load),
        /// depth at the sample as the Vulkan and GLES specifications ask, and
        /// [`Robust::CONFORMANT_TOLERANCE`] for snapping and transform rounding.
        #[default]
        Conformant = "conformant",
            "a conformant GPU: standard sample locations, 8 sub-pixel bits, depth at the sample";
        /// A conformant GPU that snaps to as little as 4 sub-pixel bits (the Vulkan and GLES
        /// minimum), depth at the sample, [`Robust::SNAP4_TOLERANCE`].
        Snap4 = "snap4",
            "as conformant, but corners snapped to 4 to 8 sub-pixel bits (the API minimum)";
        /// SwiftShader (Chromium's WebGL2 without a GPU): corners snapped to 4 to 8 bits and a
        /// sample's depth taken anywhere in its pixel, ±1/8 px (what SwiftShader was measured to
        /// need: BENCHMARKS.md § Exactness across rasterizers).
        Browser = "browser",
            "SwiftShader's rules (the web build): 4 to 8 bits, depth anywhere in the pixel, 1/8 px";
    }
}

option_enum! {
    /// Where a rasterizer of a [`RasterProfile`] takes a sample's depth.
    pub enum DepthAt: "depth position" {
        /// At the sample, as the Vulkan and GLES specifications ask.
        #[default]
        Sample = "sample", "at the sample (the Vulkan and GLES rule)";
        /// Anywhere in the sample's pixel (SwiftShader takes it at a mirrored offset).
        Pixel = "pixel", "anywhere in the sample's pixel";
    }
}

/// What a bake assumes about the rasterizer that plays it, besides the tolerance
/// ([`Robust::tolerance`]): the recorded sample pattern (the size and sample count of the
/// [`RecordSettings`], at the standard 4× positions), the sub-pixel grids its corners may be
/// snapped to, and where it takes a sample's depth. The conservative recording is exactly as
/// wide as this asks; the player checks the device against it at load.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RasterProfile {
    /// The profile's name ([`ProfileName`]); the fields below are what the recorder used.
    pub name: ProfileName,
    /// The fewest sub-pixel bits a rasterizer of the profile snaps corners to (4..=16).
    pub subpixel_bits_min: u32,
    /// The most sub-pixel bits (at least `subpixel_bits_min`, at most 16). The bound on a
    /// snapped sliver's depth is not monotone in the grid, so the range is stated, not just
    /// its least.
    pub subpixel_bits_max: u32,
    /// Where a sample's depth is taken.
    pub depth_at: DepthAt,
}

impl RasterProfile {
    /// What a device reports against the profile of a bake recorded with `settings`, in
    /// words (empty: nothing reported differs): its sub-pixel precision where known (Vulkan's
    /// `subPixelPrecisionBits`, GL's `GL_SUBPIXEL_BITS`), whether it uses the standard sample
    /// locations where known, and the sample count it plays at. The player adds what its
    /// raster probe measures (`trisort_gpu::raster_probe`); the C API's
    /// `trisort_check_device` takes what the host's API reports.
    pub fn device_differences(
        &self,
        settings: &RecordSettings,
        subpixel_bits: Option<u32>,
        standard_sample_locations: Option<bool>,
        samples: u32,
    ) -> Vec<String> {
        let mut out = vec![];
        if samples != settings.samples {
            out.push(format!(
                "sample count: played at {samples}x, the bake's pattern is {}x",
                settings.samples
            ));
        }
        if let Some(bits) = subpixel_bits {
            if !(self.subpixel_bits_min..=self.subpixel_bits_max).contains(&bits) {
                out.push(format!(
                    "sub-pixel precision: the device reports {bits} bits, the profile `{}` asks {}",
                    self.name,
                    self.bits_text()
                ));
            }
        }
        if standard_sample_locations == Some(false) {
            out.push(
                "sample locations: the device reports non-standard sample locations, the \
                 profile assumes the standard ones"
                    .into(),
            );
        }
        out
    }

    /// How far a corner moves in x and y when a rasterizer of the profile snaps it to its
    /// coarsest grid, rounding to nearest: half a step of 2^−`subpixel_bits_min` px.
    pub fn snap_reach(&self) -> f32 {
        0.5 * 0.5f32.powi(self.subpixel_bits_min as i32)
    }

    /// Checks sub-pixel bits `lo..=hi`: 4 ≤ least ≤ most ≤ 16.
    pub fn check_bits(lo: u32, hi: u32) -> Result<(), SettingsError> {
        if !(4..=16).contains(&lo) || !(lo..=16).contains(&hi) {
            return Err(SettingsError::SubpixelBits(lo, hi));
        }
        Ok(())
    }

    /// Where depth is taken, in words: `at the sample`, `anywhere in the pixel`.
    pub fn depth_text(&self) -> &'static str {
        match self.depth_at {
            DepthAt::Sample => "at the sample",
            DepthAt::Pixel => "anywhere in the pixel",
        }
    }

    /// The sub-pixel bits as words: `8`, `4 to 8`.
    pub fn bits_text(&self) -> String {
        if self.subpixel_bits_min == self.subpixel_bits_max {
            format!("{}", self.subpixel_bits_min)
        } else {
            format!("{} to {}", self.subpixel_bits_min, self.subpixel_bits_max)
        }
    }

    /// The profile a name stands for (its tolerance: [`Robust::profile_named`]).
    pub const fn named(name: ProfileName) -> RasterProfile {
        let (lo, hi, depth_at) = match name {
            ProfileName::Exact | ProfileName::Conformant => (8, 8, DepthAt::Sample),
            ProfileName::Snap4 => (4, 8, DepthAt::Sample),
            ProfileName::Browser => (4, 8, DepthAt::Pixel),
        };
        RasterProfile {
            name,
            subpixel_bits_min: lo,
            subpixel_bits_max: hi,
            depth_at,
        }
    }
}

impl Robust {
    /// The most patterns [`RecordSettings::validate`] accepts.
    pub const MAX_PATTERNS: u32 = 64;
    /// The conformant profile's tolerance, 1/512 px, for f32 vertex transforms: two
    /// conformant devices put the same corner of CarConcept's car tour at 1280×480 at most
    /// 6.3e-4 px apart (twice the largest distance from the exact value over four evaluation
    /// orders, with and without fused multiply-add, each division moved by Vulkan's 2.5 ulp:
    /// `cargo run --release -p trisort-recorder --example transform_spread -- SCENE PATH SIZE`,
    /// BENCHMARKS § Raster profiles), rounded up to a power of two with room for images about
    /// three times as wide (the error grows with the image). The 8-bit snap (1/512 px) is
    /// added by the recorder: a sample's box is ±1/256 px in all.
    pub const CONFORMANT_TOLERANCE: f32 = 1.0 / 512.0;
    /// The `snap4` profile's tolerance: the conformant one (a 4-bit snap adds 1/32 px).
    pub const SNAP4_TOLERANCE: f32 = Robust::CONFORMANT_TOLERANCE;
    /// The `browser` profile's tolerance, 3/32 px: with a 4-bit snap (1/32 px) a sample's box
    /// is ±1/8 px, measured with no hole in SwiftShader
    /// (BENCHMARKS § Exactness across rasterizers).
    pub const BROWSER_TOLERANCE: f32 = 3.0 / 32.0;

    /// Recorded pattern only: a bake exact where it is played as recorded, and only there
    /// (the `exact` profile; `record --conservative=false`).
    pub const OFF: Robust = Robust::profile_named(ProfileName::Exact);
    /// The default of `record`: the conformant-GPU profile ([`ProfileName::Conformant`]):
    /// conservative within ±[`Robust::CONFORMANT_TOLERANCE`] for corners snapped to 8
    /// sub-pixel bits and depth at the sample (BENCHMARKS § Raster profiles for its price and
    /// the holes measured).
    pub const DEFAULT: Robust = Robust::profile_named(ProfileName::Conformant);

    /// The robust settings of a named profile: one pattern; conservative unless `exact`; the
    /// profile's tolerance.
    pub const fn profile_named(name: ProfileName) -> Robust {
        let tolerance = match name {
            // Unused while not conservative; the jitter of `--robust N` patterns (1/8 px).
            ProfileName::Exact => 0.125,
            ProfileName::Conformant => Robust::CONFORMANT_TOLERANCE,
            ProfileName::Snap4 => Robust::SNAP4_TOLERANCE,
            ProfileName::Browser => Robust::BROWSER_TOLERANCE,
        };
        Robust {
            patterns: 1,
            tolerance,
            conservative: !matches!(name, ProfileName::Exact),
            profile: RasterProfile::named(name),
        }
    }

    /// The half-size in pixels (x and y) of the box a player's sample may lie in relative to
    /// the exact geometry: the tolerance plus how far a corner moves when snapped to the
    /// profile's coarsest grid ([`RasterProfile::snap_reach`]). The conservative recording
    /// grows coverage by it.
    pub fn sample_box(&self) -> f32 {
        self.tolerance + self.profile.snap_reach()
    }

    /// The half-size in pixels of the box a sample's depth may be taken in, around the
    /// recorded sample: [`Robust::sample_box`], and half a pixel more where the profile takes
    /// depth anywhere in the pixel ([`DepthAt::Pixel`]).
    pub fn depth_box(&self) -> f32 {
        let pixel = if self.profile.depth_at == DepthAt::Pixel {
            0.5
        } else {
            0.0
        };
        self.sample_box() + pixel
    }

    /// Whether anything beyond the recorded pattern is gathered.
    pub fn is_on(&self) -> bool {
        self.patterns > 1 || self.conservative
    }

    /// The pattern offsets in pixels (x right, y down), the recorded pattern's `[0, 0]` first,
    /// then `patterns − 1` points of the (2, 3) Halton sequence scaled to ±`tolerance`:
    /// deterministic, spread over the square without clumping.
    pub fn offsets(&self) -> Vec<[f64; 2]> {
        fn halton(mut i: u32, base: u32) -> f64 {
            let (mut f, mut r) = (1.0, 0.0);
            while i > 0 {
                f /= base as f64;
                r += f * (i % base) as f64;
                i /= base;
            }
            r
        }
        let t = self.tolerance as f64;
        let mut out = vec![[0.0, 0.0]];
        for k in 1..self.patterns.max(1) {
            out.push([
                (2.0 * halton(k, 2) - 1.0) * t,
                (2.0 * halton(k, 3) - 1.0) * t,
            ]);
        }
        out
    }
}

impl Default for Robust {
    fn default() -> Self {
        Robust::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_profiles_say_what_they_assume_and_bad_bits_are_refused() {
        assert_eq!(
            Robust::DEFAULT,
            Robust::profile_named(ProfileName::Conformant)
        );
        assert_eq!(
            RecordSettings::default().robust.profile.name,
            ProfileName::Conformant
        );
        let c = Robust::DEFAULT;
        assert!(c.conservative && c.tolerance == Robust::CONFORMANT_TOLERANCE);
        assert_eq!(
            (
                c.profile.subpixel_bits_min,
                c.profile.subpixel_bits_max,
                c.profile.depth_at
            ),
            (8, 8, DepthAt::Sample)
        );
        assert!(!Robust::OFF.conservative && Robust::OFF.profile.name == ProfileName::Exact);
        let b = Robust::profile_named(ProfileName::Browser);
        assert_eq!(
            (
                b.profile.subpixel_bits_min,
                b.profile.subpixel_bits_max,
                b.profile.depth_at
            ),
            (4, 8, DepthAt::Pixel)
        );
        // The browser box is ±1/8 px: its tolerance and a 4-bit snap.
        assert_eq!(b.tolerance + 0.5 / 16.0, 0.125);
        assert_eq!("snap4".parse::<ProfileName>(), Ok(ProfileName::Snap4));
        assert!("swiftshader".parse::<ProfileName>().is_err());
        for (lo, hi) in [(3, 8), (8, 4), (4, 17)] {
            let mut s = RecordSettings::default();
            s.robust.profile.subpixel_bits_min = lo;
            s.robust.profile.subpixel_bits_max = hi;
            assert_eq!(s.validate(), Err(SettingsError::SubpixelBits(lo, hi)));
        }
        RecordSettings::default().validate().unwrap();
    }
}
