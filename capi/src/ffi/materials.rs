//! Materials and their textures, with every mip level.

use trisort_format::{AlphaMode, Baked, Material, Texture, TextureSlot, TextureTransform};

use super::boundary::*;
use super::types::*;

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

/// A material as the C API returns it.
pub(super) fn material_of(m: &Material) -> TrisortMaterial {
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
/// `h` is an open handle; `out`, `cap`, `len` as in the copy convention (top of this header).
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

pub(super) fn texture_of(b: &Baked, texture: u32) -> Result<&Texture, Failure> {
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
/// `trisort_texture_info()` says; `cap` and `len` count bytes).
///
/// # Safety
/// `h` is an open handle; `width` and `height` are null or valid for one write; `out`, `cap`,
/// `len` as in the copy convention (top of this header).
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
/// `len` as in the copy convention (top of this header).
#[no_mangle]
#[allow(
    clippy::too_many_arguments,
    reason = "the signature is the C ABI of include/trisort.h"
)]
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
