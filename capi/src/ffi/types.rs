//! The constants, enums and structs of `include/trisort.h`: statuses, handles, and what the
//! copy functions fill in.

use std::path::PathBuf;

use trisort_format::Baked;

use crate::order::Order;

/// The ABI version of this header. A host compares it with `trisort_abi_version()`, the
/// version of the library it actually loaded: a library of a higher version keeps every
/// function, struct and enum of the lower ones unchanged (each version only added), so a host
/// needs `trisort_abi_version() >= TRISORT_ABI_VERSION`. A change that is not an addition
/// renames the shared library (its SONAME, `libtrisort.so.0`).
///
/// 3 added `TRISORT_STATUS_ABSENT`, the environment (`trisort_environment_info()`,
/// `trisort_environment_name()`, `trisort_environment_level()`), material variants
/// (`trisort_variant_count()`, `trisort_variant_name()`, `trisort_variant_materials()`) and
/// the frame rate (`trisort_fps()`). 4 added the raster profile (`trisort_raster_profile()`,
/// `trisort_check_device()`, `TRISORT_STATUS_PROFILE_MISMATCH`). 5 added
/// `trisort_format_version()`, `trisort_version_string()` and the bytes the player's shaders
/// read (`trisort_gpu_frame_uniform()`, `trisort_gpu_lighting_uniform()`,
/// `trisort_gpu_material_texels()`, `trisort_gpu_node_texels()`, `trisort_gpu_texture_array()`,
/// `trisort_gpu_texture_array_level()`, `trisort_gpu_environment()`,
/// `trisort_gpu_environment_level()`: `trisort export-shaders`), and takes the projection's depth
/// range as a `uint32_t` (the same values and calling convention as the enum it was; an
/// out-of-range value is now `TRISORT_STATUS_OUT_OF_RANGE` instead of undefined behaviour);
/// `trisort_export_order()` moved to `libtrisort_export` (`trisort_export.h`). 6 added the
/// clips of a file of format 6, the camera paths it bundles (`trisort_clip_count()`,
/// `trisort_clip_name()`, `trisort_clip_frames()`, `trisort_clip_fps()`,
/// `trisort_clip_find()`).
pub const TRISORT_ABI_VERSION: u32 = 6;

/// The baked-file format version this header's library reads (`trisort_format_version()`
/// says what the loaded library reads): a file of another version is refused with
/// `TRISORT_STATUS_FORMAT` and a message saying to bake it again.
pub const TRISORT_FORMAT_VERSION: u32 = 7;
const _: () = assert!(TRISORT_FORMAT_VERSION == trisort_format::FORMAT_VERSION);

/// `TrisortRasterProfile.name`: the recorded pattern only (`--raster-profile exact`).
pub const TRISORT_PROFILE_EXACT: u32 = 0;
/// `TrisortRasterProfile.name`: a conformant GPU (the default): standard sample
/// locations, 8 sub-pixel bits, depth at the sample.
pub const TRISORT_PROFILE_CONFORMANT: u32 = 1;
/// `TrisortRasterProfile.name`: as conformant, snapping to 4 to 8 sub-pixel bits.
pub const TRISORT_PROFILE_SNAP4: u32 = 2;
/// `TrisortRasterProfile.name`: SwiftShader's rules (the web build).
pub const TRISORT_PROFILE_BROWSER: u32 = 3;

/// The result of a call.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrisortStatus {
    /// Success.
    Ok = 0,
    /// A required pointer argument was null.
    NullArgument = 1,
    /// A file could not be read or written.
    Io = 2,
    /// A file is not a valid trisort file of a supported version.
    Format = 3,
    /// A frame, texture or other index is out of range.
    OutOfRange = 4,
    /// The caller's buffer is smaller than the data (see `len`).
    BufferTooSmall = 5,
    /// The request cannot be met for this file (e.g. u16 indices for more than 65,536
    /// vertices, or a scene that is not the baked file's).
    Unsupported = 6,
    /// An internal error (a panic, caught): please report it.
    Panic = 7,
    /// The file holds no such thing: no frame rate (`trisort_fps()`, `trisort_clip_fps()`),
    /// no material variant of that name (`trisort_variant_materials()`), no clip of that name
    /// (`trisort_clip_find()`). The message says what is missing.
    Absent = 8,
    /// The device is outside the bake's raster profile (`trisort_check_device()`); the
    /// message names each difference.
    ProfileMismatch = 9,
}

