//! The `Recording`: what the recorder saw, per frame, at one sample pattern.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::camera::FrameState;
use crate::geometry::Geometry;
use crate::options::{option_enum, OptionValue, ParseOptionError};
use crate::Hash;

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
        /// sample's depth taken anywhere in its pixel, ±1/8 px (the default before profiles).
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
    /// is ±1/8 px, the default before raster profiles, measured with no hole in SwiftShader
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

/// The device a recording was made on.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct DeviceInfo {
    /// Adapter name (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
    pub adapter: String,
    /// Driver name and version.
    pub driver: String,
    /// Backend (Vulkan, Gl, Metal, Dx12).
    pub backend: String,
}

/// A depth-order edge at one frame: `from` lies in front of `to` at `weight` samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct Edge {
    /// The triangle in front (scene id in a Recording, G-local id in a Baked file).
    pub from: u32,
    /// The triangle behind.
    pub to: u32,
    /// Number of samples at which `from` is the peel-order neighbour in front of `to`.
    pub weight: u32,
}

/// Which phases a recording holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Phase {
    /// Phase 1 only: per-frame visible sets; `covered` and `edges` are empty.
    Visibility,
    /// Phases 1 and 2: visible sets and the graphs of G.
    Graphs,
}

/// One frame's record.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FrameRecord {
    /// Frame index on the path.
    pub frame: u32,
    /// V_f: visible triangles (scene ids, ascending).
    pub visible: Vec<u32>,
    /// C_f ⊆ G: triangles of G with at least one fragment (ascending; phase 2).
    /// The ignore list is G \ C_f.
    pub covered: Vec<u32>,
    /// E_f: front → back edges between peel-order neighbours, sorted by (from, to), weights
    /// in samples (phase 2).
    pub edges: Vec<Edge>,
    /// Ties: the edges of E_f between fragments of *equal* depth, `from` being the one the
    /// peel put in front (the lower id), weighted by the number of samples showing the tie
    /// (phase 2). A depth-only bake (`merge --depth-only`) keeps only these: with the depth
    /// test on, the draw order matters only where depths are equal.
    pub ties: Vec<Edge>,
    /// Peel passes used (phase 1, phase 2).
    pub layers: [u32; 2],
    /// Whether `max_layers` stopped the peel before it was complete.
    pub truncated: bool,
}

/// A recording of a frame range of one path over one scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Recording {
    /// Version of the tool that wrote it.
    pub tool_version: String,
    /// Hash of the scene (its geometry, materials, textures and nodes).
    pub scene_hash: Hash,
    /// Hash of the path's frames.
    pub path_hash: Hash,
    /// Recording settings.
    pub settings: RecordSettings,
    /// The device it was recorded on.
    pub device: DeviceInfo,
    /// Which phases it holds.
    pub phase: Phase,
    /// Number of triangles in the scene (scene ids are below this).
    pub scene_triangles: u32,
    /// Every frame of the path (camera and poses), not only the recorded range, so frame
    /// ranges recorded on different machines can be merged.
    pub frame_states: Vec<FrameState>,
    /// Recorded frames, ascending by frame index, a contiguous half-open range.
    pub frames: Vec<FrameRecord>,
    /// G: the triangles visible in at least one frame of the whole path (ascending scene
    /// ids). For a `Visibility` recording: the union over its own range only.
    pub unique_visible: Vec<u32>,
    /// Geometry of G (triangle k is scene triangle `unique_visible[k]`); empty for a
    /// `Visibility` recording.
    pub geometry: Geometry,
    /// Frames per second of the path (TOML `fps`, a generator's `--fps`, the glTF sampling
    /// rate), carried into the baked file; `None` where the writer did not know it.
    pub fps: Option<f64>,
}

