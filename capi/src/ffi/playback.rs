//! What a player needs to play a file as it was baked: the frame rate and the raster
//! profile, and whether a device meets it.

use super::boundary::*;
use super::types::*;

/// Stores the frame rate the file's path was recorded at (what a player plays at by default)
/// in `*out`. When the file stores none (its recordings did not know it), writes 0 to `*out`
/// and returns `TRISORT_STATUS_ABSENT`; a stored rate is always finite and positive.
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
/// standard ones (each where known). Returns `TRISORT_STATUS_OK` when nothing reported
/// differs, else `TRISORT_STATUS_PROFILE_MISMATCH` with every difference in the last error
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
