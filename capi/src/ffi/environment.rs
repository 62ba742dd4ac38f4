//! The baked environment light and the material variants.

use std::ffi::{c_char, CStr};

use trisort_format::VariantError;

use super::boundary::*;
use super::materials::material_of;
use super::types::*;

/// Stores the figures of the light the file is shaded with in `*out` (its name:
/// `trisort_environment_name()`; its texels: `trisort_environment_level()`).
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
/// name) as a NUL-terminated UTF-8 string; `cap` and `len` count bytes (the string convention,
/// top of this header).
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
/// on `TrisortEnvironmentInfo`. `cap` and `len` count `uint16_t` values (4 per texel).
///
/// # Safety
/// `h` is an open handle; `width` and `height` are null or valid for one write; `out`, `cap`,
/// `len` as in the copy convention (top of this header).
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
/// `trisort_variant_count()`) as a NUL-terminated UTF-8 string; `cap` and `len` count bytes
/// (the string convention, top of this header). Names come from the glTF file: they may be empty
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
/// null: the default materials, as `trisort_materials()`): entry k is what material slot k
/// (a vertex's `material`) shows under the variant, so a host switches variants by
/// re-uploading this table alone. Where names repeat, the first variant of the name is used
/// (as the player's `--variant`).
///
/// Refusals, with a message naming the file and the variant: `TRISORT_STATUS_ABSENT` when
/// no variant has this name (the message lists the file's variants);
/// `TRISORT_STATUS_UNSUPPORTED` when the variant changes something that decides visibility
/// (alpha mode, double-sidedness, transmission, a cut-out or blended material's alpha or
/// cutoff...), so the baked order would not be exact for it.
///
/// # Safety
/// `h` is an open handle; `name` is null or a NUL-terminated string; `out`, `cap`, `len` as
/// in the copy convention (top of this header).
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
