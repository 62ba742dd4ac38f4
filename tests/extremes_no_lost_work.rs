//! No lost work and determinism through the real binary: an interrupted `bake` resumes from
//! its finished frames to the same bytes as an uninterrupted one; an error in the middle of a
//! run ends with a message naming the file and keeps the finished frames; a device that
//! cannot hold the recording ends with a clear message instead of a panic; identical inputs
//! give byte-identical Recording and Baked files across runs and thread counts.
//!
//! Not tested, because lavapipe cannot lose its device or run out of memory on demand: a
//! failed device wait in the recorder is `RecordError::Device` ("finished frames are kept;
//! rerun to resume", exit 1); a wgpu validation or out-of-memory error outside an error scope
//! goes to wgpu's default handler, which panics, ending the process (exit 101, wgpu's
//! message) the way the kill below does — frames already stored in `OUT.partial/` stay, as
//! the kill test shows, and a rerun resumes from them.

use std::path::Path;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use crate::support::*;

const SCENE: &str = "demo:200000";
const PATH: &str = "orbit:frames=8,elevation=15";

/// The bake every test here runs, writing `out`.
fn bake(out: &str) -> Vec<&str> {
    bake_args(SCENE, PATH, "64x64", "4", out)
}

fn run_bake(dir: &Path, out: &str, threads: &str) -> std::process::Output {
    let out = trisort(dir)
        .env("RAYON_NUM_THREADS", threads)
        .args(bake(out))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The uninterrupted bake (2 threads) the tests here compare with, made once for all of
/// them: its baked file and its recording.
fn clean_bake() -> &'static (Vec<u8>, Vec<u8>) {
    static CLEAN: OnceLock<(Vec<u8>, Vec<u8>)> = OnceLock::new();
    CLEAN.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        run_bake(dir.path(), "clean.baked", "2");
        (
            read(dir.path(), "clean.baked"),
            read(dir.path(), "clean.baked.rec"),
        )
    })
}

/// A GPU test directory holding the uninterrupted bake as `clean.baked` and
/// `clean.baked.rec`; `None` to skip.
fn with_clean_bake() -> Option<tempfile::TempDir> {
    let dir = gpu_tempdir()?;
    let (baked, rec) = clean_bake();
    std::fs::write(dir.path().join("clean.baked"), baked).unwrap();
    std::fs::write(dir.path().join("clean.baked.rec"), rec).unwrap();
    Some(dir)
}

