//! The C host (examples/c-gles/host.c): built with the system C compiler against the C API's
//! static library and Mesa's EGL/GLES, it draws the demo bake through `trisort.h` with its own
//! shaders (the basic model: one light plus ambient), and its frames must match the Rust
//! player's `--shading basic` on the same CPU driver.
//!
//! Tolerance: at most 0.5% of a frame's pixels may differ by more than 2/255 in a channel
//! (rasterizers of two APIs may place an edge sample differently). Measured on Mesa 22.3.6
//! (llvmpipe for GLES, lavapipe for the player's Vulkan): 0 pixels differ, in every mode
//! (`cargo test --test tests c_host -- --nocapture` prints each frame's count and largest
//! difference).
//!
//! With `--shading pbr` the host draws with the player's own shaders, exported by `trisort
//! export-shaders --lang glsl-es-300`, fed the bytes the player uploads (`trisort_gpu_*`); its
//! blend-mode frames (4×) must equal `trisort play --shading pbr`'s within 1/255 on at least
//! 99.9% of the pixels. Measured on Mesa 22.3.6: at most 1 pixel a frame differs, by 1/255
//! (the demo car and the textured CesiumMilkTruck).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use crate::support::{args, gpu_tempdir, run};

/// Whether the C toolchain and Mesa's EGL/GLES headers are here; CI (which installs them with
/// scripts/ensure-c-host.sh) requires them.
fn c_toolchain() -> bool {
    let ok = Command::new("gcc").arg("--version").output().is_ok()
        && Path::new("/usr/include/EGL/egl.h").exists()
        && Path::new("/usr/include/GLES3/gl3.h").exists();
    if !ok {
        assert!(
            std::env::var_os("CI").is_none(),
            "gcc, libegl-dev or libgles-dev missing: run scripts/ensure-c-host.sh"
        );
        eprintln!("skipping: gcc or the EGL/GLES headers are missing (scripts/ensure-c-host.sh)");
    }
    ok
}

/// Builds the host into `dir` with the command examples/c-gles/README.md gives.
pub fn build_host(dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let exe = dir.join("host");
    let out = Command::new("gcc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-O1", "-I"])
        .arg(root.join("capi/include"))
        .arg(root.join("examples/c-gles/host.c"))
        .arg(trisort_testkit::capi_static_library())
        // The player library needs no C++ runtime (scripts/test-capi-package.sh checks the
        // shared one with ldd).
        .args(["-lEGL", "-lGLESv2", "-lpthread", "-ldl", "-lm", "-o"])
        .arg(&exe)
        .output()
        .expect("run gcc");
    assert!(
        out.status.success(),
        "gcc failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    exe
}

/// Pixels of two PNG frames differing by more than `by` in a channel, and the largest
/// difference.
fn differing(a: &Path, b: &Path, by: u8) -> (usize, u8, usize) {
    let a = image::open(a).unwrap().to_rgb8();
    let b = image::open(b).unwrap().to_rgb8();
    assert_eq!(a.dimensions(), b.dimensions());
    let mut count = 0;
    let mut max = 0u8;
    for (p, q) in a.pixels().zip(b.pixels()) {
        let d = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap();
        max = max.max(d);
        count += (d > by) as usize;
    }
    (count, max, (a.width() * a.height()) as usize)
}

/// The demo bake both host tests draw (6 frames, 96², 4×), baked once and written into each
/// test's directory as `car.baked`.
fn demo_bake(d: &Path) {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    let bytes = BYTES.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        run(
            dir.path(),
            &args("bake demo:10000 --path orbit:frames=6,degrees=120 --size 96x96 --samples 4 -o car.baked"),
            true,
        );
        std::fs::read(dir.path().join("car.baked")).unwrap()
    });
    std::fs::write(d.join("car.baked"), bytes).unwrap();
}

#[test]
fn c_host_draws_the_demo_bake_like_the_player() {
    if !c_toolchain() {
        return;
    }
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let host = build_host(d);
    demo_bake(d);
    for mode in ["blend", "depth", "saturate"] {
        let (c_dir, rust_dir) = (d.join(format!("c-{mode}")), format!("rust-{mode}"));
        run_host(&host, &d.join("car.baked"), &c_dir, mode, &[]);
        run(
            d,
            &[
                "play",
                "car.baked",
                "--out-dir",
                &rust_dir,
                "--mode",
                mode,
                "--backend",
                "vulkan",
                // The C host implements the basic model only (one light plus ambient).
                "--shading",
                "basic",
            ],
            true,
        );
        for f in 0..6 {
            let name = format!("frame-{f:05}.png");
            let (count, max, pixels) =
                differing(&c_dir.join(&name), &d.join(&rust_dir).join(&name), 2);
            eprintln!("{mode} frame {f}: {count} of {pixels} pixels differ by more than 2/255 (max {max})");
            assert!(
                count * 200 <= pixels,
                "{mode} frame {f}: {count} of {pixels} pixels differ by more than 2/255 (max {max})"
            );
        }
    }
}

