//! The `extern "C"` functions of `include/trisort.h`.
//!
//! Conventions (also in the header):
//! - Every function returns a [`TrisortStatus`] (except [`trisort_abi_version`],
//!   [`trisort_last_error`] and the `close` functions). On failure, [`trisort_last_error`]
//!   copies a message naming the file and the problem (per thread, until the next call).
//! - No panic crosses the boundary: each entry point runs under `catch_unwind` and reports one
//!   as [`TrisortStatus::Panic`].
//! - Handles are opened and closed by the library (`trisort_open_*` / `trisort_close`). The
//!   host never frees library memory: arrays are copied into host buffers. Each copy function
//!   takes `out`, its capacity `cap` in elements and `len`: it stores the element count in
//!   `*len` (when `len` is not null); with `out` null it only reports it, with `cap` too small
//!   it returns [`TrisortStatus::BufferTooSmall`] and copies nothing.
//! - Strings (names) are copied the same way as UTF-8 bytes plus a terminating NUL: `*len`
//!   is the length in bytes without the NUL, and `cap` must be at least `*len + 1`.
//! - Matrices are 16 floats, column major.

use std::cell::RefCell;
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use glam::DMat4;
use trisort_format::{
    container, AlphaMode, Baked, FileKind, Material, Texture, TextureSlot, TextureTransform,
    VariantError,
};

use crate::order::{Order, OrderRange, OrderSource};

/// The ABI version of this library: bumped whenever a function, a struct or an enum of the
/// header changes incompatibly. Hosts compare [`trisort_abi_version`] with the header's
/// `TRISORT_ABI_VERSION`.
///
/// 3 added [`TrisortStatus::Absent`], the environment ([`trisort_environment_info`],
/// [`trisort_environment_name`], [`trisort_environment_level`]), material variants
/// ([`trisort_variant_count`], [`trisort_variant_name`], [`trisort_variant_materials`]) and
/// the frame rate ([`trisort_fps`]); the functions of 2 are unchanged. 4 added the raster
/// profile ([`trisort_raster_profile`], [`trisort_check_device`],
/// [`TrisortStatus::ProfileMismatch`]); the functions of 3 are unchanged.
pub const TRISORT_ABI_VERSION: u32 = 4;

/// [`TrisortRasterProfile::name`]: the recorded pattern only (`--raster-profile exact`).
pub const TRISORT_PROFILE_EXACT: u32 = 0;
/// [`TrisortRasterProfile::name`]: a conformant GPU (the default): standard sample
/// locations, 8 sub-pixel bits, depth at the sample.
pub const TRISORT_PROFILE_CONFORMANT: u32 = 1;
/// [`TrisortRasterProfile::name`]: as conformant, snapping to 4 to 8 sub-pixel bits.
pub const TRISORT_PROFILE_SNAP4: u32 = 2;
/// [`TrisortRasterProfile::name`]: SwiftShader's rules (the web build).
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
    /// The file holds no such thing: no frame rate ([`trisort_fps`]), no material variant of
    /// that name ([`trisort_variant_materials`]). The message says what is missing.
    Absent = 8,
    /// The device is outside the bake's raster profile ([`trisort_check_device`]); the
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
/// [`trisort_check_device`].
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

/// A baked file opened by [`trisort_open_path`] or [`trisort_open_bytes`].
pub struct TrisortBaked {
    baked: Baked,
    /// Where it was opened from (`<bytes>` for [`trisort_open_bytes`]), for messages.
    path: PathBuf,
}

/// An ORDER file opened by [`trisort_order_open_path`] or [`trisort_order_open_bytes`].
pub struct TrisortOrder {
    order: Order,
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
    /// Whether the file plays only with the depth test ([`TrisortMode::Depth`]).
    pub depth_only: bool,
    /// Whether intersecting triangles were split before recording.
    pub split_intersections: bool,
    /// The mode the file plays best in: [`TrisortMode::Depth`] when `depth_only`, else
    /// [`TrisortMode::Blend`].
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

impl TrisortTextureSlot {
    fn new(texture: Option<u32>, tex_coord: u32, transform: &TextureTransform) -> Self {
        let [a, b] = transform.matrix();
        TrisortTextureSlot {
            texture: texture.map_or(-1, |t| t as i32),
            tex_coord,
            transform: [a[0], a[1], a[2], b[0], b[1], b[2]],
        }
    }