/// Finished frame files in a partial folder (everything but its `key`).
fn finished(partial: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(partial)
        .map(|d| {
            d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .filter(|n| n != "key")
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

fn read(dir: &Path, name: &str) -> Vec<u8> {
    std::fs::read(dir.join(name)).unwrap()
}

/// A bake killed as soon as it has opened its partial folder leaves no output file. A rerun
/// whose storage fails at phase-1 frame 3 (that frame's file name, and every later one's, is
/// taken by a non-empty folder) ends with exit 1 naming the file, and keeps frames 0–2. The
/// next rerun resumes from them and writes the same bytes as a clean bake (recording and
/// baked file), removing its partial folder and leaving no temporary file. The failure point
/// is set by the folder, not by timing, so the test holds on a device of any speed.
#[test]
fn an_interrupted_bake_resumes_to_identical_bytes() {
    let Some(dir) = with_clean_bake() else {
        return;
    };
    let d = dir.path();
    let mut child = trisort(d)
        .args(bake("resumed.baked"))
        .stderr(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let partial = d.join("resumed.baked.rec.partial");
    let t0 = Instant::now();
    while !partial.join("key").exists() && t0.elapsed() < Duration::from_secs(120) {
        if child.try_wait().unwrap().is_some() {
            panic!("the bake finished before it could be interrupted");
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!d.join("resumed.baked").exists() && !d.join("resumed.baked.rec").exists());

    // Every frame result not yet written, except phase-1 frames 0–2: its file name is taken.
    let done = finished(&partial);
    let mut planted = vec![];
    for phase in ["visibility", "graph"] {
        for f in 0..8 {
            let name = format!("{phase}-{f:07}");
            let may_finish = phase == "visibility" && f < 3;
            if !may_finish && !done.contains(&name) {
                std::fs::create_dir_all(partial.join(&name).join("in-the-way")).unwrap();
                planted.push(name);
            }
        }
    }
    let out = trisort(d).args(bake("resumed.baked")).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains(&planted[0]),
        "the message names {}: {err}",
        planted[0]
    );
    assert!(!d.join("resumed.baked").exists());
    let kept = finished(&partial);
    for f in 0..3 {
        let name = format!("visibility-{f:07}");
        assert!(kept.contains(&name), "finished frame {name} lost: {kept:?}");
        assert!(partial.join(&name).is_file());
    }
    for name in &planted {
        std::fs::remove_dir_all(partial.join(name)).unwrap();
    }

    let out = run_bake(d, "resumed.baked", "1");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("resuming"), "the rerun did not resume: {err}");
    assert!(!partial.exists(), "partial folder removed after success");
    assert!(read(d, "clean.baked.rec") == read(d, "resumed.baked.rec"));
    assert!(read(d, "clean.baked") == read(d, "resumed.baked"));
    let mut left: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(
        left,
        [
            "clean.baked",
            "clean.baked.rec",
            "resumed.baked",
            "resumed.baked.rec"
        ],
        "no temporary file is left"
    );
}

/// A bake killed while merging leaves its finished recording beside the output and
/// no baked file (both are written to a temporary name, then renamed). Run again, it merges
/// only: it says it resumes from the finished recording, reports `recording_reused`, leaves
/// the recording untouched (not rewritten) and writes the bytes an uninterrupted bake writes.
/// The same output with other settings records again.
#[test]
fn a_bake_killed_while_merging_merges_only_when_run_again() {
    let Some(dir) = with_clean_bake() else {
        return;
    };
    let d = dir.path();
    // The state a kill during the merge leaves: the recording, no baked file.
    let rec = d.join("merged.baked.rec");
    std::fs::copy(d.join("clean.baked.rec"), &rec).unwrap();
    let modified = |p: &Path| std::fs::metadata(p).unwrap().modified().unwrap();
    let before = modified(&rec);
    std::thread::sleep(Duration::from_millis(50));
    let out = run_bake_json(d, bake("merged.baked"));
    assert!(out.1.contains("merging only"), "{}", out.1);
    assert_eq!(out.0["recording_reused"], true, "{}", out.0);
    assert_eq!(modified(&rec), before, "the recording was written again");
    assert!(read(d, "clean.baked") == read(d, "merged.baked"));
    // Other settings (another size) for the same output: recorded again, and replaced.
    let out = run_bake_json(d, bake_args(SCENE, PATH, "48x48", "4", "merged.baked"));
    assert!(!out.1.contains("merging only"), "{}", out.1);
    assert_eq!(out.0["recording_reused"], false, "{}", out.0);
    assert_ne!(modified(&rec), before);
}

/// `bake ARGS --json` in `dir`, which must succeed: its JSON and its stderr.
fn run_bake_json(dir: &Path, mut args: Vec<&str>) -> (serde_json::Value, String) {
    args.push("--json");
    let out = run(dir, &args, true);
    let v = serde_json::from_slice(&out.stdout).unwrap();
    (v, String::from_utf8_lossy(&out.stderr).into_owned())
}

/// The same bake with 1 and 2 rayon threads, twice with 2 (the clean bake and one more):
/// byte-identical recordings and baked files (the merger tries all strategies and layouts in
/// parallel).
#[test]
fn bakes_are_byte_identical_across_runs_and_thread_counts() {
    let Some(dir) = with_clean_bake() else {
        return;
    };
    let d = dir.path();
    for (k, threads) in ["1", "2"].iter().enumerate() {
        let out = format!("t{k}.baked");
        run_bake(d, &out, threads);
        let rec = format!("{out}.rec");
        assert!(
            read(d, &rec) == read(d, "clean.baked.rec"),
            "recording {k} differs"
        );
        assert!(
            read(d, &out) == read(d, "clean.baked"),
            "baked file {k} differs"
        );
    }
}

/// A recording the device cannot hold (16384² at 4× needs 4 GiB of per-sample list heads to
/// capture, or a 12 GiB gather buffer to peel, beyond any binding limit) ends with exit 1 and
/// a message naming the limit, no panic, no output, before anything that size is allocated.
#[test]
fn a_recording_too_large_for_the_device_fails_cleanly() {
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let d = dir.path();
    let out = trisort(d)
        .args([
            "record",
            "demo:10000",
            "--path",
            "orbit:frames=2",
            "--size",
            "16384x16384",
            "--samples",
            "4",
            "-o",
            "huge.rec",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("huge.rec") && err.contains("binds at most"),
        "{err}"
    );
    assert!(!d.join("huge.rec").exists());
}
