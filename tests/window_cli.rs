//! `trisort play --window` through the real binary: a clean error without a display, and, where
//! `xvfb-run` is installed (`apt-get install xvfb`), the viewer playing in a virtual X server
//! until `--window-frames` frames were presented.

mod support;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use support::*;

const NO_DISPLAY: &str = "no display: --window needs X11 or Wayland; use --out-dir for PNG frames";

/// `play --window` with every display variable removed.
fn play_window_without_display(dir: &Path, args: &[&str]) -> std::process::Output {
    trisort(dir)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .args(["play"])
        .args(args)
        .output()
        .expect("spawn trisort")
}

#[test]
fn window_without_a_display_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    // The display is checked before the file is read, so this needs neither a GPU nor a baked
    // file: the error is about the display, not the missing file.
    for args in [
        &["missing.baked", "--window"][..],
        &[
            "missing.baked",
            "--window",
            "--window-frames",
            "3",
            "--json",
        ][..],
    ] {
        let out = play_window_without_display(dir.path(), args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            out.status.code(),
            Some(1),
            "play {args:?} without a display: {stderr}"
        );
        assert!(
            stderr.contains(NO_DISPLAY),
            "play {args:?} without a display says: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(out.stdout.is_empty(), "nothing on stdout: {:?}", out.stdout);
    }
    // The automation options belong to --window: without it, a command-line error (exit 2).
    let out = play_window_without_display(dir.path(), &["missing.baked", "--window-frames", "3"]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
}

/// Whether `name` is an executable on PATH.
fn on_path(name: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|d| {
            let p = d.join(name);
            p.is_file()
                && std::fs::metadata(&p).is_ok_and(|m| {
                    use std::os::unix::fs::PermissionsExt;
                    m.permissions().mode() & 0o111 != 0
                })
        })
    })
}

/// Runs the binary under `xvfb-run` with `args`, killing it after `limit`; returns the exit
/// code, stdout and stderr.
fn under_xvfb(dir: &Path, args: &[&str], limit: Duration) -> (Option<i32>, String, String) {
    let (out_path, err_path) = (dir.join("xvfb.stdout"), dir.join("xvfb.stderr"));
    let mut cmd = Command::new("xvfb-run");
    cmd.current_dir(dir)
        .args(["-a", "-s", "-screen 0 640x480x24"])
        .arg(bin())
        .args(args)
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap());
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        cmd.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    let mut child = cmd.spawn().expect("spawn xvfb-run");
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "xvfb-run trisort {} still running after {limit:?}\n--- stderr\n{}",
                args.join(" "),
                std::fs::read_to_string(&err_path).unwrap_or_default()
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    (
        status.code(),
        std::fs::read_to_string(&out_path).unwrap(),
        std::fs::read_to_string(&err_path).unwrap(),
    )
}

#[test]
fn window_plays_frames_under_xvfb() {
    if !on_path("xvfb-run") {
        eprintln!(
            "skipping the windowed part: xvfb-run is not on PATH (apt-get install xvfb); \
             only the no-display error is tested"
        );
        return;
    }
    if !gpu_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    run(
        dir.path(),
        &[
            "bake",
            "demo:3000",
            "--path",
            "orbit:frames=4",
            "--size",
            "64x48",
            "-o",
            "w.baked",
        ],
        true,
    );
    for (mode, samples, frames) in [
        ("blend", "4", 5u64),
        ("depth", "1", 3),
        ("saturate", "4", 2),
    ] {
        let n = frames.to_string();
        let args = [
            "play",
            "w.baked",
            "--window",
            "--window-frames",
            &n,
            "--mode",
            mode,
            "--samples",
            samples,
            "--fps",
            "60",
            "--json",
        ];
        let (code, stdout, stderr) = under_xvfb(dir.path(), &args, Duration::from_secs(120));
        assert_eq!(
            code,
            Some(0),
            "xvfb-run trisort {}\n--- stdout\n{stdout}\n--- stderr\n{stderr}",
            args.join(" ")
        );
        let v: serde_json::Value = serde_json::from_str(&stdout)
            .unwrap_or_else(|e| panic!("bad JSON ({e}): {stdout}\n--- stderr\n{stderr}"));
        assert_eq!(v["presented_frames"].as_u64(), Some(frames), "{v}");
        assert_eq!(v["mode"].as_str(), Some(mode), "{v}");
        assert!(v["last_frame"].as_u64().is_some_and(|f| f < 4), "{v}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        // Played away from the recorded sample count: the player's warning is shown.
        assert_eq!(
            stderr.contains("recorded with 4"),
            samples != "4",
            "warnings: {stderr}"
        );
    }
}