    fn of(slot: &Option<TextureSlot>) -> Self {
        match slot {
            Some(s) => TrisortTextureSlot::new(Some(s.texture), s.tex_coord, &s.transform),
            None => TrisortTextureSlot::new(None, 0, &TextureTransform::default()),
        }
    }
}

/// A material: glTF metallic-roughness with the extensions trisort reads.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrisortMaterial {
    /// Linear RGBA base colour factor.
    pub base_color: [f32; 4],
    /// Linear RGB emissive colour (factor × `KHR_materials_emissive_strength`).
    pub emissive: [f32; 3],
    /// Alpha cutoff (for [`TrisortAlphaMode::Mask`]).
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
/// The radiance is an equirectangular image ([`trisort_environment_level`]): texel (x, y) of
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

/// Clip-space depth convention of a projection matrix.
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

/// What went wrong, for the status code and the thread's last error.
struct Failure(TrisortStatus, String);

impl From<trisort_format::FormatError> for Failure {
    fn from(e: trisort_format::FormatError) -> Self {
        let status = match e {
            trisort_format::FormatError::Io { .. } => TrisortStatus::Io,
            _ => TrisortStatus::Format,
        };
        Failure(status, e.to_string())
    }
}

impl From<crate::OrderError> for Failure {
    fn from(e: crate::OrderError) -> Self {
        use crate::OrderError as E;
        let status = match &e {
            E::Io { .. } | E::Format(trisort_format::FormatError::Io { .. }) => TrisortStatus::Io,
            E::Malformed { .. } | E::MalformedBaked { .. } | E::Format(_) | E::Scene(_) => {
                TrisortStatus::Format
            }
            E::WrongScene { .. } => TrisortStatus::Unsupported,
        };
        Failure(status, e.to_string())
    }
}

thread_local! {
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

fn set_error(message: String) {
    LAST_ERROR.with(|e| *e.borrow_mut() = message);
}

/// Runs `f` with panics caught, recording its failure as the thread's last error.
fn guard(f: impl FnOnce() -> Result<(), Failure>) -> TrisortStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => {
            set_error(String::new());
            TrisortStatus::Ok
        }
        Ok(Err(Failure(status, message))) => {
            set_error(message);
            status
        }
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            set_error(format!("trisort: internal error (panic): {what}"));
            TrisortStatus::Panic
        }
    }
}

fn null(what: &str) -> Failure {
    Failure(TrisortStatus::NullArgument, format!("{what} is null"))
}

/// `*ptr` as a reference, or a null-argument failure.
///
/// # Safety
/// `ptr` is null or valid for reads for the call.
unsafe fn handle<'a, T>(ptr: *const T, what: &str) -> Result<&'a T, Failure> {
    ptr.as_ref().ok_or_else(|| null(what))
}

/// A C string as a path.
///
/// # Safety
/// `s` is null or a NUL-terminated string.
unsafe fn c_path(s: *const c_char, what: &str) -> Result<PathBuf, Failure> {
    if s.is_null() {
        return Err(null(what));
    }
    let s = CStr::from_ptr(s).to_str().map_err(|_| {
        Failure(
            TrisortStatus::Unsupported,
            format!("{what} is not valid UTF-8"),
        )
    })?;
    Ok(PathBuf::from(s))
}

/// The length half of the copy conventions of the module documentation: writes `n` to `*len`
/// when `len` is given, and says whether to copy (`out` is given). Both null is a failure.
///
/// # Safety
/// `len` is null or valid for one write.
unsafe fn report_len<T>(n: usize, out: *mut T, len: *mut usize) -> Result<bool, Failure> {
    if !len.is_null() {
        *len = n;
    }
    if out.is_null() && len.is_null() {
        return Err(null("both out and len are"));
    }
    Ok(!out.is_null())
}

/// Copies `src` to the host's buffer under the conventions of the module documentation.
///
/// # Safety
/// `out` is null or valid for `cap` writes of `T`; `len` is null or valid for one write.
unsafe fn copy_out<T: Copy>(
    src: &[T],
    out: *mut T,
    cap: usize,
    len: *mut usize,
) -> Result<(), Failure> {
    if !report_len(src.len(), out, len)? {
        return Ok(());
    }
    if cap < src.len() {
        return Err(Failure(
            TrisortStatus::BufferTooSmall,
            format!("buffer holds {cap} elements, {} needed", src.len()),
        ));
    }
    std::ptr::copy_nonoverlapping(src.as_ptr(), out, src.len());
    Ok(())
}

/// Stores `value` in `*out`.
///
/// # Safety
/// `out` is null or valid for one write.
unsafe fn store<T>(out: *mut T, value: T, what: &str) -> Result<(), Failure> {
    if out.is_null() {
        return Err(null(what));
    }
    out.write(value);
    Ok(())
}

/// Copies `s` as a NUL-terminated string under the conventions of the module documentation
/// (`*len`: bytes without the NUL; `cap` must hold them and the NUL).
///
/// # Safety
/// `out` is null or valid for `cap` byte writes; `len` is null or valid for one write.
unsafe fn copy_string(
    s: &str,
    out: *mut c_char,
    cap: usize,
    len: *mut usize,
) -> Result<(), Failure> {
    if !report_len(s.len(), out, len)? {
        return Ok(());
    }
    if cap <= s.len() {
        return Err(Failure(
            TrisortStatus::BufferTooSmall,
            format!(
                "buffer holds {cap} bytes, {} needed (the string and its NUL)",
                s.len() + 1
            ),
        ));
    }
    std::ptr::copy_nonoverlapping(s.as_ptr(), out.cast::<u8>(), s.len());
    *out.add(s.len()) = 0;
    Ok(())
}