impl Recording {
    /// The edges of frame `fr` that a frame played in depth mode (front to back, depth test
    /// `Less` with depth writes, *over*) must hold, and so all that a depth-only bake
    /// (`merge --depth-only`) keeps: every tie (equal depths: the first drawn wins the depth
    /// test), and every edge x → y whose x is a triangle that may have a fragment with alpha
    /// below 1 (a `Blend` material, or glass recorded below opacity 1) or lies behind one in
    /// E_f. A translucent a drawn after something behind it blends over it where the exact
    /// reference shows a alone; so everything behind a, opaque triangles between included
    /// (a → b → c: c drawn before a shows through it), must come after a. Behind opaque
    /// triangles only, the order does not matter: the nearest opaque fragment is what remains
    /// whichever is drawn first. Sorted; a tie that is also a kept edge is listed once, with
    /// the edge's weight. A triangle outside G counts as translucent. `fr`'s edges and ties
    /// are sorted, as [`Recording::check_structure`] requires.
    pub fn depth_mode_edges(&self, fr: &FrameRecord) -> Vec<Edge> {
        let g = &self.geometry;
        let opaque = |t: u32| {
            self.unique_visible
                .binary_search(&t)
                .ok()
                .and_then(|k| g.triangles.get(k))
                .and_then(|tri| g.vertices.get(tri[0] as usize))
                .and_then(|v| g.materials.get(v.material as usize))
                .is_some_and(|m| m.every_fragment_opaque(self.settings.glass_opacity))
        };
        let edges = &fr.edges;
        // Triangles translucent or behind a translucent one (reachable in E_f).
        let mut behind = std::collections::HashSet::new();
        let mut stack: Vec<u32> = Vec::new();
        for e in edges {
            if !opaque(e.from) && behind.insert(e.from) {
                stack.push(e.from);
            }
        }
        while let Some(t) = stack.pop() {
            let first = edges.partition_point(|e| e.from < t);
            for e in edges[first..].iter().take_while(|e| e.from == t) {
                if behind.insert(e.to) {
                    stack.push(e.to);
                }
            }
        }
        let mut out: Vec<Edge> = edges
            .iter()
            .filter(|e| behind.contains(&e.from))
            .copied()
            .collect();
        let kept = out.len();
        for t in &fr.ties {
            let i = out[..kept].partition_point(|e| (e.from, e.to) < (t.from, t.to));
            let listed = out[..kept]
                .get(i)
                .is_some_and(|e| (e.from, e.to) == (t.from, t.to));
            if !listed {
                out.push(*t);
            }
        }
        out.sort_unstable();
        out
    }

    /// The recording's identity: BLAKE3 of its postcard encoding (what a [`crate::Baked`]
    /// stores in `recording_hashes`; independent of the container's compression).
    pub fn content_hash(&self) -> Hash {
        crate::hash_bytes(&postcard::to_allocvec(self).expect("a Recording always serializes"))
    }

    /// Checks the structural consistency a reader relies on before using the recording, and
    /// returns the first problem found:
    /// - settings a recorder could have recorded with ([`RecordSettings::check_stored`]: size,
    ///   samples, saturation, glass opacity, layers, robust patterns, tolerance, sub-pixel
    ///   bits);
    /// - `unique_visible` (G) strictly ascending, every id below `scene_triangles`;
    /// - frames ascending and contiguous, inside the path's `frame_states`;
    /// - per frame: visible and covered sets strictly ascending and inside G; edges and ties
    ///   sorted by (from, to) without duplicates, between distinct triangles of G, with a
    ///   positive weight; a `Visibility` recording has no covered set, edges or ties;
    /// - a `Graphs` recording's geometry holds one triangle per member of G and passes
    ///   [`Geometry::check_structure`]; a `Visibility` recording holds none;
    /// - every frame state passes [`crate::camera::check_frame_state`] (finite cameras; poses
    ///   of existing nodes when the geometry is present).
    ///
    /// O(size of the recording).
    pub fn check_structure(&self) -> Result<(), crate::StructureError> {
        self.settings.check_stored()?;
        let g = &self.unique_visible;
        if g.windows(2).any(|w| w[0] >= w[1]) {
            return Err(crate::Part::Graphs.error("the visible set G is not strictly ascending"));
        }
        if let Some(&t) = g.last().filter(|&&t| t >= self.scene_triangles) {
            return Err(crate::Part::Graphs.error(format!(
                "G names triangle {t}, but the scene has {}",
                self.scene_triangles
            )));
        }
        let in_g = |t: u32| g.binary_search(&t).is_ok();
        let path_frames = self.frame_states.len() as u64;
        let first = self.frames.first().map_or(0, |f| f.frame);
        for (k, fr) in self.frames.iter().enumerate() {
            let f = fr.frame;
            if f as u64 != first as u64 + k as u64 {
                return Err(crate::Part::Graphs.error(format!(
                    "frame record {k} is frame {f}; frames must be contiguous from {first}"
                )));
            }
            if f as u64 >= path_frames {
                return Err(crate::Part::Graphs.error(format!(
                    "frame {f} lies beyond the path's {path_frames} frames"
                )));
            }
            for (what, set) in [("visible", &fr.visible), ("covered", &fr.covered)] {
                if set.windows(2).any(|w| w[0] >= w[1]) {
                    return Err(crate::Part::Graphs.error(format!(
                        "frame {f}: the {what} set is not strictly ascending"
                    )));
                }
                if let Some(&t) = set.iter().find(|&&t| !in_g(t)) {
                    return Err(crate::Part::Graphs
                        .error(format!("frame {f}: {what} triangle {t} is not in G")));
                }
            }
            for (what, list) in [("edges", &fr.edges), ("ties", &fr.ties)] {
                if list
                    .windows(2)
                    .any(|w| (w[0].from, w[0].to) >= (w[1].from, w[1].to))
                {
                    return Err(crate::Part::Graphs.error(format!(
                        "frame {f}: {what} are not sorted without duplicates"
                    )));
                }
                if let Some(e) = list
                    .iter()
                    .find(|e| e.from == e.to || e.weight == 0 || !in_g(e.from) || !in_g(e.to))
                {
                    return Err(crate::Part::Graphs.error(format!(
                        "frame {f}: edge {} → {} (weight {}) is a loop, has no weight or leaves G",
                        e.from, e.to, e.weight
                    )));
                }
            }
            if self.phase == Phase::Visibility
                && !(fr.covered.is_empty() && fr.edges.is_empty() && fr.ties.is_empty())
            {
                return Err(crate::Part::Graphs
                    .error(format!("frame {f}: a visibility recording holds graphs")));
            }
        }
        let nodes = match self.phase {
            Phase::Graphs => {
                if self.geometry.triangles.len() != g.len() {
                    return Err(crate::Part::Graphs.error(format!(
                        "the geometry holds {} triangles for the {} of G",
                        self.geometry.triangles.len(),
                        g.len()
                    )));
                }
                self.geometry.check_structure()?;
                Some(self.geometry.nodes.len())
            }
            Phase::Visibility => {
                if !self.geometry.triangles.is_empty() {
                    return Err(crate::Part::Graphs.error("a visibility recording holds geometry"));
                }
                None
            }
        };
        for (f, st) in self.frame_states.iter().enumerate() {
            crate::camera::check_frame_state(f, st, nodes)?;
        }
        crate::baked::check_fps(self.fps)
    }

