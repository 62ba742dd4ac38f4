//! `trisort play --window` through the real binary: a clean error without a display, and, where
//! `xvfb-run` is installed (`apt-get install xvfb`), the viewer playing in a virtual X server
//! until `--window-frames` frames were presented; where `xwd` is installed too
//! (`apt-get install x11-apps`), screenshots of the window equal the PNG of the same frame.

use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use crate::support::*;

/// `xvfb-run` on a display number of its own (`-a` could pick the number of a server that an
/// earlier `xvfb-run` killed without waiting for it), with `-noreset`: by default the X server
/// resets when its last client disconnects, and a client connecting during the reset fails
/// ("unable to open display"), which happened to the viewer when an `xwd` ran first under load.
fn xvfb_run(screen: &str) -> Command {
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let base = 1000 + (std::process::id() % 3000) * 8;
    let number = loop {
        let n = base + NEXT.fetch_add(1, Ordering::Relaxed);
        if !Path::new(&format!("/tmp/.X{n}-lock")).exists() {
            break n;
        }
    };
    let mut cmd = Command::new("xvfb-run");
    cmd.args([
        "-n",
        &number.to_string(),
        "-s",
        &format!("-screen 0 {screen} -noreset"),
    ])
    .env_remove("WAYLAND_DISPLAY")
    .env_remove("WAYLAND_SOCKET");
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        cmd.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    cmd
}

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
pub(crate) fn under_xvfb(
    dir: &Path,
    args: &[&str],
    limit: Duration,
) -> (Option<i32>, String, String) {
    let (out_path, err_path) = (dir.join("xvfb.stdout"), dir.join("xvfb.stderr"));
    let mut cmd = xvfb_run("640x480x24");
    cmd.current_dir(dir)
        .arg(bin())
        .args(args)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap());
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

/// CI sets `TRISORT_REQUIRE_DISPLAY=1` (and installs xvfb and x11-apps): there a missing tool
/// fails the test instead of skipping it.
pub(crate) fn tools_missing(tools: &[&str]) -> bool {
    let missing: Vec<&str> = tools.iter().copied().filter(|t| !on_path(t)).collect();
    if !missing.is_empty() && std::env::var("TRISORT_REQUIRE_DISPLAY").as_deref() == Ok("1") {
        panic!("{missing:?} not on PATH and TRISORT_REQUIRE_DISPLAY=1");
    }
    !missing.is_empty()
}

/// A temporary directory holding the demo car (3,000 triangles, 4 frames at 64×48) baked as
/// `w.baked`, or `None` to skip the test where there is no GPU.
fn baked_demo() -> Option<tempfile::TempDir> {
    let dir = gpu_tempdir()?;
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
    Some(dir)
}

#[test]
fn window_plays_frames_under_xvfb() {
    if tools_missing(&["xvfb-run"]) {
        eprintln!(
            "skipping the windowed part: xvfb-run is not on PATH (apt-get install xvfb); \
             only the no-display error is tested"
        );
        return;
    }
    let Some(dir) = baked_demo() else {
        return;
    };
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
        assert_eq!(v["fps"], 60.0, "{v}");
    }
}

/// A file with BC7 textures: the window uploads its texture arrays as headless `play` does,
/// as blocks where the device samples them (lavapipe does) and decoded to RGBA8 with
/// `--decode-textures`, which shows what a device without the feature draws.
#[test]
fn window_uploads_textures_as_play_does_and_decodes_them_when_asked() {
    if tools_missing(&["xvfb-run"]) {
        eprintln!("skipping the texture upload window test: xvfb-run is not on PATH");
        return;
    }
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let d = dir.path();
    let bake = "bake demo:400 --path orbit:frames=2 --size 48x32 --textures bc7 -o t.baked";
    run(d, &args(bake), true);
    for extra in [&[][..], &["--decode-textures"][..]] {
        let mut headless = vec!["play", "t.baked", "--out-dir", "frames"];
        headless.extend_from_slice(extra);
        let played = run_json(d, &headless);
        let mut window = vec![
            "play",
            "t.baked",
            "--window",
            "--window-frames",
            "2",
            "--json",
        ];
        window.extend_from_slice(extra);
        let (code, stdout, stderr) = under_xvfb(d, &window, Duration::from_secs(120));
        assert_eq!(code, Some(0), "{window:?}\n{stdout}\n--- stderr\n{stderr}");
        let v: serde_json::Value = serde_json::from_str(&stdout)
            .unwrap_or_else(|e| panic!("bad JSON ({e}): {stdout}\n--- stderr\n{stderr}"));
        assert_eq!(
            v["texture_upload"], played["texture_upload"],
            "{extra:?}: {v}"
        );
        if !extra.is_empty() {
            assert_eq!(
                v["texture_upload"]["srgb"], "rgba8 (decoded from bc7)",
                "{v}"
            );
        }
    }
}