/// `frame` as an index into `frames` frames, or an out-of-range failure.
fn frame_index(frames: usize, frame: u32) -> Result<usize, Failure> {
    if (frame as usize) < frames {
        Ok(frame as usize)
    } else {
        Err(Failure(
            TrisortStatus::OutOfRange,
            format!("frame {frame} is out of range ({frames} frames)"),
        ))
    }
}

/// The bytes of the file at the C string `path`, and the path (for messages).
///
/// # Safety
/// `path` is null or a NUL-terminated string.
unsafe fn read_path(path: *const c_char) -> Result<(Vec<u8>, PathBuf), Failure> {
    let path = c_path(path, "path")?;
    let bytes = std::fs::read(&path)
        .map_err(|source| Failure(TrisortStatus::Io, format!("{}: {source}", path.display())))?;
    Ok((bytes, path))
}

/// The bytes the host passed, or a null-argument failure.
///
/// # Safety
/// `data` is null or valid for `len` byte reads.
unsafe fn host_bytes<'a>(data: *const u8, len: usize) -> Result<&'a [u8], Failure> {
    if data.is_null() {
        return Err(null("data"));
    }
    Ok(std::slice::from_raw_parts(data, len))
}

/// Frees a handle made by `Box::into_raw` (null is ignored), with panics caught.
///
/// # Safety
/// `h` is null or such a handle, not freed before.
unsafe fn close_handle<T>(h: *mut T) {
    if !h.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(h))));
    }
}

fn open_baked(bytes: &[u8], path: &Path) -> Result<Box<TrisortBaked>, Failure> {
    let baked: Baked = container::decode(FileKind::Baked, bytes, path)?;
    baked.check_structure().map_err(|problem| {
        Failure(
            TrisortStatus::Format,
            format!("{}: inconsistent baked file: {problem}", path.display()),
        )
    })?;
    Ok(Box::new(TrisortBaked {
        baked,
        path: path.to_path_buf(),
    }))
}

/// The library's ABI version ([`TRISORT_ABI_VERSION`] of the library actually linked).
#[no_mangle]
pub extern "C" fn trisort_abi_version() -> u32 {
    TRISORT_ABI_VERSION
}

/// Copies the calling thread's last error message (UTF-8, empty after a success) into `buf`,
/// truncated to `cap - 1` bytes and NUL-terminated (nothing is written when `buf` is null or
/// `cap` is 0). Returns the message's full length in bytes, without the NUL.
///
/// # Safety
/// `buf` is null or valid for `cap` byte writes.
#[no_mangle]
pub unsafe extern "C" fn trisort_last_error(buf: *mut c_char, cap: usize) -> usize {
    catch_unwind(|| {
        LAST_ERROR.with(|e| {
            let e = e.borrow();
            if !buf.is_null() && cap > 0 {
                let n = e.len().min(cap - 1);
                std::ptr::copy_nonoverlapping(e.as_ptr(), buf.cast::<u8>(), n);
                *buf.add(n) = 0;
            }
            e.len()
        })
    })
    .unwrap_or(0)
}

/// Opens the baked file at `path` (NUL-terminated UTF-8) and stores its handle in `*out`.
/// The file is read, checked (magic, version, checksum, structure) and kept in memory.
///
/// # Safety
/// `path` is a NUL-terminated string; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_open_path(
    path: *const c_char,
    out: *mut *mut TrisortBaked,
) -> TrisortStatus {
    guard(|| {
        let (bytes, path) = read_path(path)?;
        let h = open_baked(&bytes, &path)?;
        store(out, Box::into_raw(h), "out")
    })
}

/// Opens a baked file from `len` bytes at `data` (copied; the host may free them after the
/// call) and stores its handle in `*out`.
///
/// # Safety
/// `data` is valid for `len` byte reads; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_open_bytes(
    data: *const u8,
    len: usize,
    out: *mut *mut TrisortBaked,
) -> TrisortStatus {
    guard(|| {
        let bytes = host_bytes(data, len)?;
        let h = open_baked(bytes, Path::new("<bytes>"))?;
        store(out, Box::into_raw(h), "out")
    })
}

/// Closes a handle from `trisort_open_*` (null is ignored). The handle is invalid afterwards.
///
/// # Safety
/// `h` is null or a handle not closed before.
#[no_mangle]
pub unsafe extern "C" fn trisort_close(h: *mut TrisortBaked) {
    close_handle(h)
}

