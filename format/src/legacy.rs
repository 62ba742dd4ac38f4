//! Baked files of earlier format versions, read and migrated in memory (docs/FORMAT.md §
//! Compatibility policy): version 6 (no block-compressed textures), version 5 (nor clips) and
//! version 4 (nor a raster profile).
//! Recordings are not migrated: they are intermediate files, recorded again.

use serde::Deserialize;

use crate::baked::{DrawIndexedIndirectArgs, FrameWindow, MergeInfo, MergeStats};
use crate::camera::FrameState;
use crate::geometry::{Geometry, Material, MaterialVariant, Node, Texture, Vertex};
use crate::recording::{DeviceInfo, Edge, ProfileName, RasterProfile, RecordSettings, Robust};
use crate::{Baked, Clip, Environment, Hash};

/// The oldest baked-file version this reader migrates.
pub const OLDEST_READABLE: u32 = 4;

/// A texture of versions 4 to 6: RGBA8 levels only.
#[derive(Deserialize)]
struct TextureV6 {
    name: String,
    width: u32,
    height: u32,
    rgba8: Vec<u8>,
    srgb: bool,
    mips: Vec<Vec<u8>>,
}

/// The geometry of versions 4 to 6: today's, with [`TextureV6`].
#[derive(Deserialize)]
struct GeometryV6 {
    vertices: Vec<Vertex>,
    triangles: Vec<[u32; 3]>,
    materials: Vec<Material>,
    textures: Vec<TextureV6>,
    nodes: Vec<Node>,
    variants: Vec<MaterialVariant>,
}

impl From<GeometryV6> for Geometry {
    fn from(g: GeometryV6) -> Geometry {
        let textures = (g.textures.into_iter())
            .map(|t| Texture {
                name: t.name,
                width: t.width,
                height: t.height,
                rgba8: t.rgba8,
                srgb: t.srgb,
                mips: t.mips,
                blocks: None,
            })
            .collect();
        Geometry {
            vertices: g.vertices,
            triangles: g.triangles,
            materials: g.materials,
            textures,
            nodes: g.nodes,
            variants: g.variants,
        }
    }
}

/// A baked file of version 6: today's [`Baked`] with [`GeometryV6`].
#[derive(Deserialize)]
struct BakedV6 {
    before: BakedBefore6<RecordSettings>,
    clips: Vec<Clip>,
}

/// A baked file of version 4 or 5: every field of version 6 but the clips, with the
/// settings of its version.
#[derive(Deserialize)]
struct BakedBefore6<S> {
    tool_version: String,
    scene_hash: Hash,
    path_hash: Hash,
    recording_hashes: Vec<Hash>,
    settings: S,
    device: DeviceInfo,
    merge: MergeInfo,
    stats: MergeStats,
    geometry: GeometryV6,
    scene_ids: Vec<u32>,
    copies: Vec<u32>,
    draws: Vec<DrawIndexedIndirectArgs>,
    frames: Vec<FrameWindow>,
    frame_states: Vec<FrameState>,
    removed_edges: Vec<Vec<Edge>>,
    fps: Option<f64>,
    environment: Environment,
}

/// Version 4's recording settings: `Robust` without its profile.
#[derive(Deserialize)]
struct SettingsV4 {
    width: u32,
    height: u32,
    samples: u32,
    saturation: f32,
    glass_opacity: f32,
    max_layers: u32,
    split_intersections: bool,
    robust: RobustV4,
}

/// Version 4's `Robust`.
#[derive(Deserialize)]
struct RobustV4 {
    patterns: u32,
    tolerance: f32,
    conservative: bool,
}

impl RobustV4 {
    /// The version-5 `Robust` that states what a version-4 recording assumed, no more.
    ///
    /// Without `conservative` it recorded the patterns only: the `exact` profile, tolerance
    /// kept (the patterns' jitter). A conservative version-4 recording grew coverage and
    /// compared depth over a box of ±`tolerance` px around each sample, sub-pixel snapping
    /// included; today's profile splits that box into the snapping of a grid
    /// ([`RasterProfile::snap_reach`]) and the tolerance beside it. So the profile is the
    /// coarsest grid of 4 to 16 bits whose snapping fits in the box (4 bits, `snap4`, for the
    /// old default of 1/8 px; `conformant`'s 8 bits where it is the coarsest that fits), the
    /// most bits 8 or that, depth at the sample, and the tolerance the rest of the box:
    /// [`Robust::sample_box`] equals the old tolerance.
    fn migrate(self) -> Robust {
        if !self.conservative {
            return Robust {
                patterns: self.patterns,
                tolerance: self.tolerance,
                conservative: false,
                profile: RasterProfile::named(ProfileName::Exact),
            };
        }
        if !self.tolerance.is_finite() {
            // A corrupted tolerance stays what it is, so the structure check refuses it
            // rather than the migration turning it into a plausible box.
            return Robust {
                patterns: self.patterns,
                tolerance: self.tolerance,
                conservative: true,
                profile: RasterProfile::named(ProfileName::Snap4),
            };
        }
        let reach = |bits: u32| 0.5 * 0.5f32.powi(bits as i32);
        let bits = (4..=16).find(|&b| reach(b) <= self.tolerance).unwrap_or(16);
        let name = if bits <= 4 {
            ProfileName::Snap4
        } else {
            ProfileName::Conformant
        };
        let mut profile = RasterProfile::named(name);
        profile.subpixel_bits_min = bits;
        profile.subpixel_bits_max = bits.max(8);
        Robust {
            patterns: self.patterns,
            tolerance: (self.tolerance - reach(bits)).max(0.0),
            conservative: true,
            profile,
        }
    }
}

