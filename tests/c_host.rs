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

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::support::{args, gpu_tempdir, run};

/// The C API's static library, built next to this test binary (the CLI depends on the crate,
/// which builds its cdylib and staticlib too).
fn static_library() -> PathBuf {
    let deps = std::env::current_exe()
        .unwrap()
        .parent()
        .unwrap()
        .to_path_buf();
    let lib = deps.join("libtrisort_capi.a");
    assert!(lib.exists(), "{} is missing", lib.display());
    lib
}

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
        .arg(static_library())
        // -lstdc++: the scene importer links meshoptimizer (C++) through the meshopt crate.
        .args([
            "-lEGL",
            "-lGLESv2",
            "-lstdc++",
            "-lpthread",
            "-ldl",
            "-lm",
            "-o",
        ])
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

#[test]
fn c_host_draws_the_demo_bake_like_the_player() {
    if !c_toolchain() {
        return;
    }
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let host = build_host(d);
    run(
        d,
        &args("bake demo:10000 --path orbit:frames=6,degrees=120 --size 96x96 --samples 4 -o car.baked"),
        true,
    );
    for mode in ["blend", "depth", "saturate"] {
        let (c_dir, rust_dir) = (d.join(format!("c-{mode}")), format!("rust-{mode}"));
        std::fs::create_dir_all(&c_dir).unwrap();
        let out = Command::new(&host)
            .arg(d.join("car.baked"))
            .arg(&c_dir)
            .arg(mode)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "host failed in {mode} mode:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
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
