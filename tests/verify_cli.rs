//! `trisort verify --scene` through the real binary: the JSON keys scripts rely on (README § Using it),
//! graph and image checks together, difference images, a scene that is not the baked one,
//! off the pattern only with `--max-error` or `--measure-only`, the mutation check (a file whose order was
//! corrupted on purpose fails with exit code 3), and frames captured elsewhere
//! (`--frames-dir`).

use trisort_format::{Baked, FileKind, Recording};

use crate::support::*;

const SCENE: &str = "demo:10000";

/// A temporary directory holding the demo car baked (2 frames, 64², 4×) as `car.baked`
/// (recording beside it), or `None` to skip the test where there is no GPU.
fn baked_car() -> Option<tempfile::TempDir> {
    let dir = gpu_tempdir()?;
    let bake = format!(
        "bake {SCENE} --path orbit:frames=2,degrees=40 --size 64x64 --samples 4 -o car.baked"
    );
    run(dir.path(), &args(&bake), true);
    Some(dir)
}

#[test]
fn verify_reports_contract_keys_and_writes_difference_images() {
    let Some(dir) = baked_car() else {
        return;
    };
    let verify = format!(
        "verify car.baked --recording car.baked.rec --scene {SCENE} \
         --diff-dir diff --diff-all --frames 1..2"
    );
    let v = run_json(dir.path(), &args(&verify));
    assert_eq!(v["ok"], true, "{v}");
    assert_eq!(v["at_recorded_pattern"], true);
    let frames = v["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 1);
    let f = &frames[0];
    assert_eq!(f["frame"], 1);
    for key in [
        "frame",
        "graph_violations",
        "unordered_samples",
        "pixels_differing",
        "pixels_differing_ordered",
        "max_channel_diff",
        "max_channel_diff_ordered",
        "psnr",
        "flip_mean",
    ] {
        assert!(!f[key].is_null(), "verify --json lacks frames[].{key}: {f}");
    }
    assert_eq!(f["graph_violations"], 0);
    assert!(f["max_channel_diff_ordered"].as_u64().unwrap() <= 1);
    assert!(!f["srgb8"].is_null(), "the 8-bit sRGB figure is reported");
    for name in ["player", "reference", "diff", "unordered"] {
        let p = dir.path().join(format!("diff/00001-{name}.png"));
        let img = image::open(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        assert_eq!((img.width(), img.height()), (64, 64));
    }
    // The player's frame and the reference are the same picture.
    let a = image::open(dir.path().join("diff/00001-player.png")).unwrap();
    let b = image::open(dir.path().join("diff/00001-reference.png")).unwrap();
    assert_eq!(a.to_rgba8(), b.to_rgba8());
}

#[test]
fn another_scene_is_refused_with_a_clear_error() {
    let Some(dir) = baked_car() else {
        return;
    };
    let out = run(
        dir.path(),
        &["verify", "car.baked", "--scene", "demo:12000"],
        false,
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("not the scene the baked file was made from"),
        "{err}"
    );
}

/// Off the recorded pattern nothing passes unchecked: without `--max-error` the run
/// is refused before anything is drawn; `--measure-only` measures, says nothing was verified
/// and exits 4 unless `--allow-unverified`; `--max-error` below the measured error fails.
#[test]
fn off_pattern_is_checked_only_with_max_error_or_measured_only_on_request() {
    let Some(dir) = baked_car() else {
        return;
    };
    // Twice the recorded size.
    let off_pattern = [
        "verify",
        "car.baked",
        "--scene",
        SCENE,
        "--size",
        "128x128",
        "--frames",
        "0..1",
    ];
    let out = run(dir.path(), &off_pattern, false);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("off the recorded pattern") && err.contains("--max-error N"),
        "{err}"
    );
    let measured = [&off_pattern[..], &["--measure-only", "--json"]].concat();
    let out = run(dir.path(), &measured, false);
    assert_eq!(out.status.code(), Some(4));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["at_recorded_pattern"], false);
    assert_eq!(v["ok"], false);
    assert_eq!(v["verified"], false);
    assert_eq!(v["image_check"], "measured_only");
    assert!(v["frames"][0]["ok"].is_null(), "{v}");
    let max = v["frames"][0]["max_channel_diff_ordered"].as_u64().unwrap();
    assert!(max > 0, "holes show at twice the size: {v}");
    // And they are told apart from order errors: samples the file does not draw.
    let f = &v["frames"][0];
    assert!(
        f["hole_pixels"].as_u64().unwrap() > f["order_error_pixels"].as_u64().unwrap(),
        "{f}"
    );
    let text = run(
        dir.path(),
        &[&off_pattern[..], &["--measure-only"]].concat(),
        false,
    );
    assert!(String::from_utf8_lossy(&text.stdout).contains("NOTHING VERIFIED"));
    // Allowed: exit 0, and still not verified.
    let allowed = [&off_pattern[..], &["--measure-only", "--allow-unverified"]].concat();
    let v = run_json(dir.path(), &allowed);
    assert_eq!(
        (v["ok"].as_bool(), v["verified"].as_bool()),
        (Some(true), Some(false))
    );
    // A bound below the measured error fails (exit 3); at it, passes and says so.
    let bound = (max - 1).to_string();
    let out = run(
        dir.path(),
        &[&off_pattern[..], &["--max-error", &bound]].concat(),
        false,
    );
    assert_eq!(out.status.code(), Some(3));
    let v = run_json(
        dir.path(),
        &[&off_pattern[..], &["--max-error", &max.to_string()]].concat(),
    );
    assert_eq!(v["image_check"], "max_error");
    assert_eq!(v["verified"], true);
}

