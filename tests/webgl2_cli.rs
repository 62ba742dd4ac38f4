//! `--backend` and `--limits`: `play --limits webgl2` takes the player's GLES 3.0 /
//! WebGL2 path (data-texture bindings, direct draws), says so in `--json`, and writes the same
//! PNG bytes as the default path on the same adapter; `verify --limits webgl2` checks those
//! frames at the recorded pattern; `--backend gl` plays through EGL where Mesa's GL is
//! installed (skipped elsewhere unless TRISORT_REQUIRE_GPU=1).

use crate::support::*;

#[test]
fn webgl2_limits_play_the_same_bytes_and_verify() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    run(
        d,
        &args("bake demo:3000 --path orbit:frames=3 --size 64x48 -o w.baked"),
        true,
    );
    let full = run_json(d, &args("play w.baked --out-dir full"));
    assert_eq!(full["bindings"], "storage");
    let web = run_json(d, &args("play w.baked --limits webgl2 --out-dir web"));
    assert_eq!(web["bindings"], "textures", "{web}");
    assert_eq!(web["draw_path"], "direct", "{web}");
    for f in 0..3 {
        let name = format!("frame-{f:05}.png");
        let a = std::fs::read(d.join("full").join(&name)).unwrap();
        let b = std::fs::read(d.join("web").join(&name)).unwrap();
        assert!(a == b, "{name} differs between the tiers");
    }
    let v = run_json(
        d,
        &args("verify w.baked --recording w.baked.rec --scene demo:3000 --limits webgl2"),
    );
    assert_eq!(v["ok"], true, "{v}");
    assert_eq!(v["captured"], true, "{v}");
    assert_eq!(v["at_recorded_pattern"], true, "{v}");
    let out = run(d, &args("play w.baked --limits webgl3"), false);
    assert!(String::from_utf8_lossy(&out.stderr).contains("webgl2"));

    let Some(gl) = play_on_gl(
        d,
        "play w.baked --backend gl --limits webgl2 --out-dir gl --json",
    ) else {
        return;
    };
    assert_eq!(gl["backend"], "Gl", "{gl}");
    assert_eq!(gl["bindings"], "textures", "{gl}");
    assert_eq!(gl["draw_path"], "direct", "{gl}");
}

/// `trisort` run with `line` (a `play --backend gl … --json`): its JSON, or `None` where no GL
/// adapter opens (a skip on a developer machine, a failure under TRISORT_REQUIRE_GPU=1).
fn play_on_gl(d: &std::path::Path, line: &str) -> Option<serde_json::Value> {
    let gl = trisort(d).args(args(line)).output().unwrap();
    if !gl.status.success() {
        let err = String::from_utf8_lossy(&gl.stderr);
        if std::env::var(trisort_testkit::REQUIRE_GPU_ENV).as_deref() == Ok("1") {
            panic!("no GL adapter and TRISORT_REQUIRE_GPU=1: {err}");
        }
        eprintln!("skipping the GL part: {err}");
        return None;
    }
    Some(serde_json::from_slice(&gl.stdout).unwrap())
}

/// Pixels of two same-sized PNGs whose largest channel difference exceeds `threshold`.
fn pixels_over(a: &std::path::Path, b: &std::path::Path, threshold: u8) -> usize {
    let a = image::open(a).unwrap().to_rgba8();
    let b = image::open(b).unwrap().to_rgba8();
    assert_eq!(a.dimensions(), b.dimensions());
    a.pixels()
        .zip(b.pixels())
        .filter(|(p, q)| (0..4).any(|c| p[c].abs_diff(q[c]) > threshold))
        .count()
}

/// The demo car's licence plates carry the scene's only texture. wgpu's GL backend made a
/// one-layer texture array a plain 2D texture, which the shaders' array binding sampled as
/// black: GL drew the plates black where Vulkan drew them yellow. Played on GL (both binding
/// tiers), every frame must match the Vulkan player's but for a few pixels of rasterization
/// (a black plate is dozens of pixels off by more than 200 in this close-up).
#[test]
fn gl_player_samples_a_one_texture_scene_like_vulkan() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    run(
        d,
        &args("bake demo:3000 --path demo --size 128x128 -o p.baked"),
        true,
    );
    run(d, &args("play p.baked --out-dir vk"), true);
    for (tier, extra) in [("storage", ""), ("textures", " --limits webgl2")] {
        let line = format!("play p.baked --backend gl{extra} --out-dir gl-{tier} --json");
        let Some(json) = play_on_gl(d, &line) else {
            return;
        };
        assert_eq!(json["backend"], "Gl", "{json}");
        assert_eq!(json["bindings"], tier, "{json}");
        let frames = json["frames"].as_array().unwrap().len();
        assert_eq!(frames, 48, "{json}");
        for f in 0..frames {
            let name = format!("frame-{f:05}.png");
            let off = pixels_over(
                &d.join("vk").join(&name),
                &d.join(format!("gl-{tier}")).join(&name),
                32,
            );
            assert!(
                off <= 2,
                "{tier} {name}: {off} pixels differ from Vulkan's by > 32"
            );
        }
    }
}

/// `bench --limits webgl2` adds `merged_device`: the bake played on the GLES 3.0 / WebGL2
/// path, timed and checked against the exact reference like `merged`.
#[test]
fn bench_plays_merged_on_the_webgl2_path_too() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let b = run_json(
        d,
        &args(
            "bench demo:3000 --path orbit:frames=2 --size 48x48 --samples 4 --mode blend \
             --methods merged --repeats 1 --limits webgl2 --out b",
        ),
    );
    let rows = b["groups"][0]["rows"].as_array().unwrap();
    let row = |name: &str| {
        rows.iter()
            .find(|r| r["method"] == name)
            .unwrap_or_else(|| panic!("no {name} row: {b}"))
    };
    let device = row("merged_device");
    let variant = device["variant"].as_str().unwrap();
    assert!(
        variant.contains("textures bindings") && variant.contains("direct draws"),
        "{variant}"
    );
    assert_eq!(row("merged")["error"]["frames_exact"], 2, "{b}");
    assert_eq!(device["error"]["frames_exact"], 2, "{b}");
    assert!(
        b["methods"]["merged_device"]["ms_per_frame"].is_number(),
        "{b}"
    );
}
