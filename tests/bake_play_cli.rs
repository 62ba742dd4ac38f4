//! End to end through the real binary: bake → verify → play on the demo car and CarConcept,
//! and `trisort demo` with `--export-scene`.

use crate::support::*;

fn pngs(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png"))
        .collect();
    v.sort();
    v
}

#[test]
fn demo_car_bakes_verifies_and_plays() {
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let bake =
        "bake demo:10000 --path orbit:frames=6,degrees=120 --size 96x96 --samples 4 -o car.baked";
    let v = run_json(dir.path(), &args(bake));
    for key in [
        "frames",
        "unique_visible",
        "per_frame",
        "strategy",
        "layout",
        "index_triangles",
        "source_triangles",
        "draws_per_frame_mean",
        "draws_per_frame_max",
        "drawn_not_visible_mean",
        "unordered_samples",
        "seconds",
    ] {
        assert!(!v[key].is_null(), "bake --json lacks {key}: {v}");
    }
    let g = v["unique_visible"].as_u64().unwrap();
    let index = v["index_triangles"].as_u64().unwrap();
    let source = v["source_triangles"].as_u64().unwrap();
    assert!(
        g <= index && index <= source,
        "|G| {g} ≤ index {index} ≤ Σ|V_f| {source}"
    );
    run(
        dir.path(),
        &["verify", "car.baked", "--recording", "car.baked.rec"],
        true,
    );
    let p = run_json(dir.path(), &["play", "car.baked", "--out-dir", "frames"]);
    assert_eq!(p["frames"].as_array().unwrap().len(), 6);
    assert_eq!(pngs(&dir.path().join("frames")).len(), 6);
    // Frames are pictures of the car: not a flat background.
    let img = image::open(dir.path().join("frames/frame-00000.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(img.dimensions(), (96, 96));
    let distinct: std::collections::HashSet<[u8; 4]> = img.pixels().map(|p| p.0).collect();
    assert!(
        distinct.len() > 20,
        "frame 0 has {} colours",
        distinct.len()
    );
    // inspect reads the baked file back.
    let i = run_json(dir.path(), &["inspect", "car.baked"]);
    assert_eq!(i["index_triangles"], index);
}

#[test]
fn car_concept_bakes_and_plays_a_few_frames() {
    let Some(car) = scene("CarConcept") else {
        return;
    };
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let bake = bake_args(
        &car,
        "orbit:frames=4,degrees=40",
        "128x128",
        "4",
        "car.baked",
    );
    run(dir.path(), &bake, true);
    run(
        dir.path(),
        &["verify", "car.baked", "--recording", "car.baked.rec"],
        true,
    );
    for mode in ["blend", "depth", "saturate"] {
        let out = format!("frames-{mode}");
        let play = format!("play car.baked --mode {mode} --frames 1..3 --out-dir {out}");
        run(dir.path(), &args(&play), true);
        assert_eq!(
            pngs(&dir.path().join(&out)),
            vec!["frame-00001.png", "frame-00002.png"]
        );
    }
    // Playing off the recorded pattern works, with a warning.
    let out = run(
        dir.path(),
        &["play", "car.baked", "--size", "64x64", "--frames", "0..1"],
        true,
    );
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("warning"),
        "no warning for another size"
    );
}

#[test]
fn demo_exports_a_scene_that_imports_back_with_the_same_triangles() {
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let demo = "demo --triangles 10000 --size 64x64 --out-dir out --export-scene car.glb";
    let out = run(dir.path(), &args(demo), true);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("index triangles")
            && text.contains("draws per frame")
            && text.contains("ms per frame"),
        "{text}"
    );
    assert!(!pngs(&dir.path().join("out/frames")).is_empty());
    // The demo shows its glass: baked and played at opacity 0.35.
    assert!(text.contains("glass at opacity 0.35"), "{text}");
    let baked: trisort_format::Baked = trisort_format::container::read_file(
        trisort_format::FileKind::Baked,
        &dir.path().join("out/demo.baked"),
    )
    .unwrap();
    assert_eq!(baked.settings.glass_opacity, 0.35);
    let exported = run_json(dir.path(), &["inspect", "car.glb"]);
    let builtin = run_json(dir.path(), &["inspect", "demo:10000"]);
    assert_eq!(exported["triangles"], builtin["triangles"]);
}