/// Runs the host on `baked` into `out` with `extra` arguments after the mode; panics with its
/// stderr when it fails.
fn run_host(host: &Path, baked: &Path, out: &Path, mode: &str, extra: &[&Path]) {
    std::fs::create_dir_all(out).unwrap();
    let mut cmd = Command::new(host);
    cmd.arg(baked).arg(out).arg(mode);
    for a in extra {
        cmd.arg(a);
    }
    let result = cmd.output().unwrap();
    assert!(
        result.status.success(),
        "host failed ({mode}, {extra:?}):\n{}",
        String::from_utf8_lossy(&result.stderr)
    );
}

/// Plays `baked` with the host's PBR path (the exported GLSL in `shaders`) and with `trisort
/// play --shading pbr` in blend mode, and holds each of its `frames` frames to 1/255 on 99.9%
/// of its pixels.
fn compare_pbr(d: &Path, host: &Path, shaders: &Path, baked: &str, frames: usize) {
    let c_dir = d.join(format!("c-pbr-{baked}"));
    let rust_dir = format!("rust-pbr-{baked}");
    let (shading, pbr) = (Path::new("--shading"), Path::new("pbr"));
    let extra = [shading, pbr, Path::new("--shaders"), shaders];
    run_host(host, &d.join(baked), &c_dir, "blend", &extra);
    run(
        d,
        &[
            "play",
            baked,
            "--out-dir",
            &rust_dir,
            "--mode",
            "blend",
            "--backend",
            "vulkan",
            "--shading",
            "pbr",
        ],
        true,
    );
    for f in 0..frames {
        let name = format!("frame-{f:05}.png");
        let (c, r) = (c_dir.join(&name), d.join(&rust_dir).join(&name));
        let (count, max, pixels) = differing(&c, &r, 1);
        let (any, _, _) = differing(&c, &r, 0);
        eprintln!(
            "pbr {baked} frame {f}: {any} of {pixels} pixels differ, {count} by more than 1/255 \
             (max {max})"
        );
        assert!(
            count * 1000 <= pixels,
            "pbr {baked} frame {f}: {count} of {pixels} pixels differ by more than 1/255 (max {max})"
        );
        // Not vacuous: the scene covers part of the frame, in more than one colour.
        let img = image::open(&c).unwrap().to_rgb8();
        let colours: std::collections::HashSet<_> = img.pixels().map(|p| p.0).collect();
        assert!(
            colours.len() > 50,
            "pbr {baked} frame {f}: {} colours",
            colours.len()
        );
    }
}

#[test]
fn c_host_draws_pbr_with_the_exported_shaders_like_the_player() {
    if !c_toolchain() {
        return;
    }
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let host = build_host(d);
    run(
        d,
        &args("export-shaders --lang glsl-es-300 -o shaders"),
        true,
    );
    let shaders = d.join("shaders");
    for f in [
        "player.vert",
        "pbr_straight.frag",
        "bindings.txt",
        "layout.json",
    ] {
        assert!(shaders.join(f).exists(), "export-shaders wrote no {f}");
    }
    demo_bake(d);
    compare_pbr(d, &host, &shaders, "car.baked", 6);
    // A textured scene: the sRGB and linear texture arrays with their mips.
    if let Some(truck) = crate::support::scene("CesiumMilkTruck") {
        run(
            d,
            &[
                "bake",
                &truck,
                "--path",
                "orbit:frames=3",
                "--size",
                "96x96",
                "--samples",
                "4",
                "-o",
                "truck.baked",
            ],
            true,
        );
        compare_pbr(d, &host, &shaders, "truck.baked", 3);
    }
    // Without the folder of shaders the host says what to run.
    let out = Command::new(&host)
        .arg(d.join("car.baked"))
        .arg(d)
        .args(["blend", "--shading", "pbr"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("trisort export-shaders"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn export_shaders_refuses_bad_arguments_and_writes_every_language() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bad = run(d, &args("export-shaders --lang hlsl -o out"), false);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("glsl-es-300"));
    std::fs::write(d.join("file"), b"").unwrap();
    let onto_file = run(d, &args("export-shaders --lang wgsl -o file"), false);
    assert_eq!(onto_file.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&onto_file.stderr).contains("not a directory"),
        "{}",
        String::from_utf8_lossy(&onto_file.stderr)
    );
    for (lang, file) in [
        ("glsl-es-300", "pbr_straight.frag"),
        ("spirv", "pbr_straight.frag.spv"),
        ("wgsl", "pbr.wgsl"),
    ] {
        let out = format!("out-{lang}");
        run(d, &["export-shaders", "--lang", lang, "-o", &out], true);
        assert!(d.join(&out).join(file).exists(), "{lang}: no {file}");
        let layout: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join(&out).join("layout.json")).unwrap())
                .unwrap();
        assert_eq!(layout["lang"], lang);
        assert!(
            layout["bindings"].as_array().unwrap().len() >= 9,
            "{layout}"
        );
    }
    spirv_validates(&d.join("out-spirv"));
    // No temporary folder is left behind.
    let names: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.starts_with('.')), "{names:?}");
}