/// What a baked file assumes about the rasterizer that plays it (`trisort inspect`'s
/// `raster_profile`): frames played on a device outside it may show holes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct TrisortRasterProfile {
    /// The profile's name: one of `TRISORT_PROFILE_EXACT`, `_CONFORMANT`, `_SNAP4`,
    /// `_BROWSER`.
    pub name: u32,
    /// How far (pixels, in x and y) a sample may lie from the recorded one relative to the
    /// exact geometry, besides the snapping of corners.
    pub tolerance: f32,
    /// The fewest sub-pixel bits a device of the profile snaps corners to.
    pub subpixel_bits_min: u32,
    /// The most sub-pixel bits.
    pub subpixel_bits_max: u32,
    /// Whether the profile's devices take a sample's depth at the sample (the Vulkan and GLES
    /// rule); false: anywhere in its pixel.
    pub depth_at_sample: bool,
    /// Whether the recording was conservative (false: the recorded pattern only).
    pub conservative: bool,
    /// Sample patterns unioned (1: the recorded one only).
    pub patterns: u32,
}

/// What the host's graphics API reports about the device it plays on, for
/// `trisort_check_device()`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct TrisortDeviceRaster {
    /// Sub-pixel precision in bits (Vulkan's `VkPhysicalDeviceLimits::subPixelPrecisionBits`,
    /// GL's `GL_SUBPIXEL_BITS`); 0 when unknown.
    pub subpixel_bits: u32,
    /// 1 where the device uses the standard sample locations (Vulkan's
    /// `standardSampleLocations`), 0 where it does not, −1 when unknown.
    pub standard_sample_locations: i32,
    /// The MSAA sample count the host plays at.
    pub samples: u32,
}

/// A baked file opened by `trisort_open_path()` or `trisort_open_bytes()`.
pub struct TrisortBaked {
    pub(super) baked: Baked,
    /// Where it was opened from (`<bytes>` for `trisort_open_bytes()`), for messages.
    pub(super) path: PathBuf,
}

/// An ORDER file opened by `trisort_order_open_path()` or `trisort_order_open_bytes()`.
pub struct TrisortOrder {
    pub(super) order: Order,
}

/// Figures of a baked file.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct TrisortInfo {
    /// Frames.
    pub frame_count: u32,
    /// Recorded image width (the bake is exact at this size and sample count).
    pub width: u32,
    /// Recorded image height.
    pub height: u32,
    /// Recorded MSAA sample count (1 or 4).
    pub samples: u32,
    /// Vertices of G.
    pub vertex_count: u32,
    /// Triangles of G (the vertex streams' triangles).
    pub triangle_count: u32,
    /// Triangles of the sorted index buffer (3 indices each).
    pub index_triangle_count: u32,
    /// Draw ranges over all frames.
    pub draw_count: u32,
    /// Nodes.
    pub node_count: u32,
    /// Materials.
    pub material_count: u32,
    /// Textures.
    pub texture_count: u32,
    /// Opacity transmissive (glass) materials are drawn with.
    pub glass_opacity: f32,
    /// Whether u16 indices suffice (at most 65,536 vertices).
    pub fits_u16: bool,
    /// Whether the file plays only with the depth test (`TRISORT_MODE_DEPTH`).
    pub depth_only: bool,
    /// Whether intersecting triangles were split before recording.
    pub split_intersections: bool,
    /// The mode the file plays best in: `TRISORT_MODE_DEPTH` when `depth_only`, else
    /// `TRISORT_MODE_BLEND`.
    pub recommended_mode: TrisortMode,
}

/// How frames are drawn (the player's `--mode`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TrisortMode {
    /// Back to front (reversed order), straight-alpha *over*, no depth test.
    #[default]
    Blend = 0,
    /// Front to back, depth test `LESS` with depth writes, *over*.
    Depth = 1,
    /// Front to back, premultiplied *under* on a target cleared to alpha 0, no depth test.
    Saturate = 2,
}

