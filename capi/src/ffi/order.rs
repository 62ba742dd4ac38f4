//! Opening and reading ORDER files (writing them: trisort-capi-export).

use std::ffi::c_char;
use std::path::Path;

use crate::order::{Order, OrderRange, OrderSource};

use super::boundary::*;
use super::types::*;

pub(super) fn open_order(bytes: &[u8], path: &Path) -> Result<*mut TrisortOrder, Failure> {
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
/// `h` is an open order handle; `out`, `cap`, `len` as in the copy convention (top of this header).
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
/// `h` is an open order handle; `out`, `cap`, `len` as in the copy convention (top of this header).
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
