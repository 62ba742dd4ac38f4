//! The C API called as a C host calls it: statuses, the last-error message, the copy-out
//! convention, and ORDER files (encode, decode, every truncation refused).

use std::ffi::{c_char, CString};
use std::path::Path;
use std::ptr::{null, null_mut};

use trisort_capi::ffi::*;
use trisort_capi::{Order, OrderRange, OrderSource};

/// The calling thread's last error message, as a host reads it.
pub fn last_error() -> String {
    let mut buf = vec![0u8; 4096];
    let n = unsafe { trisort_last_error(buf.as_mut_ptr().cast::<c_char>(), buf.len()) };
    buf.truncate(n.min(4095));
    String::from_utf8(buf).unwrap()
}

fn sample_order() -> Order {
    let triangles = (0..10)
        .map(|k| OrderSource {
            mesh: k % 3,
            primitive: k % 2,
            triangle: 100 + k,
            node: 7,
        })
        .collect();
    Order {
        split: true,
        scene_hash: [9; 32],
        frames: vec![
            OrderRange { first: 0, count: 2 },
            OrderRange { first: 2, count: 1 },
        ],
        ranges: vec![
            OrderRange { first: 0, count: 4 },
            OrderRange { first: 6, count: 4 },
            OrderRange { first: 2, count: 8 },
        ],
        triangles,
    }
}