/// One draw: `count` indices starting at index `first` of the index buffer (for
/// `glDrawElements(GL_TRIANGLES, count, type, first * index_size)`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TrisortRange {
    /// First index.
    pub first: u32,
    /// Number of indices (a multiple of 3).
    pub count: u32,
}

/// One indexed indirect draw, laid out as Vulkan's `VkDrawIndexedIndirectCommand` and
/// OpenGL's `DrawElementsIndirectCommand` read it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TrisortDrawIndexedIndirectArgs {
    /// Number of indices.
    pub index_count: u32,
    /// Number of instances (1).
    pub instance_count: u32,
    /// First index.
    pub first_index: u32,
    /// Added to each index (0).
    pub base_vertex: i32,
    /// First instance (0).
    pub first_instance: u32,
}

/// One vertex of G, 64 bytes, as trisort's own pipelines read it (the file's vertex layout:
/// `tangent` at byte 40, `uv1` at byte 56).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrisortVertex {
    /// Position in the local space of `node`.
    pub position: [f32; 3],
    /// Unit normal in the local space of `node` (zero when unknown).
    pub normal: [f32; 3],
    /// Texture coordinate set 0 (`TEXCOORD_0`; zero where no texture samples it).
    pub uv: [f32; 2],
    /// Material index.
    pub material: u32,
    /// Node index: the node matrix that moves this vertex.
    pub node: u32,
    /// Tangent in the local space of `node` (xyz unit) and handedness (w, ±1): the bitangent
    /// is `cross(normal, tangent.xyz) * tangent.w`. Zero where the material has no normal
    /// texture.
    pub tangent: [f32; 4],
    /// Texture coordinate set 1 (`TEXCOORD_1`; zero where no texture samples it).
    pub uv1: [f32; 2],
}

/// A material's reference to a texture: which, sampled at which texture coordinate set,
/// through which `KHR_texture_transform`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrisortTextureSlot {
    /// Texture index, or -1 for none.
    pub texture: i32,
    /// Texture coordinate set: 0 (the vertex `uv`) or 1 (`uv1`).
    pub tex_coord: u32,
    /// The transform as a 2×3 matrix, row major: `u' = m[0]·u + m[1]·v + m[2]`,
    /// `v' = m[3]·u + m[4]·v + m[5]` (identity: 1, 0, 0, 0, 1, 0).
    pub transform: [f32; 6],
}

/// A material: glTF metallic-roughness with the extensions trisort reads.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrisortMaterial {
    /// Linear RGBA base colour factor.
    pub base_color: [f32; 4],
    /// Linear RGB emissive colour (factor × `KHR_materials_emissive_strength`).
    pub emissive: [f32; 3],
    /// Alpha cutoff (for `TRISORT_ALPHA_MODE_MASK`).
    pub alpha_cutoff: f32,
    /// `KHR_materials_transmission` factor; > 0 marks glass, drawn at the info's
    /// `glass_opacity`.
    pub transmission: f32,
    /// Base-colour texture index, or -1 for none (the same as `base_color_slot.texture`).
    pub base_color_texture: i32,
    /// Alpha mode.
    pub alpha_mode: TrisortAlphaMode,
    /// Whether back faces are drawn (single-sided materials discard them).
    pub double_sided: bool,
    /// Base-colour texture (sRGB) with its set and transform; its alpha is what MASK and BLEND
    /// materials are recorded with.
    pub base_color_slot: TrisortTextureSlot,
    /// Metallic factor.
    pub metallic: f32,
    /// Perceptual roughness factor.
    pub roughness: f32,
    /// Metallic-roughness texture (linear; blue: metallic, green: roughness).
    pub metallic_roughness: TrisortTextureSlot,
    /// Tangent-space normal texture (linear).
    pub normal: TrisortTextureSlot,
    /// Scale of the normal texture's x and y.
    pub normal_scale: f32,
    /// Occlusion texture (linear, red channel).
    pub occlusion: TrisortTextureSlot,
    /// Strength of the occlusion texture.
    pub occlusion_strength: f32,
    /// Emissive texture (sRGB), multiplied by `emissive`.
    pub emissive_texture: TrisortTextureSlot,
    /// `KHR_materials_clearcoat` intensity (0: none).
    pub clearcoat: f32,
    /// `KHR_materials_clearcoat` roughness.
    pub clearcoat_roughness: f32,
}