    /// The half-open range of recorded frames.
    pub fn frame_range(&self) -> std::ops::Range<u32> {
        match (self.frames.first(), self.frames.last()) {
            (Some(a), Some(b)) => a.frame..b.frame + 1,
            _ => 0..0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;

    /// A phase-1 recording of frames 1..3 of a 4-frame path over a 10-triangle scene.
    fn visibility() -> Recording {
        let state = FrameState {
            camera: Camera {
                view: glam::DMat4::IDENTITY.to_cols_array(),
                yfov: 1.0,
                znear: 0.1,
                zfar: Some(100.0),
            },
            poses: vec![],
        };
        let frame = |f: u32, visible: Vec<u32>| FrameRecord {
            frame: f,
            visible,
            ..Default::default()
        };
        Recording {
            tool_version: crate::TOOL_VERSION.into(),
            scene_hash: [0; 32],
            path_hash: [0; 32],
            settings: RecordSettings::default(),
            device: DeviceInfo::default(),
            phase: Phase::Visibility,
            scene_triangles: 10,
            frame_states: vec![state; 4],
            frames: vec![frame(1, vec![2, 5]), frame(2, vec![5, 9])],
            unique_visible: vec![2, 5, 9],
            geometry: Geometry::default(),
            fps: Some(30.0),
        }
    }

    #[test]
    fn check_structure_accepts_a_valid_recording_and_names_each_fault() {
        visibility().check_structure().unwrap();
        type Edit = fn(&mut Recording);
        let faults: [(Edit, &str); 9] = [
            (|r| r.fps = Some(f64::INFINITY), "frame rate inf"),
            (|r| r.unique_visible.push(10), "but the scene has 10"),
            (|r| r.unique_visible.swap(0, 1), "not strictly ascending"),
            (|r| r.frames[1].frame = 3, "contiguous"),
            (|r| r.frames[1].visible = vec![4], "not in G"),
            (|r| r.frame_states.truncate(2), "beyond the path"),
            (|r| r.frame_states[3].camera.znear = f64::NAN, "znear NaN"),
            (
                |r| {
                    r.frames[0].edges = vec![Edge {
                        from: 2,
                        to: 5,
                        weight: 1,
                    }]
                },
                "holds graphs",
            ),
            (|r| r.settings.saturation = f32::NAN, "saturation NaN"),
        ];
        for (edit, needle) in faults {
            let mut r = visibility();
            edit(&mut r);
            let err = r.check_structure().unwrap_err().problem;
            assert!(err.contains(needle), "{err:?} lacks {needle:?}");
        }
    }

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
        // The browser box is the old default's ±1/8 px: its tolerance and a 4-bit snap.
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