/// Every SPIR-V module in `dir` passes Khronos' validator for Vulkan 1.0 (`spirv-val`, Debian's
/// spirv-tools: scripts/ensure-c-host.sh installs it; CI requires it). The GLSL ES files need no
/// such check: the PBR test compiles them with Mesa's GLES compiler.
fn spirv_validates(dir: &Path) {
    let modules: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "spv"))
        .collect();
    assert!(modules.len() >= 3, "{modules:?}");
    if Command::new("spirv-val").arg("--version").output().is_err() {
        assert!(
            std::env::var_os("CI").is_none(),
            "spirv-val missing: run scripts/ensure-c-host.sh"
        );
        eprintln!("skipping the SPIR-V validation: spirv-val is missing (spirv-tools)");
        return;
    }
    for m in &modules {
        let out = Command::new("spirv-val")
            .args(["--target-env", "vulkan1.0"])
            .arg(m)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}: {}{}",
            m.display(),
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn c_host_reports_a_bad_file_and_exits_non_zero() {
    if !c_toolchain() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let host = build_host(dir.path());
    let bad = dir.path().join("bad.baked");
    std::fs::write(&bad, b"TRISBAK\0 truncated").unwrap();
    let out = Command::new(&host)
        .arg(&bad)
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("trisort_open_path failed") && err.contains("bad.baked"),
        "{err}"
    );
}

/// `host --clip NAME` draws only that clip's frames (ABI 6: `trisort_clip_find`,
/// `trisort_clip_frames`), named by the file's frame numbers and equal to the same frames of a
/// run over every frame; an unknown name fails listing the file's clips. The demo bake is
/// rewritten as two clips, "approach" (frames 0..2) and "orbit" (2..6).
#[test]
fn c_host_draws_one_clip_of_a_bundle() {
    if !c_toolchain() {
        return;
    }
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let host = build_host(d);
    demo_bake(d);
    let kind = trisort_format::FileKind::Baked;
    let mut baked: trisort_format::Baked =
        trisort_format::read_file(kind, &d.join("car.baked")).unwrap();
    assert_eq!(baked.frames.len(), 6);
    let whole = baked.clips[0].clone();
    baked.clips = vec![
        trisort_format::Clip {
            name: "approach".into(),
            count: 2,
            ..whole.clone()
        },
        trisort_format::Clip {
            name: "orbit".into(),
            first: 2,
            count: 4,
            path_first: 2,
            ..whole
        },
    ];
    baked.check_structure().unwrap();
    let bundle = d.join("bundle.baked");
    trisort_format::write_file_atomic(kind, &bundle, &baked).unwrap();

    let (all, orbit) = (d.join("all"), d.join("orbit"));
    run_host(&host, &bundle, &all, "blend", &[]);
    run_host(
        &host,
        &bundle,
        &orbit,
        "blend",
        &[Path::new("--clip"), Path::new("orbit")],
    );
    let mut names: Vec<String> = std::fs::read_dir(&orbit)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    let want: Vec<String> = (2..6).map(|f| format!("frame-{f:05}.png")).collect();
    assert_eq!(names, want);
    for name in &want {
        let (count, max, _) = differing(&orbit.join(name), &all.join(name), 0);
        assert_eq!(
            (count, max),
            (0, 0),
            "{name}: the clip's frame is the file's frame"
        );
    }

    std::fs::create_dir_all(d.join("none")).unwrap();
    let out = Command::new(&host)
        .arg(&bundle)
        .arg(d.join("none"))
        .args(["blend", "--clip", "door"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("\"door\"") && err.contains("approach, orbit"),
        "{err}"
    );
}