/// Stores the file's figures in `*out`.
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_info(
    h: *const TrisortBaked,
    out: *mut TrisortInfo,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let g = &b.geometry;
        let info = TrisortInfo {
            frame_count: b.frames.len() as u32,
            width: b.settings.width,
            height: b.settings.height,
            samples: b.settings.samples,
            vertex_count: g.vertices.len() as u32,
            triangle_count: g.triangles.len() as u32,
            index_triangle_count: b.copies.len() as u32,
            draw_count: b.draws.len() as u32,
            node_count: g.nodes.len() as u32,
            material_count: g.materials.len() as u32,
            texture_count: g.textures.len() as u32,
            glass_opacity: b.settings.glass_opacity,
            fits_u16: b.fits_u16(),
            depth_only: b.merge.depth_only,
            split_intersections: b.settings.split_intersections,
            recommended_mode: if b.merge.depth_only {
                TrisortMode::Depth
            } else {
                TrisortMode::Blend
            },
        };
        store(out, info, "out")
    })
}

/// The index buffer's triangles (G-local triangle ids) in front-to-back order, or reversed.
fn ordered_copies(b: &Baked, back_to_front: bool) -> Vec<u32> {
    let mut copies = b.copies.clone();
    if back_to_front {
        copies.reverse();
    }
    copies
}

/// Copies the sorted index buffer as u32 indices into the vertex streams: front to back, or
/// reversed (`back_to_front`, what [`TrisortMode::Blend`] draws; use the same flag for the
/// frame ranges). `len` counts indices.
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_indices_u32(
    h: *const TrisortBaked,
    back_to_front: bool,
    out: *mut u32,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let idx: Vec<u32> = ordered_copies(b, back_to_front)
            .iter()
            .flat_map(|&c| b.geometry.triangles[c as usize])
            .collect();
        copy_out(&idx, out, cap, len)
    })
}

/// [`trisort_indices_u32`] as u16 indices; [`TrisortStatus::Unsupported`] when the file has
/// more than 65,536 vertices (see the info's `fits_u16`).
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_indices_u16(
    h: *const TrisortBaked,
    back_to_front: bool,
    out: *mut u16,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        if !b.fits_u16() {
            return Err(Failure(
                TrisortStatus::Unsupported,
                format!(
                    "{} vertices do not fit u16 indices: use trisort_indices_u32",
                    b.geometry.vertices.len()
                ),
            ));
        }
        let idx: Vec<u16> = ordered_copies(b, back_to_front)
            .iter()
            .flat_map(|&c| b.geometry.triangles[c as usize].map(|v| v as u16))
            .collect();
        copy_out(&idx, out, cap, len)
    })
}

/// Frame `frame`'s draws in drawing order over the index buffer of the same `back_to_front`.
fn frame_ranges(b: &Baked, frame: usize, back_to_front: bool) -> Vec<TrisortRange> {
    let n = b.copies.len() as u32 * 3;
    let mut out: Vec<TrisortRange> = b
        .frame_draws(frame)
        .iter()
        .map(|d| TrisortRange {
            first: if back_to_front {
                n - d.first_index - d.index_count
            } else {
                d.first_index
            },
            count: d.index_count,
        })
        .collect();
    if back_to_front {
        out.reverse();
    }
    out
}

/// Copies frame `frame`'s draw ranges, in drawing order, over the index buffer of the same
/// `back_to_front` ([`trisort_indices_u32`]). `len` counts ranges.
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_frame_ranges(
    h: *const TrisortBaked,
    frame: u32,
    back_to_front: bool,
    out: *mut TrisortRange,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let f = frame_index(b.frames.len(), frame)?;
        copy_out(&frame_ranges(b, f, back_to_front), out, cap, len)
    })
}

/// Copies frame `frame`'s draws as indirect-draw arguments (the same draws as
/// [`trisort_frame_ranges`], ready for `glMultiDrawElementsIndirect`/`vkCmdDrawIndexedIndirect`).
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_frame_draws(
    h: *const TrisortBaked,
    frame: u32,
    back_to_front: bool,
    out: *mut TrisortDrawIndexedIndirectArgs,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let f = frame_index(b.frames.len(), frame)?;
        let draws: Vec<TrisortDrawIndexedIndirectArgs> = frame_ranges(b, f, back_to_front)
            .iter()
            .map(|r| TrisortDrawIndexedIndirectArgs {
                index_count: r.count,
                instance_count: 1,
                first_index: r.first,
                base_vertex: 0,
                first_instance: 0,
            })
            .collect();
        copy_out(&draws, out, cap, len)
    })
}

/// Copies the vertex streams of G, interleaved (64 bytes per vertex).
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_vertices(
    h: *const TrisortBaked,
    out: *mut TrisortVertex,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let v: Vec<TrisortVertex> = b
            .geometry
            .vertices
            .iter()
            .map(|v| TrisortVertex {
                position: v.position,
                normal: v.normal,
                uv: v.uv,
                material: v.material,
                node: v.node,
                tangent: v.tangent,
                uv1: v.uv1,
            })
            .collect();
        copy_out(&v, out, cap, len)
    })
}

