//! What every entry point does at the C boundary: failures turned into a status and the
//! thread's last error, panics caught, null and UTF-8 checks on host pointers, and the copy
//! copy convention (top of the header).

use std::cell::RefCell;
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use super::types::{TrisortStatus, TRISORT_ABI_VERSION, TRISORT_FORMAT_VERSION};

/// What went wrong, for the status code and the thread's last error: what an entry point's
/// body returns to [`guard`].
pub struct Failure(pub TrisortStatus, pub String);

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
            E::Malformed { .. } | E::Format(_) => TrisortStatus::Format,
        };
        Failure(status, e.to_string())
    }
}

thread_local! {
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

pub(super) fn set_error(message: String) {
    LAST_ERROR.with(|e| *e.borrow_mut() = message);
}

/// Runs `f` with panics caught, recording its failure as the thread's last error.
pub fn guard(f: impl FnOnce() -> Result<(), Failure>) -> TrisortStatus {
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

/// A null-argument failure naming the argument.
pub fn null(what: &str) -> Failure {
    Failure(TrisortStatus::NullArgument, format!("{what} is null"))
}

/// `*ptr` as a reference, or a null-argument failure.
///
/// # Safety
/// `ptr` is null or valid for reads for the call.
pub(super) unsafe fn handle<'a, T>(ptr: *const T, what: &str) -> Result<&'a T, Failure> {
    ptr.as_ref().ok_or_else(|| null(what))
}

/// A C string as a path.
///
/// # Safety
/// `s` is null or a NUL-terminated string.
pub unsafe fn c_path(s: *const c_char, what: &str) -> Result<PathBuf, Failure> {
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

/// The length half of the copy convention (top of the header): writes `n` to `*len`
/// when `len` is given, and says whether to copy (`out` is given). Both null is a failure.
///
/// # Safety
/// `len` is null or valid for one write.
pub(super) unsafe fn report_len<T>(
    n: usize,
    out: *mut T,
    len: *mut usize,
) -> Result<bool, Failure> {
    if !len.is_null() {
        *len = n;
    }
    if out.is_null() && len.is_null() {
        return Err(null("both out and len are"));
    }
    Ok(!out.is_null())
}

/// Copies `src` to the host's buffer under the copy convention (top of the header).
///
/// # Safety
/// `out` is null or valid for `cap` writes of `T`; `len` is null or valid for one write.
pub(super) unsafe fn copy_out<T: Copy>(
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
pub(super) unsafe fn store<T>(out: *mut T, value: T, what: &str) -> Result<(), Failure> {
    if out.is_null() {
        return Err(null(what));
    }
    out.write(value);
    Ok(())
}

/// Copies `s` as a NUL-terminated string under the copy convention (top of the header)
/// (`*len`: bytes without the NUL; `cap` must hold them and the NUL).
///
/// # Safety
/// `out` is null or valid for `cap` byte writes; `len` is null or valid for one write.
pub(super) unsafe fn copy_string(
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
pub(super) fn frame_index(frames: usize, frame: u32) -> Result<usize, Failure> {
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
pub(super) unsafe fn read_path(path: *const c_char) -> Result<(Vec<u8>, PathBuf), Failure> {
    let path = c_path(path, "path")?;
    let bytes = std::fs::read(&path)
        .map_err(|source| Failure(TrisortStatus::Io, format!("{}: {source}", path.display())))?;
    Ok((bytes, path))
}

/// The bytes the host passed, or a null-argument failure.
///
/// # Safety
/// `data` is null or valid for `len` byte reads.
pub(super) unsafe fn host_bytes<'a>(data: *const u8, len: usize) -> Result<&'a [u8], Failure> {
    if data.is_null() {
        return Err(null("data"));
    }
    Ok(std::slice::from_raw_parts(data, len))
}

/// Frees a handle made by `Box::into_raw` (null is ignored), with panics caught.
///
/// # Safety
/// `h` is null or such a handle, not freed before.
pub(super) unsafe fn close_handle<T>(h: *mut T) {
    if !h.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(h))));
    }
}

/// The library's ABI version (`TRISORT_ABI_VERSION` of the library actually linked): a host
/// built with this header needs at least its `TRISORT_ABI_VERSION`.
#[no_mangle]
pub extern "C" fn trisort_abi_version() -> u32 {
    TRISORT_ABI_VERSION
}

/// The baked-file format version the linked library reads (`TRISORT_FORMAT_VERSION` of the
/// library actually linked; docs/FORMAT.md § Container says where a file stores its own).
#[no_mangle]
pub extern "C" fn trisort_format_version() -> u32 {
    TRISORT_FORMAT_VERSION
}

/// The linked library's version (trisort's release, e.g. "0.1.0"), as a static NUL-terminated
/// string: valid for the life of the program, never freed by the host.
#[no_mangle]
pub extern "C" fn trisort_version_string() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
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
