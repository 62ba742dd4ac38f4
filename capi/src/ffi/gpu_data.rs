//! The bytes trisort's own player uploads to the GPU, for hosts that draw with its exported
//! shaders (`trisort export-shaders`): the `Frame` and `Lighting` uniforms, the material and
//! node-matrix data textures, the two material texture arrays and the prefiltered
//! environment, packed by `trisort_format::gpu_layout` exactly as the player packs them.
//! Added in ABI 5.

use trisort_format::gpu_layout::{
    self, environment_levels, frame_uniform, material_table, material_texels, node_texels,
    plan_texture_arrays, Lighting, LightingUniform, TextureArray, View,
};
use trisort_format::{Shading, ToneMap};

use super::boundary::*;
use super::types::*;

/// Texels per row of the player's data textures (material and node texels): `DATA_WIDTH` in
/// the exported GLSL. Added in ABI 5.
pub const TRISORT_GPU_DATA_WIDTH: u32 = 1024;
/// RGBA32F texels a material takes in the material texels (the fields of the shaders'
/// `MaterialGpu`, in order). Added in ABI 5.
pub const TRISORT_GPU_MATERIAL_TEXELS: u32 = 20;
/// Bytes of the `Frame` uniform block (std140). Added in ABI 5.
pub const TRISORT_GPU_FRAME_UNIFORM_SIZE: u32 = 144;
/// Bytes of the `Lighting` uniform block (std140). Added in ABI 5.
pub const TRISORT_GPU_LIGHTING_UNIFORM_SIZE: u32 = 192;
/// The `shading` argument of `trisort_gpu_lighting_uniform()`: one light plus ambient.
pub const TRISORT_SHADING_BASIC: u32 = 0;
/// The `shading` argument of `trisort_gpu_lighting_uniform()`: glTF metallic-roughness lit by
/// the file's environment (what `trisort play` draws by default).
pub const TRISORT_SHADING_PBR: u32 = 1;
/// The `tone_map` argument of `trisort_gpu_lighting_uniform()`: Khronos PBR Neutral (the
/// player's default).
pub const TRISORT_TONE_MAP_NEUTRAL: u32 = 0;
/// The `tone_map` argument of `trisort_gpu_lighting_uniform()`: ACES (Narkowicz's fit).
pub const TRISORT_TONE_MAP_ACES: u32 = 1;
/// The `array` argument of the texture array functions: base-colour and emissive textures,
/// uploaded as sRGB (`GL_SRGB8_ALPHA8`).
pub const TRISORT_TEXTURE_ARRAY_SRGB: u32 = 0;
/// The `array` argument of the texture array functions: metallic-roughness, normal and
/// occlusion textures, uploaded as linear (`GL_RGBA8`).
pub const TRISORT_TEXTURE_ARRAY_LINEAR: u32 = 1;

/// The size of a texture the player uploads: a material texture array
/// (`trisort_gpu_texture_array()`) or the environment (`trisort_gpu_environment()`, one
/// layer). Added in ABI 5.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct TrisortGpuTexture {
    /// Level 0 width in texels.
    pub width: u32,
    /// Level 0 height in texels.
    pub height: u32,
    /// Layers (1 for the environment).
    pub layers: u32,
    /// Mip levels, level 0 included (level k is max(1, width >> k) × max(1, height >> k)).
    pub levels: u32,
}

/// The largest texture size a host passes (0: no limit).
fn max_dim(max_texture_size: u32) -> u32 {
    if max_texture_size == 0 {
        u32::MAX
    } else {
        max_texture_size
    }
}

/// An out-of-range failure for argument `what` naming the file.
fn out_of_range(h: &TrisortBaked, what: String) -> Failure {
    Failure(
        TrisortStatus::OutOfRange,
        format!("{}: {what}", h.path.display()),
    )
}

/// The texture array `array` names.
fn array_of(h: &TrisortBaked, array: u32, max_texture_size: u32) -> Result<TextureArray, Failure> {
    let plan = plan_texture_arrays(&h.baked.geometry, max_dim(max_texture_size), false);
    match array {
        TRISORT_TEXTURE_ARRAY_SRGB => Ok(plan.srgb),
        TRISORT_TEXTURE_ARRAY_LINEAR => Ok(plan.linear),
        _ => Err(out_of_range(
            h,
            format!(
                "texture array {array} is out of range (TRISORT_TEXTURE_ARRAY_SRGB or _LINEAR)"
            ),
        )),
    }
}

