//! `presort` (paper 000) through the real binary: a small demo car presorted into 6
//! partitions verifies exact against the exact reference from random cameras outside its
//! polyhedron (blend and depth); the same file with its lists drawn the wrong way round fails;
//! `play` writes the frames; cameras inside the polyhedron, bad partition counts, missing
//! paths and damaged files are refused with the file and the problem named.

use std::path::Path;

use trisort_format::{FileKind, Presorted};

use crate::support::*;

const SCENE: &str = "demo:6000";

fn presort(d: &Path) -> serde_json::Value {
    run_json(
        d,
        &args(&format!("presort {SCENE} -o car.presorted --partitions 6")),
    )
}

#[test]
fn a_presorted_demo_car_verifies_exact_from_random_cameras_and_a_reversed_one_does_not() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let figures = presort(d);
    for key in ["triangles", "list_triangles", "partitions", "seconds"] {
        assert!(
            figures.get(key).is_some(),
            "presort --json lacks {key}: {figures}"
        );
    }
    assert_eq!(figures["partitions"], 6);
    let sorted = figures["sorted_triangles"].as_u64().unwrap();
    assert!(sorted > 0, "the demo car has glass: {figures}");
    assert!(figures["list_triangles"].as_u64().unwrap() >= sorted);
    // The demo car's glass has no cycle the cutting planes leave (the lists are exact).
    assert_eq!(figures["unresolved_cycles"], 0, "{figures}");
    assert_eq!(figures["cycles"].as_array().map(Vec::len), Some(0));

    let blend = run_json(
        d,
        &args(&format!(
            "verify car.presorted --path random:10:7 --size 96x96 --samples 4 --scene {SCENE}"
        )),
    );
    assert_eq!(blend["ok"], true, "{blend}");
    let frames = blend["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 10);
    let partitions: std::collections::BTreeSet<u64> = frames
        .iter()
        .map(|f| f["partition"].as_u64().unwrap())
        .collect();
    assert_eq!(
        partitions.len(),
        6,
        "a camera in every partition: {partitions:?}"
    );
    let depth = run_json(
        d,
        &args("verify car.presorted --path random:4:8 --size 96x96 --samples 4 --mode depth"),
    );
    assert_eq!(depth["ok"], true, "{depth}");
    // The test in the vertex stage selects the same copies.
    let vertex = run_json(
        d,
        &args(&format!(
            "verify car.presorted --path random:6:9 --size 96x96 --samples 4 --scene {SCENE} \
             --test-stage vertex"
        )),
    );
    assert_eq!(vertex["ok"], true, "{vertex}");

    // The lists reversed (front to back in blend mode) and their tests dropped: each partition
    // draws every copy, nearest first. The check must see it.
    let mut file: Presorted =
        trisort_format::read_file(FileKind::Presorted, &d.join("car.presorted")).unwrap();
    for s in file.segments.clone() {
        file.copies[s.first as usize..(s.first + s.count) as usize].reverse();
    }
    for c in &mut file.copies {
        c.tests = 0;
    }
    trisort_format::write_file_atomic(FileKind::Presorted, &d.join("wrong.presorted"), &file)
        .unwrap();
    let out = run(
        d,
        &args("verify wrong.presorted --path random:10:7 --size 96x96 --samples 4 --json"),
        false,
    );
    assert_eq!(
        out.status.code(),
        Some(3),
        "a wrong order fails with exit 3"
    );
    let wrong: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(wrong["ok"], false);
    assert!(
        wrong["frames"]
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f["max_channel_diff"].as_u64().unwrap() > 1),
        "{wrong}"
    );

    // Play: PNG frames and per-frame figures.
    let played = run_json(
        d,
        &args("play car.presorted --path random:3 --size 64x48 --out-dir frames"),
    );
    assert_eq!(played["frames"].as_array().unwrap().len(), 3);
    for f in 0..3 {
        let png = d.join(format!("frames/frame-{f:05}.png"));
        let img = image::open(&png).unwrap();
        assert_eq!((img.width(), img.height()), (64, 48));
    }
    // Inspect.
    let inspected = run_json(d, &args("inspect car.presorted"));
    assert_eq!(inspected["kind"], "presorted");
    assert_eq!(inspected["list_triangles"], figures["list_triangles"]);
}

#[test]
fn presort_refuses_what_it_cannot_play() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let out = run(
        d,
        &args("presort demo:2000 -o bad.presorted --partitions 5"),
        false,
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("--partitions 5"));
    assert!(!d.join("bad.presorted").exists(), "no output on failure");

    run(
        d,
        &args("presort demo:2000 -o small.presorted --partitions 4"),
        true,
    );
    // A camera inside the polyhedron: the error names the frame.
    let out = run(
        d,
        &args("play small.presorted --path orbit:frames=3,distance=0.2 --out-dir f"),
        false,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("frame 0") && err.contains("inside"), "{err}");
    // No path.
    let out = run(d, &args("play small.presorted --out-dir f"), false);
    assert!(String::from_utf8_lossy(&out.stderr).contains("--path"));
    // A truncated file.
    let bytes = std::fs::read(d.join("small.presorted")).unwrap();
    std::fs::write(d.join("cut.presorted"), &bytes[..bytes.len() / 2]).unwrap();
    let out = run(d, &args("play cut.presorted --path random:1"), false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cut.presorted") && err.contains("truncated"),
        "{err}"
    );
}