/// Without `--fps` the viewer plays at the path's rate, stored in the baked file.
#[test]
fn window_plays_at_the_baked_fps() {
    if tools_missing(&["xvfb-run"]) {
        return;
    }
    let Some(dir) = gpu_tempdir() else { return };
    let bake = "bake demo:3000 --path orbit:frames=2 --size 32x24 --fps 12 -o f.baked";
    run(dir.path(), &args(bake), true);
    let play = args("play f.baked --window --window-frames 1 --json");
    let (code, stdout, stderr) = under_xvfb(dir.path(), &play, Duration::from_secs(120));
    assert_eq!(code, Some(0), "{stdout}\n--- stderr\n{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["fps"], 12.0, "{v}");
    assert_eq!(v["variant"], serde_json::Value::Null, "{v}");
}

/// An `xwd` dump (X Window Dump, version 7, ZPixmap, 24/32-bit TrueColor) as RGB rows.
struct Xwd {
    width: usize,
    height: usize,
    rgb: Vec<[u8; 3]>,
}

fn parse_xwd(bytes: &[u8]) -> Xwd {
    let field = |k: usize| u32::from_be_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap());
    let (header_size, version, format) = (field(0) as usize, field(1), field(2));
    assert_eq!((version, format), (7, 2), "xwd version 7 ZPixmap");
    let (width, height) = (field(4) as usize, field(5) as usize);
    let little_endian = field(7) == 0;
    let bits_per_pixel = field(11);
    assert_eq!(
        bits_per_pixel, 32,
        "xwd of a 24-bit screen stores 32 bits per pixel"
    );
    let bytes_per_line = field(12) as usize;
    let masks = [field(14), field(15), field(16)];
    let colormap_entries = field(19) as usize;
    let data = &bytes[header_size + 12 * colormap_entries..];
    let mut rgb = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let b: [u8; 4] = data[y * bytes_per_line + 4 * x..][..4].try_into().unwrap();
            let px = if little_endian {
                u32::from_le_bytes(b)
            } else {
                u32::from_be_bytes(b)
            };
            rgb.push(masks.map(|m| ((px & m) >> m.trailing_zeros()) as u8));
        }
    }
    Xwd { width, height, rgb }
}