/// Copies frame `frame`'s `Frame` uniform as the player uploads it for an image of `width` ×
/// `height` pixels (0 and 0: the recorded size): `TRISORT_GPU_FRAME_UNIFORM_SIZE` bytes in the
/// std140 layout of the exported shaders' `Frame` block (the projection with clip depth 0 to
/// 1, the basic model's light, glass opacity, size and sample count, the view-to-world
/// rotation). `cap` and `len` count bytes. Added in ABI 5.
///
/// # Safety
/// `h` is an open handle; `out` is null or valid for `cap` byte writes; `len` is null or valid
/// for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_gpu_frame_uniform(
    h: *const TrisortBaked,
    frame: u32,
    width: u32,
    height: u32,
    out: *mut u8,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        let b = &h.baked;
        let f = frame_index(b.frame_states.len(), frame)?;
        let (width, height) = if width == 0 || height == 0 {
            (b.settings.width, b.settings.height)
        } else {
            (width, height)
        };
        let view = View {
            width: width.max(1),
            height: height.max(1),
            samples: b.settings.samples,
            glass_opacity: b.settings.glass_opacity,
        };
        let u = frame_uniform(&b.frame_states[f], view);
        copy_out(u.bytes(), out, cap, len)
    })
}

/// Copies the `Lighting` uniform as the player uploads it for surface model `shading`
/// (`TRISORT_SHADING_BASIC` or `TRISORT_SHADING_PBR`) and tone map `tone_map`
/// (`TRISORT_TONE_MAP_NEUTRAL` or `TRISORT_TONE_MAP_ACES`), for an environment uploaded as
/// `trisort_gpu_environment()` gives it at `max_texture_size` (the device's largest 2D
/// texture; 0: no limit): `TRISORT_GPU_LIGHTING_UNIFORM_SIZE` bytes, std140. `cap` and `len`
/// count bytes. Other values of `shading` or `tone_map` return `TRISORT_STATUS_OUT_OF_RANGE`.
/// Added in ABI 5.
///
/// # Safety
/// `h` is an open handle; `out` is null or valid for `cap` byte writes; `len` is null or valid
/// for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_gpu_lighting_uniform(
    h: *const TrisortBaked,
    shading: u32,
    tone_map: u32,
    max_texture_size: u32,
    out: *mut u8,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        let shading = match shading {
            TRISORT_SHADING_BASIC => Shading::Basic,
            TRISORT_SHADING_PBR => Shading::Pbr,
            _ => {
                return Err(out_of_range(
                    h,
                    format!("shading {shading} is out of range"),
                ))
            }
        };
        let tone_map = match tone_map {
            TRISORT_TONE_MAP_NEUTRAL => ToneMap::Neutral,
            TRISORT_TONE_MAP_ACES => ToneMap::Aces,
            _ => {
                return Err(out_of_range(
                    h,
                    format!("tone map {tone_map} is out of range"),
                ))
            }
        };
        let env = &h.baked.environment;
        let levels = environment_levels(env, max_dim(max_texture_size)).len() as u32;
        let lighting = Lighting {
            shading,
            tone_map,
            environment: env,
        };
        let u = LightingUniform::new(&lighting, levels);
        copy_out(u.bytes(), out, cap, len)
    })
}

/// Copies the material texels as the player uploads them (its data texture for GLES 3.0):
/// `TRISORT_GPU_MATERIAL_TEXELS` RGBA32F texels per material in material order (one zero
/// material when the file has none), with texture layers placed as the texture arrays at
/// `max_texture_size` place them (0: no limit), padded with zeros to whole rows of
/// `TRISORT_GPU_DATA_WIDTH` texels. Upload as a `TRISORT_GPU_DATA_WIDTH` × (`*len` / 4 /
/// `TRISORT_GPU_DATA_WIDTH`) `GL_RGBA32F` texture. `cap` and `len` count floats. Added in ABI 5.
///
/// # Safety
/// `h` is an open handle; `out` is null or valid for `cap` float writes; `len` is null or
/// valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_gpu_material_texels(
    h: *const TrisortBaked,
    max_texture_size: u32,
    out: *mut f32,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let g = &handle(h, "handle")?.baked.geometry;
        let places = plan_texture_arrays(g, max_dim(max_texture_size), false).places;
        let texels = material_texels(&material_table(&g.materials, &places));
        copy_out(&texels, out, cap, len)
    })
}

/// Copies the node texels as the player uploads them (its data texture for GLES 3.0): every
/// frame's camera-relative node matrices (view × world, built in f64 and rounded once, column
/// major), frame after frame, max(1, node count) matrices of 4 RGBA32F texels a frame, padded
/// with zeros to whole rows of `TRISORT_GPU_DATA_WIDTH` texels. Frame f's first node is
/// f × max(1, node count): the `x` the exported vertex stage's node-base uniform takes. `cap`
/// and `len` count floats. Added in ABI 5.
///
/// # Safety
/// `h` is an open handle; `out` is null or valid for `cap` float writes; `len` is null or
/// valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_gpu_node_texels(
    h: *const TrisortBaked,
    out: *mut f32,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        copy_out(&node_texels(&b.geometry, &b.frame_states), out, cap, len)
    })
}