impl From<SettingsV4> for RecordSettings {
    fn from(s: SettingsV4) -> RecordSettings {
        RecordSettings {
            width: s.width,
            height: s.height,
            samples: s.samples,
            saturation: s.saturation,
            glass_opacity: s.glass_opacity,
            max_layers: s.max_layers,
            split_intersections: s.split_intersections,
            robust: s.robust.migrate(),
        }
    }
}

impl<S: Into<RecordSettings>> BakedBefore6<S> {
    /// Today's [`Baked`]: one clip, [`Clip::DEFAULT_NAME`], of every frame, at the file's
    /// rate and path.
    fn migrate(self) -> Baked {
        let clips = vec![Clip::whole(
            self.frames.len() as u32,
            self.fps,
            self.path_hash,
        )];
        Baked {
            tool_version: self.tool_version,
            scene_hash: self.scene_hash,
            path_hash: self.path_hash,
            recording_hashes: self.recording_hashes,
            settings: self.settings.into(),
            device: self.device,
            merge: self.merge,
            stats: self.stats,
            geometry: self.geometry.into(),
            scene_ids: self.scene_ids,
            copies: self.copies,
            draws: self.draws,
            frames: self.frames,
            frame_states: self.frame_states,
            removed_edges: self.removed_edges,
            fps: self.fps,
            environment: self.environment,
            clips,
        }
    }
}

/// Decodes the postcard payload `raw` of a baked file of format `version` (4 to 6) and
/// migrates it; `None` for a version this reader does not migrate. The error is postcard's,
/// or trailing bytes.
pub(crate) fn decode_baked(version: u32, raw: &[u8]) -> Option<Result<Baked, String>> {
    fn take<S: for<'de> Deserialize<'de> + Into<RecordSettings>>(
        raw: &[u8],
    ) -> Result<Baked, String> {
        let (old, rest) =
            postcard::take_from_bytes::<BakedBefore6<S>>(raw).map_err(|e| e.to_string())?;
        if !rest.is_empty() {
            return Err(format!("{} trailing bytes", rest.len()));
        }
        Ok(old.migrate())
    }
    match version {
        6 => Some(
            postcard::take_from_bytes::<BakedV6>(raw)
                .map_err(|e| e.to_string())
                .and_then(|(old, rest)| match rest.len() {
                    0 => Ok(Baked {
                        clips: old.clips,
                        ..old.before.migrate()
                    }),
                    n => Err(format!("{n} trailing bytes")),
                }),
        ),
        5 => Some(take::<RecordSettings>(raw)),
        4 => Some(take::<SettingsV4>(raw)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_version_4_robust_setting_migrates_to_the_box_it_recorded() {
        let old = |conservative, tolerance| RobustV4 {
            patterns: 1,
            tolerance,
            conservative,
        };
        // The old default, conservative within 1/8 px: 4-bit snapping (1/32) + 3/32.
        let r = old(true, 0.125).migrate();
        assert_eq!(r.profile.name, ProfileName::Snap4);
        assert_eq!(
            (r.profile.subpixel_bits_min, r.profile.subpixel_bits_max),
            (4, 8)
        );
        assert_eq!(r.sample_box(), 0.125);
        // A box of 1/256 px fits 7-bit snapping only: bits 7..8, nothing left over.
        let r = old(true, 1.0 / 256.0).migrate();
        assert_eq!(
            (r.profile.subpixel_bits_min, r.profile.subpixel_bits_max),
            (7, 8)
        );
        assert_eq!(r.sample_box(), 1.0 / 256.0);
        // A NaN tolerance is kept, for the structure check to refuse.
        let r = old(true, f32::NAN).migrate();
        assert!(r.tolerance.is_nan());
        let r = old(false, 0.125).migrate();
        assert_eq!(r.profile.name, ProfileName::Exact);
        assert!(!r.conservative);
    }
}