#[test]
fn window_shows_the_png_frames_pixels() {
    if tools_missing(&["xvfb-run", "xwd"]) {
        eprintln!(
            "skipping the window screenshot test: it needs xvfb-run and xwd on PATH \
             (apt-get install xvfb x11-apps)"
        );
        return;
    }
    let Some(dir) = baked_demo() else {
        return;
    };
    for mode in ["blend", "saturate"] {
        let png_dir = format!("png-{mode}");
        run(
            dir.path(),
            &[
                "play",
                "w.baked",
                "--frames",
                "2..3",
                "--mode",
                mode,
                "--out-dir",
                &png_dir,
            ],
            true,
        );
        let png = image::open(dir.path().join(&png_dir).join("frame-00002.png"))
            .unwrap()
            .to_rgb8();
        // The viewer plays the one-frame range 2..3 for 120 presents at 60 fps while the script
        // dumps the screen every 0.1 s. With no window manager the window sits at (0, 0).
        let script = format!(
            "\"$0\" play w.baked --window --frames 2..3 --mode {mode} --fps 60 \
             --window-frames 120 >viewer.out 2>viewer.err & pid=$!; i=0; \
             while kill -0 $pid 2>/dev/null; do i=$((i+1)); xwd -root -silent >shot-$i.xwd; \
             sleep 0.1; done; wait $pid"
        );
        for old in std::fs::read_dir(dir.path()).unwrap() {
            let p = old.unwrap().path();
            if p.extension().is_some_and(|e| e == "xwd") {
                std::fs::remove_file(p).unwrap();
            }
        }
        let out = xvfb_run("320x240x24")
            .current_dir(dir.path())
            .args(["sh", "-c", &script])
            .arg(bin())
            .output()
            .expect("spawn xvfb-run");
        let viewer_err = std::fs::read_to_string(dir.path().join("viewer.err")).unwrap_or_default();
        assert!(
            out.status.success(),
            "{mode}: xvfb-run exited with {:?}\n--- xvfb-run stderr\n{}\n--- viewer stderr\n{viewer_err}",
            out.status.code(),
            String::from_utf8_lossy(&out.stderr)
        );
        let (mut matching, mut empty, mut shots) = (0, 0, 0);
        for entry in std::fs::read_dir(dir.path()).unwrap() {
            let p = entry.unwrap().path();
            if p.extension().is_none_or(|e| e != "xwd") {
                continue;
            }
            let bytes = std::fs::read(&p).unwrap();
            if bytes.len() < 100 {
                continue; // the server went away during the dump
            }
            shots += 1;
            let shot = parse_xwd(&bytes);
            assert!(shot.width >= 64 && shot.height >= 48);
            let window: Vec<[u8; 3]> = (0..48)
                .flat_map(|y| (0..64).map(move |x| (x, y)))
                .map(|(x, y)| shot.rgb[y * shot.width + x])
                .collect();
            let expected: Vec<[u8; 3]> = png.pixels().map(|p| p.0).collect();
            if window == expected {
                matching += 1;
            } else if window.iter().all(|&p| p == window[0]) {
                empty += 1; // before the first present or after the window closed
            } else {
                let differing = window.iter().zip(&expected).filter(|(a, b)| a != b).count();
                panic!(
                    "{mode}: {} shows a frame differing from the PNG at {differing} of {} pixels\n{viewer_err}",
                    p.display(),
                    expected.len()
                );
            }
        }
        assert!(
            matching > 0,
            "{mode}: none of {shots} screenshots shows the frame ({empty} show no window)\n{viewer_err}"
        );
        eprintln!(
            "{mode}: {matching} of {shots} screenshots equal the PNG, {empty} show no window"
        );
    }
}

/// `play --window` on a presorted file (paper 000): the free-viewpoint window turns the camera
/// as a turntable until `--window-frames` frames were presented, every one drawn sorted from
/// a camera outside the polyhedron.
#[test]
fn window_orbits_a_presorted_file() {
    if tools_missing(&["xvfb-run"]) {
        eprintln!("skipping the presorted window test: xvfb-run is not on PATH");
        return;
    }
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let d = dir.path();
    run(d, &args("presort demo:2000 -o w.presorted"), true);
    let window = args("play w.presorted --window --window-frames 40 --size 96x64 --json");
    let (code, stdout, stderr) = under_xvfb(d, &window, Duration::from_secs(120));
    assert_eq!(code, Some(0), "{stdout}\n--- stderr\n{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout)
        .unwrap_or_else(|e| panic!("bad JSON ({e}): {stdout}\n--- stderr\n{stderr}"));
    assert_eq!(v["kind"], "presorted");
    assert_eq!(v["presented"], 40, "{v}");
    assert!(!v["partitions"].as_array().unwrap().is_empty(), "{v}");
    // The turntable turned the camera 1.5 degrees after each frame but the last, from 30.
    let yaw = v["last_camera"]["yaw"].as_f64().unwrap();
    assert!((yaw - (30.0 + 1.5 * 39.0)).abs() < 1e-6, "{v}");
    assert!(
        stderr.contains("drag to orbit"),
        "the controls are told: {stderr}"
    );
}