/// The mutation check: swapping the positions of two triangles drawn in frame 0 that the
/// recording orders (the heaviest edge between different materials) breaks the images, and
/// verify fails with exit code 3, writing the failing frame's images.
#[test]
fn corrupted_order_fails_verification() {
    let Some(dir) = baked_car() else {
        return;
    };
    let path = dir.path().join("car.baked");
    let mut baked: Baked = trisort_format::read_file(FileKind::Baked, &path).unwrap();
    let rec: Recording =
        trisort_format::read_file(FileKind::Recording, &dir.path().join("car.baked.rec")).unwrap();
    let local = |scene_id: u32| baked.scene_ids.binary_search(&scene_id).unwrap() as u32;
    let material = |t: u32| {
        let g = &baked.geometry;
        g.vertices[g.triangles[t as usize][0] as usize].material
    };
    // Positions in `copies` drawn in frame 0.
    let drawn: Vec<usize> = baked
        .frame_draws(0)
        .iter()
        .flat_map(|d| (d.first_index / 3..(d.first_index + d.index_count) / 3).map(|p| p as usize))
        .collect();
    let position = |t: u32| drawn.iter().copied().find(|&p| baked.copies[p] == t);
    let edge = rec.frames[0]
        .edges
        .iter()
        .filter(|e| material(local(e.from)) != material(local(e.to)))
        .max_by_key(|e| e.weight)
        .expect("frame 0 has an edge between different materials");
    let (a, b) = (local(edge.from), local(edge.to));
    let (pa, pb) = (position(a).unwrap(), position(b).unwrap());
    assert!(pa < pb, "front is drawn before back in the stored order");
    baked.copies.swap(pa, pb);
    trisort_format::write_file_atomic(FileKind::Baked, &path, &baked).unwrap();

    let verify = format!("verify car.baked --scene {SCENE} --frames 0..1 --diff-dir diff --json");
    let out = run(dir.path(), &args(&verify), false);
    assert_eq!(out.status.code(), Some(3));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["ok"], false);
    let f = &v["frames"][0];
    assert_eq!(f["ok"], false);
    assert!(f["pixels_differing_ordered"].as_u64().unwrap() > 0, "{f}");
    assert!(f["max_channel_diff_ordered"].as_u64().unwrap() > 1, "{f}");
    assert!(dir.path().join("diff/00000-diff.png").is_file());
    // The graph rules catch it too.
    let out = run(
        dir.path(),
        &["verify", "car.baked", "--recording", "car.baked.rec"],
        false,
    );
    assert_eq!(out.status.code(), Some(3));
}

/// Frames drawn elsewhere (here: `play --out-dir`) are checked with `--frames-dir` against the
/// exact reference with the recorded pattern's tolerance: as played they pass; one pixel
/// changed by more than 1/255 fails its frame (exit 3); a missing or wrong-size frame is an
/// error naming the file (exit 1); without `--scene` the option is refused (exit 2).
#[test]
fn captured_frames_are_checked_against_the_reference() {
    let Some(dir) = baked_car() else {
        return;
    };
    let d = dir.path();
    run(d, &args("play car.baked --out-dir captured"), true);
    let verify =
        format!("verify car.baked --recording car.baked.rec --scene {SCENE} --frames-dir captured");
    let v = run_json(d, &args(&verify));
    assert_eq!(v["ok"], true, "{v}");
    assert_eq!(v["captured"], true);
    assert_eq!(v["at_recorded_pattern"], true);
    assert_eq!(v["frames"].as_array().unwrap().len(), 2);
    assert_eq!(v["frames"][1]["pixels_differing"], 0, "{v}");
    assert!(v["frames"][1]["srgb8"].is_null(), "no player ran here");

    // One background pixel of frame 1 off by 40/255.
    let frame1 = d.join("captured/frame-00001.png");
    let mut img = image::open(&frame1).unwrap().to_rgba8();
    let p = img.get_pixel_mut(0, 0);
    p.0[0] = if p.0[0] >= 128 {
        p.0[0] - 40
    } else {
        p.0[0] + 40
    };
    img.save(&frame1).unwrap();
    let out = run(d, &[&args(&verify)[..], &["--json"]].concat(), false);
    assert_eq!(out.status.code(), Some(3));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let (f0, f1) = (&v["frames"][0], &v["frames"][1]);
    assert_eq!(f0["ok"], true, "{f0}");
    assert_eq!(f1["ok"], false, "{f1}");
    assert_eq!(f1["pixels_differing_ordered"], 1, "{f1}");
    assert_eq!(f1["max_channel_diff_ordered"], 40, "{f1}");

    // A frame of another size, then none at all: errors naming the file.
    let frame0 = d.join("captured/frame-00000.png");
    image::RgbaImage::new(32, 32).save(&frame0).unwrap();
    let out = run(d, &args(&verify), false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("frame-00000.png") && err.contains("32x32"),
        "{err}"
    );
    std::fs::remove_file(&frame0).unwrap();
    let out = run(d, &args(&verify), false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("frame-00000.png") && err.contains("missing"),
        "{err}"
    );

    let out = run(d, &args("verify car.baked --frames-dir captured"), false);
    assert_eq!(out.status.code(), Some(2));
}