fn write_matrix(m: DMat4, out: *mut f32) -> Result<(), Failure> {
    if out.is_null() {
        return Err(null("out"));
    }
    let cols = m.as_mat4().to_cols_array();
    // SAFETY: the caller promised 16 writable floats.
    unsafe { std::ptr::copy_nonoverlapping(cols.as_ptr(), out, 16) };
    Ok(())
}

/// Writes frame `frame`'s camera view matrix (world to view; right handed, looking down −Z)
/// to `out[0..16]`.
///
/// # Safety
/// `h` is an open handle; `out` is valid for 16 float writes.
#[no_mangle]
pub unsafe extern "C" fn trisort_frame_view(
    h: *const TrisortBaked,
    frame: u32,
    out: *mut f32,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let f = frame_index(b.frames.len(), frame)?;
        write_matrix(b.frame_states[f].camera.view_matrix(), out)
    })
}

/// Writes frame `frame`'s projection matrix for an image of `aspect` (width / height) in the
/// clip-depth convention `depth` to `out[0..16]`. Built in f64 and rounded once, as trisort's
/// own pipelines do.
///
/// # Safety
/// `h` is an open handle; `out` is valid for 16 float writes.
#[no_mangle]
pub unsafe extern "C" fn trisort_frame_projection(
    h: *const TrisortBaked,
    frame: u32,
    aspect: f64,
    depth: TrisortDepthRange,
    out: *mut f32,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let f = frame_index(b.frames.len(), frame)?;
        if !(aspect.is_finite() && aspect > 0.0) {
            return Err(Failure(
                TrisortStatus::OutOfRange,
                format!("aspect {aspect} is not a positive number"),
            ));
        }
        let p = b.frame_states[f].camera.projection(aspect);
        let p = match depth {
            TrisortDepthRange::ZeroToOne => p,
            // z' = 2z − w maps [0, w] onto [−w, w].
            TrisortDepthRange::MinusOneToOne => {
                DMat4::from_cols_array(&[
                    1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, -1.0, 1.0,
                ]) * p
            }
        };
        write_matrix(p, out)
    })
}

/// Copies frame `frame`'s node matrices, 16 floats per node: with `view_relative` the
/// camera-relative view × world matrices trisort's pipelines use (computed in f64, rounded
/// once: precise far from the origin), else the world matrices. `cap` and `len` count floats.
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_frame_node_matrices(
    h: *const TrisortBaked,
    frame: u32,
    view_relative: bool,
    out: *mut f32,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let f = frame_index(b.frames.len(), frame)?;
        let state = &b.frame_states[f];
        let view = if view_relative {
            state.camera.view_matrix()
        } else {
            DMat4::IDENTITY
        };
        let floats: Vec<f32> = trisort_format::world_transforms(&b.geometry.nodes, &state.poses)
            .into_iter()
            .flat_map(|w| (view * w).as_mat4().to_cols_array())
            .collect();
        copy_out(&floats, out, cap, len)
    })
}

/// A material as the C API returns it.
fn material_of(m: &Material) -> TrisortMaterial {
    TrisortMaterial {
        base_color: m.base_color,
        emissive: m.emissive,
        alpha_cutoff: m.alpha_cutoff,
        transmission: m.transmission,
        base_color_texture: m.base_color_texture.map_or(-1, |t| t as i32),
        alpha_mode: match m.alpha_mode {
            AlphaMode::Opaque => TrisortAlphaMode::Opaque,
            AlphaMode::Mask => TrisortAlphaMode::Mask,
            AlphaMode::Blend => TrisortAlphaMode::Blend,
        },
        double_sided: m.double_sided,
        base_color_slot: TrisortTextureSlot::new(
            m.base_color_texture,
            m.base_color_tex_coord,
            &m.base_color_transform,
        ),
        metallic: m.metallic,
        roughness: m.roughness,
        metallic_roughness: TrisortTextureSlot::of(&m.metallic_roughness_texture),
        normal: TrisortTextureSlot::of(&m.normal_texture),
        normal_scale: m.normal_scale,
        occlusion: TrisortTextureSlot::of(&m.occlusion_texture),
        occlusion_strength: m.occlusion_strength,
        emissive_texture: TrisortTextureSlot::of(&m.emissive_texture),
        clearcoat: m.clearcoat,
        clearcoat_roughness: m.clearcoat_roughness,
    }
}

/// Copies the materials.
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_materials(
    h: *const TrisortBaked,
    out: *mut TrisortMaterial,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let m: Vec<TrisortMaterial> = b.geometry.materials.iter().map(material_of).collect();
        copy_out(&m, out, cap, len)
    })
}

fn texture_of(b: &Baked, texture: u32) -> Result<&Texture, Failure> {
    b.geometry.textures.get(texture as usize).ok_or_else(|| {
        Failure(
            TrisortStatus::OutOfRange,
            format!(
                "texture {texture} is out of range ({} textures)",
                b.geometry.textures.len()
            ),
        )
    })
}