/// Stores the size of material texture array `array` (`TRISORT_TEXTURE_ARRAY_SRGB` or
/// `TRISORT_TEXTURE_ARRAY_LINEAR`) as the player uploads it on a device whose largest 2D
/// texture is `max_texture_size` (0: no limit) in `*out`: every layer as large as the array's
/// largest texture, a full mip chain; an array without textures is one white texel. Added in
/// ABI 5.
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_gpu_texture_array(
    h: *const TrisortBaked,
    array: u32,
    max_texture_size: u32,
    out: *mut TrisortGpuTexture,
) -> TrisortStatus {
    guard(|| {
        let a = array_of(handle(h, "handle")?, array, max_texture_size)?;
        let info = TrisortGpuTexture {
            width: a.width,
            height: a.height,
            layers: a.layers(),
            levels: a.levels,
        };
        store(out, info, "out")
    })
}

/// Copies level `level` of layer `layer` of texture array `array` as the player uploads it
/// (see `trisort_gpu_texture_array()`): RGBA8 texels, rows top to bottom, the layer's texture
/// at its own level of the same index repeated from the top-left corner over the whole level.
/// `cap` and `len` count bytes. Added in ABI 5.
///
/// # Safety
/// `h` is an open handle; `out` is null or valid for `cap` byte writes; `len` is null or valid
/// for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_gpu_texture_array_level(
    h: *const TrisortBaked,
    array: u32,
    layer: u32,
    level: u32,
    max_texture_size: u32,
    out: *mut u8,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        let a = array_of(h, array, max_texture_size)?;
        let bytes = a
            .level_bytes(&h.baked.geometry, layer, level)
            .ok_or_else(|| {
                out_of_range(
                    h,
                    format!(
                        "layer {layer}, level {level} is out of range ({} layers, {} levels)",
                        a.layers(),
                        a.levels
                    ),
                )
            })?;
        copy_out(&bytes, out, cap, len)
    })
}

/// Stores the size of the prefiltered environment as the player uploads it on a device whose
/// largest 2D texture is `max_texture_size` (0: no limit) in `*out` (`layers` 1): the file's
/// levels that fit, as many as a full chain holds. Sample it with `GL_TEXTURE_MAX_LEVEL` =
/// `levels` − 1. Added in ABI 5.
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_gpu_environment(
    h: *const TrisortBaked,
    max_texture_size: u32,
    out: *mut TrisortGpuTexture,
) -> TrisortStatus {
    guard(|| {
        let env = &handle(h, "handle")?.baked.environment;
        let levels = environment_levels(env, max_dim(max_texture_size));
        let info = TrisortGpuTexture {
            width: levels[0].width,
            height: levels[0].height,
            layers: 1,
            levels: levels.len() as u32,
        };
        store(out, info, "out")
    })
}

/// Copies level `level` of the prefiltered environment as the player uploads it (see
/// `trisort_gpu_environment()`): RGBA IEEE binary16 bits (`GL_RGBA16F`, `GL_HALF_FLOAT`), rows
/// from the zenith down. `cap` and `len` count `uint16_t` values (4 a texel). Added in ABI 5.
///
/// # Safety
/// `h` is an open handle; `out` is null or valid for `cap` writes; `len` is null or valid for
/// one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_gpu_environment_level(
    h: *const TrisortBaked,
    level: u32,
    max_texture_size: u32,
    out: *mut u16,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        let levels = environment_levels(&h.baked.environment, max_dim(max_texture_size));
        let l = levels.get(level as usize).ok_or_else(|| {
            out_of_range(
                h,
                format!(
                    "environment level {level} is out of range ({} levels)",
                    levels.len()
                ),
            )
        })?;
        copy_out(&l.texels, out, cap, len)
    })
}

const _: () = {
    assert!(TRISORT_GPU_DATA_WIDTH == gpu_layout::DATA_WIDTH);
    assert!(TRISORT_GPU_MATERIAL_TEXELS == gpu_layout::MATERIAL_TEXELS);
    assert!(
        TRISORT_GPU_FRAME_UNIFORM_SIZE as usize == std::mem::size_of::<gpu_layout::FrameUniform>()
    );
    assert!(
        TRISORT_GPU_LIGHTING_UNIFORM_SIZE as usize
            == std::mem::size_of::<gpu_layout::LightingUniform>()
    );
};
