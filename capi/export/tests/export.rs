//! `trisort_export_order` at the C boundary (the happy path, through `trisort export-order`
//! on CarConcept, is the root suite's tests/export_order.rs).

use std::ffi::CString;
use std::path::Path;

use glam::DVec3;
use trisort_export::ffi::{trisort_last_error, TrisortStatus};
use trisort_export::trisort_export_order;
use trisort_format::container::encode;
use trisort_format::{Baked, FileKind, FrameWindow, RecordSettings};
use trisort_testkit::fixtures::{baked, draw, material, quad, scene};

fn last_error() -> String {
    let mut buf = vec![0u8; 1024];
    let n = unsafe { trisort_last_error(buf.as_mut_ptr().cast(), buf.len()) };
    String::from_utf8_lossy(&buf[..n.min(buf.len() - 1)]).into_owned()
}

/// One quad, one frame drawing both its triangles; `index_count` is the draw's (6 is right).
fn one_quad(index_count: u32) -> Baked {
    let mut g = scene(vec![material([1.0, 0.0, 0.0], 1.0)]);
    quad(&mut g, [-1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], 0);
    let mut b = baked(
        g,
        vec![0, 1],
        vec![draw(0, 2)],
        vec![FrameWindow { first: 0, count: 1 }],
        &[DVec3::new(0.0, 0.0, 1.0)],
    );
    b.settings = RecordSettings::new((16, 16), 1);
    b.draws[0].index_count = index_count;
    b
}

fn c(p: &Path) -> CString {
    CString::new(p.to_str().unwrap()).unwrap()
}

#[test]
fn export_order_refuses_a_structurally_broken_baked_file_before_reading_the_scene() {
    assert!(
        one_quad(6).check_structure().is_ok(),
        "the fixture is sound"
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("broken.baked");
    let out = dir.path().join("broken.order");
    std::fs::write(&path, encode(FileKind::Baked, &one_quad(999))).unwrap();
    let (baked_c, scene_c, out_c) = (c(&path), c(&dir.path().join("none.glb")), c(&out));
    let s = unsafe { trisort_export_order(baked_c.as_ptr(), scene_c.as_ptr(), out_c.as_ptr()) };
    assert_eq!(s, TrisortStatus::Format);
    let msg = last_error();
    assert!(
        msg.contains("broken.baked") && msg.contains("draw 0"),
        "{msg}"
    );
    assert!(!out.exists(), "no output on failure");
}

#[test]
fn export_order_names_a_missing_scene_and_a_null_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sound.baked");
    std::fs::write(&path, encode(FileKind::Baked, &one_quad(6))).unwrap();
    let out = dir.path().join("sound.order");
    let (baked_c, scene_c, out_c) = (c(&path), c(&dir.path().join("none.glb")), c(&out));
    let s = unsafe { trisort_export_order(baked_c.as_ptr(), scene_c.as_ptr(), out_c.as_ptr()) };
    assert_ne!(s, TrisortStatus::Ok);
    assert!(last_error().contains("none.glb"), "{}", last_error());
    assert!(!out.exists(), "no output on failure");
    let s = unsafe { trisort_export_order(baked_c.as_ptr(), std::ptr::null(), out_c.as_ptr()) };
    assert_eq!(s, TrisortStatus::NullArgument);
    assert!(last_error().contains("scene_path"), "{}", last_error());
}