/// Stores texture `texture`'s size in `*width` and `*height` (either may be null) and copies
/// its level-0 texels (RGBA8, rows top to bottom, sRGB or linear as
/// [`trisort_texture_info`] says; `cap` and `len` count bytes).
///
/// # Safety
/// `h` is an open handle; `width` and `height` are null or valid for one write; `out`, `cap`,
/// `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_texture(
    h: *const TrisortBaked,
    texture: u32,
    width: *mut u32,
    height: *mut u32,
    out: *mut u8,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    trisort_texture_level(h, texture, 0, width, height, out, cap, len)
}

/// Stores texture `texture`'s size, colour space and level count in `*out`.
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_texture_info(
    h: *const TrisortBaked,
    texture: u32,
    out: *mut TrisortTextureInfo,
) -> TrisortStatus {
    guard(|| {
        let t = texture_of(&handle(h, "handle")?.baked, texture)?;
        if out.is_null() {
            return Err(null("out"));
        }
        *out = TrisortTextureInfo {
            width: t.width,
            height: t.height,
            srgb: t.srgb,
            level_count: 1 + t.mips.len() as u32,
        };
        Ok(())
    })
}

/// Stores the size of mip level `level` of texture `texture` in `*width` and `*height`
/// (either may be null) and copies its texels (RGBA8, rows top to bottom; `cap` and `len`
/// count bytes). Level 0 is the texture itself; levels run to the info's `level_count`.
///
/// # Safety
/// `h` is an open handle; `width` and `height` are null or valid for one write; `out`, `cap`,
/// `len` as in the module conventions.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn trisort_texture_level(
    h: *const TrisortBaked,
    texture: u32,
    level: u32,
    width: *mut u32,
    height: *mut u32,
    out: *mut u8,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let t = texture_of(&handle(h, "handle")?.baked, texture)?;
        let texels = match level {
            0 => &t.rgba8,
            k => t.mips.get(k as usize - 1).ok_or_else(|| {
                Failure(
                    TrisortStatus::OutOfRange,
                    format!(
                        "mip level {level} of texture {texture} is out of range ({} levels)",
                        1 + t.mips.len()
                    ),
                )
            })?,
        };
        let (w, ht) = Texture::level_size(t.width, t.height, level);
        if !width.is_null() {
            *width = w;
        }
        if !height.is_null() {
            *height = ht;
        }
        copy_out(texels, out, cap, len)
    })
}

/// Stores the frame rate the file's path was recorded at (what a player plays at by default)
/// in `*out`. When the file stores none (its recordings did not know it), writes 0 to `*out`
/// and returns [`TrisortStatus::Absent`]; a stored rate is always finite and positive.
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_fps(h: *const TrisortBaked, out: *mut f64) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        store(out, h.baked.fps.unwrap_or(0.0), "out")?;
        match h.baked.fps {
            Some(_) => Ok(()),
            None => Err(Failure(
                TrisortStatus::Absent,
                format!("{}: the file stores no frame rate", h.path.display()),
            )),
        }
    })
}

/// Stores the file's raster profile in `*out`.
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_raster_profile(
    h: *const TrisortBaked,
    out: *mut TrisortRasterProfile,
) -> TrisortStatus {
    guard(|| {
        let r = &handle(h, "handle")?.baked.settings.robust;
        let name = match r.profile.name {
            trisort_format::ProfileName::Exact => TRISORT_PROFILE_EXACT,
            trisort_format::ProfileName::Conformant => TRISORT_PROFILE_CONFORMANT,
            trisort_format::ProfileName::Snap4 => TRISORT_PROFILE_SNAP4,
            trisort_format::ProfileName::Browser => TRISORT_PROFILE_BROWSER,
        };
        let profile = TrisortRasterProfile {
            name,
            tolerance: r.tolerance,
            subpixel_bits_min: r.profile.subpixel_bits_min,
            subpixel_bits_max: r.profile.subpixel_bits_max,
            depth_at_sample: r.profile.depth_at == trisort_format::DepthAt::Sample,
            conservative: r.conservative,
            patterns: r.patterns,
        };
        store(out, profile, "out")
    })
}

