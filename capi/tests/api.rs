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

/// The C API tests' hand-built file (`baked::sample`, 2 frames) as a bundle of two clips:
/// "intro" (frame 0, 24 fps) and "door-open" (frame 1, no rate stored).
pub fn two_clips() -> trisort_format::Baked {
    let mut b = crate::baked::sample();
    let clip = |name: &str, first, fps| trisort_format::Clip {
        name: name.into(),
        first,
        count: 1,
        fps,
        path_hash: [first as u8 + 3; 32],
        path_first: 0,
    };
    b.clips = vec![clip("intro", 0, Some(24.0)), clip("door-open", 1, None)];
    b.check_structure().unwrap();
    b
}

/// A clip's name copied out as a host does (length query, then the copy).
fn clip_name(h: *const TrisortBaked, clip: u32) -> Result<String, TrisortStatus> {
    let mut len = 0;
    let s = unsafe { trisort_clip_name(h, clip, null_mut(), 0, &mut len) };
    if s != TrisortStatus::Ok {
        return Err(s);
    }
    let mut buf = vec![0x55u8; len + 1];
    let s = unsafe { trisort_clip_name(h, clip, buf.as_mut_ptr().cast(), buf.len(), &mut len) };
    assert_eq!(s, TrisortStatus::Ok);
    assert_eq!(buf[len], 0, "NUL-terminated");
    buf.truncate(len);
    Ok(String::from_utf8(buf).unwrap())
}

#[test]
fn clips_give_names_frame_ranges_and_rates_and_refuse_bad_indices() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bundle.baked");
    trisort_format::write_file_atomic(trisort_format::FileKind::Baked, &file, &two_clips())
        .unwrap();
    let c = CString::new(file.to_str().unwrap()).unwrap();
    let mut h: *mut TrisortBaked = null_mut();
    assert_eq!(
        unsafe { trisort_open_path(c.as_ptr(), &mut h) },
        TrisortStatus::Ok
    );
    let mut n = 0;
    assert_eq!(unsafe { trisort_clip_count(h, &mut n) }, TrisortStatus::Ok);
    assert_eq!(n, 2);

    let names: Vec<String> = (0..n).map(|k| clip_name(h, k).unwrap()).collect();
    assert_eq!(names, ["intro", "door-open"]);
    let frames: Vec<(u32, u32)> = (0..n)
        .map(|k| {
            let (mut first, mut count) = (99, 99);
            let s = unsafe { trisort_clip_frames(h, k, &mut first, &mut count) };
            assert_eq!(s, TrisortStatus::Ok);
            (first, count)
        })
        .collect();
    assert_eq!(frames, [(0, 1), (1, 1)]);
    let mut fps = -1.0;
    assert_eq!(
        unsafe { trisort_clip_fps(h, 0, &mut fps) },
        TrisortStatus::Ok
    );
    assert_eq!(fps, 24.0);
    // No rate stored: ABSENT, 0 written, as trisort_fps().
    assert_eq!(
        unsafe { trisort_clip_fps(h, 1, &mut fps) },
        TrisortStatus::Absent
    );
    assert_eq!(fps, 0.0);
    let e = last_error();
    assert!(e.contains("bundle.baked") && e.contains("door-open"), "{e}");

    // Found by name; an unknown name is ABSENT, listing the clips, *out untouched.
    let mut k = 7;
    let door = CString::new("door-open").unwrap();
    let s = unsafe { trisort_clip_find(h, door.as_ptr(), &mut k) };
    assert_eq!((s, k), (TrisortStatus::Ok, 1));
    assert_eq!(last_error(), "");
    let mut k = 7;
    let trunk = CString::new("trunk").unwrap();
    let s = unsafe { trisort_clip_find(h, trunk.as_ptr(), &mut k) };
    assert_eq!((s, k), (TrisortStatus::Absent, 7));
    let e = last_error();
    assert!(
        e.contains("bundle.baked") && e.contains("\"trunk\"") && e.contains("intro, door-open"),
        "{e}"
    );

    // Out of range: every per-clip function, with a message naming the file and the index.
    let (mut first, mut count) = (5, 5);
    assert_eq!(clip_name(h, 2), Err(TrisortStatus::OutOfRange));
    assert!(last_error().contains("clip 2 is out of range (2 clips)"));
    let s = unsafe { trisort_clip_frames(h, 2, &mut first, &mut count) };
    assert_eq!((s, first, count), (TrisortStatus::OutOfRange, 5, 5));
    assert_eq!(
        unsafe { trisort_clip_fps(h, u32::MAX, &mut fps) },
        TrisortStatus::OutOfRange
    );
    assert!(last_error().contains("bundle.baked"), "{}", last_error());

    // Null pointers.
    let null_h: *const TrisortBaked = null();
    assert_eq!(
        unsafe { trisort_clip_count(null_h, &mut n) },
        TrisortStatus::NullArgument
    );
    assert_eq!(
        unsafe { trisort_clip_count(h, null_mut()) },
        TrisortStatus::NullArgument
    );
    assert_eq!(
        unsafe { trisort_clip_name(h, 0, null_mut(), 0, null_mut()) },
        TrisortStatus::NullArgument
    );
    let mut small = [0x55u8; 5];
    let s = unsafe { trisort_clip_name(h, 0, small.as_mut_ptr().cast(), 5, null_mut()) };
    assert_eq!((s, small[0]), (TrisortStatus::BufferTooSmall, 0x55));
    let s = unsafe { trisort_clip_frames(h, 0, null_mut(), &mut count) };
    assert_eq!((s, count), (TrisortStatus::NullArgument, 5));
    let s = unsafe { trisort_clip_frames(h, 0, &mut first, null_mut()) };
    assert_eq!((s, first), (TrisortStatus::NullArgument, 5));
    assert_eq!(
        unsafe { trisort_clip_fps(h, 0, null_mut()) },
        TrisortStatus::NullArgument
    );
    assert_eq!(
        unsafe { trisort_clip_find(h, null(), &mut k) },
        TrisortStatus::NullArgument
    );
    assert!(last_error().contains("name"), "{}", last_error());
    assert_eq!(
        unsafe { trisort_clip_find(h, door.as_ptr(), null_mut()) },
        TrisortStatus::NullArgument
    );
    assert_eq!(
        unsafe { trisort_clip_find(null_h, door.as_ptr(), &mut k) },
        TrisortStatus::NullArgument
    );
    unsafe { trisort_close(h) };

    // A file of one unnamed path has one clip, "main", over all its frames.
    let h = crate::baked::open(&crate::baked::sample());
    assert_eq!(unsafe { trisort_clip_count(h, &mut n) }, TrisortStatus::Ok);
    assert_eq!((n, clip_name(h, 0).unwrap()), (1, "main".to_string()));
    let s = unsafe { trisort_clip_frames(h, 0, &mut first, &mut count) };
    assert_eq!((s, first, count), (TrisortStatus::Ok, 0, 2));
    let main = CString::new("main").unwrap();
    assert_eq!(
        unsafe { trisort_clip_find(h, main.as_ptr(), &mut k) },
        TrisortStatus::Ok
    );
    assert_eq!(k, 0);
    unsafe { trisort_close(h) };
}
