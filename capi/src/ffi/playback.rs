//! What a player needs to play a file as it was baked: the frame rate, the raster profile
//! and whether a device meets it, and the clips (the camera paths a file bundles).

use std::ffi::{c_char, CStr};

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

/// The clip `clip` of the file opened as `h`, or an out-of-range failure naming the file.
fn clip_of(h: &TrisortBaked, clip: u32) -> Result<&trisort_format::Clip, Failure> {
    h.baked.clips.get(clip as usize).ok_or_else(|| {
        Failure(
            TrisortStatus::OutOfRange,
            format!(
                "{}: clip {clip} is out of range ({} clips)",
                h.path.display(),
                h.baked.clips.len()
            ),
        )
    })
}

/// Stores the number of clips in `*out`: the camera paths the file bundles (a car's start-up
/// tour and its "door open" path sharing one index buffer), at least 1. Clip k (below this
/// count) is a run of consecutive frames (`trisort_clip_frames()`); the clips cover the
/// file's frames in order from frame 0. Frame numbers everywhere else in this API are the
/// file's: a host plays clip k by drawing frames `first .. first + count - 1`. Added in ABI 6.
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_clip_count(
    h: *const TrisortBaked,
    out: *mut u32,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        store(out, b.clips.len() as u32, "out")
    })
}

/// Copies the name of clip `clip` (below `trisort_clip_count()`) as a NUL-terminated string;
/// `cap` and `len` count bytes (the string convention, top of this header). A name is 1 to 64
/// ASCII letters, digits, `_`, `-` and `.`, unique within the file; "main" is the name of the
/// only clip of a file baked from one unnamed path. An index past the clips is
/// `TRISORT_STATUS_OUT_OF_RANGE`. Added in ABI 6.
///
/// # Safety
/// `h` is an open handle; `out` is null or valid for `cap` byte writes; `len` is null or
/// valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_clip_name(
    h: *const TrisortBaked,
    clip: u32,
    out: *mut c_char,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        copy_string(&clip_of(h, clip)?.name, out, cap, len)
    })
}

/// Stores the frames of clip `clip` (below `trisort_clip_count()`): its first frame among the
/// file's frames in `*first` and its number of frames (at least 1) in `*count`, so it spans
/// frames `*first .. *first + *count - 1`. Both pointers are required (nothing is written
/// when either is null). An index past the clips is `TRISORT_STATUS_OUT_OF_RANGE`. Added in
/// ABI 6.
///
/// # Safety
/// `h` is an open handle; `first` and `count` are valid for one write each.
#[no_mangle]
pub unsafe extern "C" fn trisort_clip_frames(
    h: *const TrisortBaked,
    clip: u32,
    first: *mut u32,
    count: *mut u32,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        let c = clip_of(h, clip)?;
        if count.is_null() {
            return Err(null("count"));
        }
        store(first, c.first, "first")?;
        store(count, c.count, "count")
    })
}

/// Stores the frame rate clip `clip` (below `trisort_clip_count()`) plays at by default in
/// `*out`. As `trisort_fps()`: when the file stores none for the clip, writes 0 to `*out` and
/// returns `TRISORT_STATUS_ABSENT`; a stored rate is always finite and positive. An index
/// past the clips is `TRISORT_STATUS_OUT_OF_RANGE`. Added in ABI 6.
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_clip_fps(
    h: *const TrisortBaked,
    clip: u32,
    out: *mut f64,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        let c = clip_of(h, clip)?;
        store(out, c.fps.unwrap_or(0.0), "out")?;
        match c.fps {
            Some(_) => Ok(()),
            None => Err(Failure(
                TrisortStatus::Absent,
                format!(
                    "{}: the file stores no frame rate for clip {:?}",
                    h.path.display(),
                    c.name
                ),
            )),
        }
    })
}

/// Stores the index of the clip named `name` (NUL-terminated UTF-8, compared byte for byte)
/// in `*out`. When no clip has this name, returns `TRISORT_STATUS_ABSENT` with a message
/// naming the file and listing its clips, and leaves `*out` as it was. Added in ABI 6.
///
/// # Safety
/// `h` is an open handle; `name` is a NUL-terminated string; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_clip_find(
    h: *const TrisortBaked,
    name: *const c_char,
    out: *mut u32,
) -> TrisortStatus {
    guard(|| {
        let h = handle(h, "handle")?;
        if name.is_null() {
            return Err(null("name"));
        }
        if out.is_null() {
            return Err(null("out"));
        }
        let clips = &h.baked.clips;
        let found = CStr::from_ptr(name)
            .to_str()
            .ok()
            .and_then(|name| clips.iter().position(|c| c.name == name));
        match found {
            Some(k) => store(out, k as u32, "out"),
            None => {
                let names: Vec<&str> = clips.iter().map(|c| c.name.as_str()).collect();
                Err(Failure(
                    TrisortStatus::Absent,
                    format!(
                        "{}: no clip is named {:?}; the file's clips: {}",
                        h.path.display(),
                        CStr::from_ptr(name).to_string_lossy(),
                        names.join(", ")
                    ),
                ))
            }
        }
    })
}