/// Checks what the host's API reports about its device against the file's raster profile:
/// the sample count, the sub-pixel precision and whether the sample locations are the
/// standard ones (each where known). Returns [`TrisortStatus::Ok`] when nothing reported
/// differs, else [`TrisortStatus::ProfileMismatch`] with every difference in the last error
/// (`trisort_last_error`): a host that must refuse such a device (as `trisort play
/// --strict-profile` does) stops there; one that plays anyway should log it. The raster probe
/// of `trisort play` also measures the sample positions and snapping; this call takes the
/// API's word.
///
/// # Safety
/// `h` is an open handle; `device` is valid for one read.
#[no_mangle]
pub unsafe extern "C" fn trisort_check_device(
    h: *const TrisortBaked,
    device: *const TrisortDeviceRaster,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        let d = *handle(device, "device")?;
        let s = &h.baked.settings;
        let standard = match d.standard_sample_locations {
            1 => Some(true),
            0 => Some(false),
            _ => None,
        };
        let bits = (d.subpixel_bits > 0).then_some(d.subpixel_bits);
        let differences = s
            .robust
            .profile
            .device_differences(s, bits, standard, d.samples);
        if differences.is_empty() {
            return Ok(());
        }
        Err(Failure(
            TrisortStatus::ProfileMismatch,
            format!(
                "{}: the device is outside the raster profile `{}`: {}",
                h.path.display(),
                s.robust.profile.name,
                differences.join("; ")
            ),
        ))
    })
}

/// Stores the figures of the light the file is shaded with in `*out` (its name:
/// [`trisort_environment_name`]; its texels: [`trisort_environment_level`]).
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_environment_info(
    h: *const TrisortBaked,
    out: *mut TrisortEnvironmentInfo,
) -> TrisortStatus {
    guard(|| {
        let e = &handle(h, "handle")?.baked.environment;
        let info = TrisortEnvironmentInfo {
            width: e.width,
            height: e.height,
            level_count: e.levels.len() as u32,
            sh: e.sh,
            has_sun: e.sun.is_some(),
            sun_direction: e.sun.map_or([0.0; 3], |s| s.direction),
            sun_color: e.sun.map_or([0.0; 3], |s| s.color),
            exposure: e.exposure,
        };
        store(out, info, "out")
    })
}

/// Copies the environment's name (`studio` for the built-in light, else the HDR file's
/// name) as a NUL-terminated UTF-8 string; `cap` and `len` count bytes (see the module
/// conventions on strings).
///
/// # Safety
/// `h` is an open handle; `out` is null or valid for `cap` byte writes; `len` is null or
/// valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_environment_name(
    h: *const TrisortBaked,
    out: *mut c_char,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let e = &handle(h, "handle")?.baked.environment;
        copy_string(&e.name, out, cap, len)
    })
}

/// Stores the size of prefiltered level `level` of the environment in `*width` and `*height`
/// (either may be null) and copies its texels: RGBA as IEEE binary16 bits (`uint16_t` each,
/// alpha 1; upload as `GL_RGBA16F` with `GL_HALF_FLOAT`), rows from the zenith down, layout as
/// on [`TrisortEnvironmentInfo`]. `cap` and `len` count `uint16_t` values (4 per texel).
///
/// # Safety
/// `h` is an open handle; `width` and `height` are null or valid for one write; `out`, `cap`,
/// `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_environment_level(
    h: *const TrisortBaked,
    level: u32,
    width: *mut u32,
    height: *mut u32,
    out: *mut u16,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        let e = &h.baked.environment;
        let texels = e.levels.get(level as usize).ok_or_else(|| {
            Failure(
                TrisortStatus::OutOfRange,
                format!(
                    "{}: environment level {level} is out of range ({} levels)",
                    h.path.display(),
                    e.levels.len()
                ),
            )
        })?;
        if !width.is_null() {
            *width = (e.width >> level).max(1);
        }
        if !height.is_null() {
            *height = (e.height >> level).max(1);
        }
        copy_out(texels, out, cap, len)
    })
}

/// Stores the number of material variants (glTF `KHR_materials_variants`) in `*out`: 0
/// without the extension.
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_variant_count(
    h: *const TrisortBaked,
    out: *mut u32,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        store(out, b.geometry.variants.len() as u32, "out")
    })
}

/// Copies the name of material variant `variant` (file order, below
/// [`trisort_variant_count`]) as a NUL-terminated UTF-8 string; `cap` and `len` count bytes
/// (see the module conventions on strings). Names come from the glTF file: they may be empty
/// and need not be unique.
///
/// # Safety
/// `h` is an open handle; `out` is null or valid for `cap` byte writes; `len` is null or
/// valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_variant_name(
    h: *const TrisortBaked,
    variant: u32,
    out: *mut c_char,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        let variants = &h.baked.geometry.variants;
        let v = variants.get(variant as usize).ok_or_else(|| {
            Failure(
                TrisortStatus::OutOfRange,
                format!(
                    "{}: material variant {variant} is out of range ({} variants)",
                    h.path.display(),
                    variants.len()
                ),
            )
        })?;
        copy_string(&v.name, out, cap, len)
    })
}