#[test]
fn abi_version_is_exported() {
    assert_eq!(trisort_abi_version(), TRISORT_ABI_VERSION);
    assert_eq!(trisort_format_version(), trisort_format::FORMAT_VERSION);
    assert_eq!(trisort_format_version(), TRISORT_FORMAT_VERSION);
    let version = unsafe { std::ffi::CStr::from_ptr(trisort_version_string()) };
    assert_eq!(version.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
}

#[test]
fn bad_input_gives_a_status_and_a_message_naming_the_file() {
    let mut h: *mut TrisortBaked = null_mut();
    let junk = b"TRISBAK\0 not a real file";
    let s = unsafe { trisort_open_bytes(junk.as_ptr(), junk.len(), &mut h) };
    assert_eq!(s, TrisortStatus::Format);
    assert!(h.is_null());
    assert!(last_error().contains("<bytes>"), "{}", last_error());
    let s = unsafe { trisort_open_bytes(b"hello".as_ptr(), 5, &mut h) };
    assert_eq!(s, TrisortStatus::Format);
    assert!(last_error().contains("wrong magic"), "{}", last_error());

    let missing = CString::new("/nonexistent/dir/car.baked").unwrap();
    let s = unsafe { trisort_open_path(missing.as_ptr(), &mut h) };
    assert_eq!(s, TrisortStatus::Io);
    assert!(last_error().contains("/nonexistent/dir/car.baked"));

    assert_eq!(
        unsafe { trisort_open_path(null(), &mut h) },
        TrisortStatus::NullArgument
    );
    assert_eq!(
        unsafe { trisort_open_bytes(null(), 0, &mut h) },
        TrisortStatus::NullArgument
    );
    let mut info = TrisortInfo::default();
    assert_eq!(
        unsafe { trisort_info(null(), &mut info) },
        TrisortStatus::NullArgument
    );
    // Closing null is allowed.
    unsafe { trisort_close(null_mut()) };
}

#[test]
fn last_error_truncates_to_the_buffer_and_clears_on_success() {
    let mut h: *mut TrisortBaked = null_mut();
    unsafe { trisort_open_bytes(b"x".as_ptr(), 1, &mut h) };
    let full = last_error();
    let mut small = [0x55u8; 8];
    let n = unsafe { trisort_last_error(small.as_mut_ptr().cast::<c_char>(), small.len()) };
    assert_eq!(n, full.len());
    assert_eq!(&small[..7], &full.as_bytes()[..7]);
    assert_eq!(small[7], 0, "NUL-terminated");
    assert_eq!(unsafe { trisort_last_error(null_mut(), 0) }, full.len());
    let bytes = sample_order().encode();
    let mut o: *mut TrisortOrder = null_mut();
    let s = unsafe { trisort_order_open_bytes(bytes.as_ptr(), bytes.len(), &mut o) };
    assert_eq!(s, TrisortStatus::Ok);
    assert_eq!(last_error(), "");
    unsafe { trisort_order_close(o) };
}

#[test]
fn order_files_round_trip_and_refuse_every_truncation_and_length() {
    let order = sample_order();
    let bytes = order.encode();
    assert_eq!(bytes.len(), 64 + 8 * (2 + 3) + 16 * 10);
    assert_eq!(&bytes[..8], b"TRISORD\0");
    let path = Path::new("t.order");
    assert_eq!(Order::decode(&bytes, path).unwrap(), order);
    for len in 0..bytes.len() {
        let e = Order::decode(&bytes[..len], path).unwrap_err().to_string();
        assert!(e.starts_with("t.order: "), "{e}");
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(Order::decode(&longer, path).is_err());
    // A range reaching past the triangles, and a frame past the ranges.
    let mut bad = order.clone();
    bad.ranges[1].count = 5;
    assert!(Order::decode(&bad.encode(), path)
        .unwrap_err()
        .to_string()
        .contains("range 1"));
    let mut bad = order.clone();
    bad.frames[1].count = 2;
    assert!(Order::decode(&bad.encode(), path).is_err());
    let mut bad = bytes.clone();
    bad[8] = 2;
    assert!(Order::decode(&bad, path)
        .unwrap_err()
        .to_string()
        .contains("version 2"));
}

#[test]
fn order_handles_copy_out_by_the_buffer_convention() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("x.order");
    sample_order().write(&file).unwrap();
    let c = CString::new(file.to_str().unwrap()).unwrap();
    let mut o: *mut TrisortOrder = null_mut();
    assert_eq!(
        unsafe { trisort_order_open_path(c.as_ptr(), &mut o) },
        TrisortStatus::Ok
    );
    let mut info = TrisortOrderInfo::default();
    assert_eq!(
        unsafe { trisort_order_info(o, &mut info) },
        TrisortStatus::Ok
    );
    assert_eq!(
        (
            info.frame_count,
            info.range_count,
            info.triangle_count,
            info.split
        ),
        (2, 3, 10, true)
    );
    // Query the length, then copy; a short buffer is refused untouched.
    let mut len = 0usize;
    let s = unsafe { trisort_order_frame_ranges(o, 0, null_mut(), 0, &mut len) };
    assert_eq!((s, len), (TrisortStatus::Ok, 2));
    let mut ranges = [OrderRange {
        first: 77,
        count: 77,
    }; 2];
    let s = unsafe { trisort_order_frame_ranges(o, 0, ranges.as_mut_ptr(), 1, &mut len) };
    assert_eq!(s, TrisortStatus::BufferTooSmall);
    assert_eq!(ranges[0].first, 77, "nothing copied");
    let s = unsafe { trisort_order_frame_ranges(o, 0, ranges.as_mut_ptr(), 2, &mut len) };
    assert_eq!(s, TrisortStatus::Ok);
    assert_eq!(ranges, [sample_order().ranges[0], sample_order().ranges[1]]);
    let s = unsafe { trisort_order_frame_ranges(o, 2, ranges.as_mut_ptr(), 2, &mut len) };
    assert_eq!(s, TrisortStatus::OutOfRange);
    assert!(last_error().contains("frame 2"));
    let mut tris = vec![OrderSource::default(); 10];
    let s = unsafe { trisort_order_triangles(o, tris.as_mut_ptr(), tris.len(), null_mut()) };
    assert_eq!(s, TrisortStatus::Ok);
    assert_eq!(tris, sample_order().triangles);
    // Neither a buffer nor a length: nothing to do is a caller error.
    let s = unsafe { trisort_order_triangles(o, null_mut(), 0, null_mut()) };
    assert_eq!(s, TrisortStatus::NullArgument);
    unsafe { trisort_order_close(o) };

    let junk = dir.path().join("junk.order");
    std::fs::write(&junk, b"TRISORD\0short").unwrap();
    let c = CString::new(junk.to_str().unwrap()).unwrap();
    let s = unsafe { trisort_order_open_path(c.as_ptr(), &mut o) };
    assert_eq!(s, TrisortStatus::Format);
    assert!(last_error().contains("junk.order"));
}