/// A texture's size, colour space and mip levels.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TrisortTextureInfo {
    /// Width of level 0 in texels.
    pub width: u32,
    /// Height of level 0 in texels.
    pub height: u32,
    /// Whether the colour channels are sRGB-encoded (base colour, emissive: upload as
    /// `GL_SRGB8_ALPHA8`) rather than linear data (metallic-roughness, normal, occlusion:
    /// `GL_RGBA8`).
    pub srgb: bool,
    /// Levels stored, level 0 included: the full chain down to 1×1 (level k is
    /// `max(1, width >> k)` × `max(1, height >> k)`; 1 for a 1×1 texture).
    pub level_count: u32,
}

/// The light a baked file is shaded with (trisort's image-based light and optional sun), in
/// world space (+Y up, glTF's convention).
///
/// The radiance is an equirectangular image (`trisort_environment_level()`): texel (x, y) of
/// level 0 looks along `(sin θ cos φ, cos θ, sin θ sin φ)` with `φ = 2π (x + 0.5) / width`
/// and `θ = π (y + 0.5) / height` (row 0 at the zenith). Level k has `max(1, width >> k)` ×
/// `max(1, height >> k)` texels and holds the radiance prefiltered for GGX perceptual
/// roughness `k / (level_count - 1)` (level 0: the mirror image; with one level, roughness 0).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrisortEnvironmentInfo {
    /// Width of level 0 in texels.
    pub width: u32,
    /// Height of level 0 in texels.
    pub height: u32,
    /// Prefiltered levels stored, level 0 included.
    pub level_count: u32,
    /// Irradiance / π as order-2 spherical harmonics: 9 RGB coefficients in the order Y00,
    /// Y1-1, Y10, Y11, Y2-2, Y2-1, Y20, Y21, Y22. A Lambertian surface of albedo ρ and
    /// world-space unit normal n = (x, y, z) reflects `ρ · Σ sh[i] · Y_i(n)`, with `Y_i`:
    /// `0.282095`, `0.488603·y`, `0.488603·z`, `0.488603·x`, `1.092548·xy`, `1.092548·yz`,
    /// `0.315392·(3z² − 1)`, `1.092548·xz`, `0.546274·(x² − y²)` (these formulas on glTF's
    /// axes as they are).
    pub sh: [[f32; 3]; 9],
    /// Whether a directional light (sun) is added to the environment; when false,
    /// `sun_direction` and `sun_color` are zero.
    pub has_sun: bool,
    /// World-space unit direction *towards* the sun.
    pub sun_direction: [f32; 3],
    /// The sun's linear RGB radiance (colour × intensity).
    pub sun_color: [f32; 3],
    /// Exposure: a multiplier on all light (environment and sun) before tone mapping.
    pub exposure: f32,
}

/// glTF alpha mode.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TrisortAlphaMode {
    /// Opaque: alpha 1.
    #[default]
    Opaque = 0,
    /// Cut out below the cutoff, else opaque.
    Mask = 1,
    /// Blended with its base-colour alpha.
    Blend = 2,
}

/// Clip-space depth convention of a projection matrix: the values of
/// `trisort_frame_projection()`'s `depth` argument (a `uint32_t`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrisortDepthRange {
    /// Depth in [0, 1] (Vulkan, Direct3D, Metal, WebGPU: what trisort renders with).
    ZeroToOne = 0,
    /// Depth in [-1, 1] (OpenGL and OpenGL ES defaults).
    MinusOneToOne = 1,
}

/// Figures of an ORDER file.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct TrisortOrderInfo {
    /// Frames.
    pub frame_count: u32,
    /// Ranges over all frames.
    pub range_count: u32,
    /// Index-buffer triangles.
    pub triangle_count: u32,
    /// Whether the bake split intersecting triangles (several consecutive entries can then
    /// name one source triangle: see docs/FORMAT.md § ORDER).
    pub split: bool,
}