/// Copies the material table under the material variant named `name` (NUL-terminated UTF-8;
/// null: the default materials, as [`trisort_materials`]): entry k is what material slot k
/// (a vertex's `material`) shows under the variant, so a host switches variants by
/// re-uploading this table alone. Where names repeat, the first variant of the name is used
/// (as the player's `--variant`).
///
/// Refusals, with a message naming the file and the variant: [`TrisortStatus::Absent`] when
/// no variant has this name (the message lists the file's variants);
/// [`TrisortStatus::Unsupported`] when the variant changes something that decides visibility
/// (alpha mode, double-sidedness, transmission, a cut-out or blended material's alpha or
/// cutoff...), so the baked order would not be exact for it.
///
/// # Safety
/// `h` is an open handle; `name` is null or a NUL-terminated string; `out`, `cap`, `len` as
/// in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_variant_materials(
    h: *const TrisortBaked,
    name: *const c_char,
    out: *mut TrisortMaterial,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        let name = if name.is_null() {
            None
        } else {
            Some(CStr::from_ptr(name).to_str().map_err(|_| {
                Failure(
                    TrisortStatus::Unsupported,
                    format!("{}: the variant name is not valid UTF-8", h.path.display()),
                )
            })?)
        };
        let table = h.baked.geometry.variant_materials(name).map_err(|e| {
            let status = match e {
                VariantError::Unknown { .. } => TrisortStatus::Absent,
                VariantError::ChangesVisibility { .. } => TrisortStatus::Unsupported,
            };
            Failure(status, format!("{}: {e}", h.path.display()))
        })?;
        let m: Vec<TrisortMaterial> = table.iter().map(material_of).collect();
        copy_out(&m, out, cap, len)
    })
}

/// Builds the order-only export of the baked file at `baked_path`, whose scene is the glTF
/// file `scene_path`, and writes it to `out_path` (atomically). The same as
/// `trisort export-order BAKED --scene SCENE -o OUT`.
///
/// # Safety
/// The three paths are NUL-terminated strings.
#[no_mangle]
pub unsafe extern "C" fn trisort_export_order(
    baked_path: *const c_char,
    scene_path: *const c_char,
    out_path: *const c_char,
) -> TrisortStatus {
    guard(|| {
        let baked_path = c_path(baked_path, "baked_path")?;
        let scene_path = c_path(scene_path, "scene_path")?;
        let out_path = c_path(out_path, "out_path")?;
        Order::export(&baked_path, &scene_path, &out_path)?;
        Ok(())
    })
}

fn open_order(bytes: &[u8], path: &Path) -> Result<*mut TrisortOrder, Failure> {
    let order = Order::decode(bytes, path)?;
    Ok(Box::into_raw(Box::new(TrisortOrder { order })))
}

/// Opens the ORDER file at `path` and stores its handle in `*out`.
///
/// # Safety
/// `path` is a NUL-terminated string; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_order_open_path(
    path: *const c_char,
    out: *mut *mut TrisortOrder,
) -> TrisortStatus {
    guard(|| {
        let (bytes, path) = read_path(path)?;
        store(out, open_order(&bytes, &path)?, "out")
    })
}

/// Opens an ORDER file from `len` bytes at `data` (copied) and stores its handle in `*out`.
///
/// # Safety
/// `data` is valid for `len` byte reads; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_order_open_bytes(
    data: *const u8,
    len: usize,
    out: *mut *mut TrisortOrder,
) -> TrisortStatus {
    guard(|| {
        let bytes = host_bytes(data, len)?;
        store(out, open_order(bytes, Path::new("<bytes>"))?, "out")
    })
}

/// Closes a handle from `trisort_order_open_*` (null is ignored).
///
/// # Safety
/// `h` is null or a handle not closed before.
#[no_mangle]
pub unsafe extern "C" fn trisort_order_close(h: *mut TrisortOrder) {
    close_handle(h)
}

/// Stores the ORDER file's figures in `*out`.
///
/// # Safety
/// `h` is an open order handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_order_info(
    h: *const TrisortOrder,
    out: *mut TrisortOrderInfo,
) -> TrisortStatus {
    guard(|| {
        let o = &handle(h, "handle")?.order;
        let info = TrisortOrderInfo {
            frame_count: o.frames.len() as u32,
            range_count: o.ranges.len() as u32,
            triangle_count: o.triangles.len() as u32,
            split: o.split,
        };
        store(out, info, "out")
    })
}

/// Copies frame `frame`'s ranges (first triangle, triangle count), front to back.
///
/// # Safety
/// `h` is an open order handle; `out`, `cap`, `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_order_frame_ranges(
    h: *const TrisortOrder,
    frame: u32,
    out: *mut OrderRange,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let o = &handle(h, "handle")?.order;
        let f = frame_index(o.frames.len(), frame)?;
        copy_out(o.frame_ranges(f), out, cap, len)
    })
}

/// Copies every index-buffer triangle's source, front to back.
///
/// # Safety
/// `h` is an open order handle; `out`, `cap`, `len` as in the module conventions.
#[no_mangle]
pub unsafe extern "C" fn trisort_order_triangles(
    h: *const TrisortOrder,
    out: *mut OrderSource,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let o = &handle(h, "handle")?.order;
        copy_out(&o.triangles, out, cap, len)
    })
}
