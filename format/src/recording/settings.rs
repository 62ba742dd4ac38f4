//! Recording settings ([`RecordSettings`]) and why a set of them cannot be recorded
//! ([`SettingsError`]).

use serde::{Deserialize, Serialize};

use super::{RasterProfile, Robust};

/// Recording settings: together with the device they define the *sample pattern* at which a
/// bake is exact.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// MSAA sample count (1 or 4; 4 uses the standard sample positions).
    pub samples: u32,
    /// Accumulated opacity at which a sample counts as saturated (default
    /// [`RecordSettings::DEFAULT_SATURATION`]).
    pub saturation: f32,
    /// Opacity at which transmissive glass is recorded (default 0: see-through).
    pub glass_opacity: f32,
    /// Safety bound on peel layers per frame; a frame that hits it is truncated.
    pub max_layers: u32,
    /// Whether interpenetrating triangles (within a rigid group of nodes) were split along
    /// their intersection before recording (`trisort_intersect::working_geometry`): the
    /// recorded scene, and the one `verify --scene` rebuilds, is then the split one. Default
    /// [`RecordSettings::DEFAULT_SPLIT_INTERSECTIONS`]; `record --keep-intersections` turns
    /// it off.
    pub split_intersections: bool,
    /// Robust recording (`record --robust N`, `--conservative`): visibility and edges gathered
    /// beyond the recorded sample pattern, so that another rasterizer's snapping or a modest
    /// resize opens no hole. Default [`Robust::DEFAULT`].
    pub robust: Robust,
}

impl RecordSettings {
    /// The default size (width, height): `record --size 512x512`.
    pub const DEFAULT_SIZE: (u32, u32) = (512, 512);
    /// The default MSAA sample count.
    pub const DEFAULT_SAMPLES: u32 = 4;
    /// The default saturation threshold.
    pub const DEFAULT_SATURATION: f32 = 0.998;
    /// The default glass opacity (see-through).
    pub const DEFAULT_GLASS_OPACITY: f32 = 0.0;
    /// The default bound on peel layers per frame.
    pub const DEFAULT_MAX_LAYERS: u32 = 256;
    /// Split interpenetrating triangles before recording by default.
    pub const DEFAULT_SPLIT_INTERSECTIONS: bool = true;
    /// The largest width or height [`RecordSettings::validate`] accepts.
    pub const MAX_SIDE: u32 = 16384;

    /// The settings at `size` (width, height) and `samples`, every other setting at its
    /// default.
    pub fn new(size: (u32, u32), samples: u32) -> RecordSettings {
        RecordSettings {
            width: size.0,
            height: size.1,
            samples,
            ..RecordSettings::default()
        }
    }

    /// [`RecordSettings::validate`] for the settings stored in a file (a recording's or a
    /// baked file's `check_structure`), as a structural error: a reader that trusted an
    /// impossible size, sample count, layer count or tolerance would divide by it, allocate by
    /// it or hand it to an image library that asserts on it.
    pub fn check_stored(&self) -> Result<(), crate::StructureError> {
        let s = self;
        if s.width == 0 || s.height == 0 || (s.samples != 1 && s.samples != 4) {
            return Err(crate::Part::Settings.error(format!(
                "settings {}x{} at {} samples are impossible",
                s.width, s.height, s.samples
            )));
        }
        let saturation_ok = s.saturation > 0.0 && s.saturation <= 1.0;
        if !saturation_ok || !(0.0..=1.0).contains(&s.glass_opacity) {
            return Err(crate::Part::Settings.error(format!(
                "saturation {} or glass opacity {} is out of range",
                s.saturation, s.glass_opacity
            )));
        }
        self.validate()
            .map_err(|e| crate::Part::Settings.error(format!("settings are impossible: {e}")))
    }

    /// Checks that the settings can be recorded: size 1..=[`RecordSettings::MAX_SIDE`], 1 or
    /// 4 samples, saturation in (0, 1], glass opacity in [0, 1], at least one layer.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let s = self;
        if s.width == 0 || s.height == 0 || s.width > Self::MAX_SIDE || s.height > Self::MAX_SIDE {
            return Err(SettingsError::Size(s.width, s.height));
        }
        if s.samples != 1 && s.samples != 4 {
            return Err(SettingsError::Samples(s.samples));
        }
        if !(s.saturation > 0.0 && s.saturation <= 1.0) {
            return Err(SettingsError::Saturation(s.saturation));
        }
        if !(0.0..=1.0).contains(&s.glass_opacity) {
            return Err(SettingsError::GlassOpacity(s.glass_opacity));
        }
        if s.max_layers == 0 {
            return Err(SettingsError::MaxLayers);
        }
        let r = &s.robust;
        if r.patterns == 0 || r.patterns > Robust::MAX_PATTERNS {
            return Err(SettingsError::Patterns(r.patterns));
        }
        if !(r.tolerance >= 0.0 && r.tolerance <= 4.0) {
            return Err(SettingsError::Tolerance(r.tolerance));
        }
        RasterProfile::check_bits(r.profile.subpixel_bits_min, r.profile.subpixel_bits_max)
    }
}

impl Default for RecordSettings {
    fn default() -> Self {
        RecordSettings {
            width: Self::DEFAULT_SIZE.0,
            height: Self::DEFAULT_SIZE.1,
            samples: Self::DEFAULT_SAMPLES,
            saturation: Self::DEFAULT_SATURATION,
            glass_opacity: Self::DEFAULT_GLASS_OPACITY,
            max_layers: Self::DEFAULT_MAX_LAYERS,
            split_intersections: Self::DEFAULT_SPLIT_INTERSECTIONS,
            robust: Robust::DEFAULT,
        }
    }
}

/// Recording settings that cannot be recorded ([`RecordSettings::validate`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SettingsError {
    /// A side is 0 or above [`RecordSettings::MAX_SIDE`].
    #[error("size {0}x{1} is out of range (1..{max})", max = RecordSettings::MAX_SIDE)]
    Size(u32, u32),
    /// Not 1 or 4 samples.
    #[error("{0} samples: only 1 and 4 are supported")]
    Samples(u32),
    /// Saturation outside (0, 1].
    #[error("saturation {0} must be in (0, 1]")]
    Saturation(f32),
    /// Glass opacity outside [0, 1].
    #[error("glass opacity {0} must be in [0, 1]")]
    GlassOpacity(f32),
    /// No layer allowed.
    #[error("max layers must be at least 1")]
    MaxLayers,
    /// Robust patterns outside 1..=[`Robust::MAX_PATTERNS`].
    #[error("--robust {0}: the number of sample patterns must be 1..={max}", max = Robust::MAX_PATTERNS)]
    Patterns(u32),
    /// Robust tolerance outside [0, 4] pixels.
    #[error("robust tolerance {0} px must be in [0, 4]")]
    Tolerance(f32),
    /// The raster profile's sub-pixel bits are not 4 ≤ least ≤ most ≤ 16.
    #[error("raster profile sub-pixel bits {0}..={1} must satisfy 4 <= least <= most <= 16")]
    SubpixelBits(u32, u32),
}
