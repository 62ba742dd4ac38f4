//! Bundles through the real binary: `bake --path NAME=SPEC` repeated records every path and
//! merges all their frames into one index buffer; each clip then plays byte for byte as the
//! separate bake of its path does, and the bundle is smaller than the separate files together.
//! `record` with the same paths and `merge` give the same file. A frame range of a path bakes
//! as a clip of those frames alone. Paths a bundle cannot name are refused before recording.

use std::path::Path;

use trisort_format::{Baked, FileKind};

use crate::support::{args, gpu_tempdir, run, run_json};

const SCENE: &str = "demo:2000";
const SPIN: &str = "orbit:frames=3,degrees=40";
const HIGH: &str = "orbit:frames=2,degrees=30,elevation=40";

/// The PNG files `play` wrote into `dir`, in name order (their bytes).
fn frames(dir: &Path) -> Vec<Vec<u8>> {
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "png"))
        .collect();
    names.sort();
    names.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

/// `play` of `file` (more options in `more`) into `out`, and its frames.
fn play(d: &Path, file: &str, more: &str, out: &str) -> Vec<Vec<u8>> {
    let mut a = vec!["play", file, "--out-dir", out];
    a.extend(args(more));
    run(d, &a, true);
    frames(&d.join(out))
}

fn read(d: &Path, file: &str) -> Baked {
    trisort_format::read_file(FileKind::Baked, &d.join(file)).unwrap()
}

#[test]
fn a_bundle_plays_each_clip_as_its_separate_bake_and_is_smaller() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let bake = |paths: &[String], out: &str| {
        let mut a = vec!["bake", SCENE, "--size", "48x32", "-o", out];
        for p in paths {
            a.extend(["--path", p.as_str()]);
        }
        run_json(d, &a)
    };
    let v = bake(
        &[format!("spin={SPIN}"), format!("high={HIGH}")],
        "bundle.baked",
    );
    assert_eq!(v["frames"], 5, "{v}");
    let clips = &v["clips"];
    assert_eq!(clips[0]["name"], "spin");
    assert_eq!(
        (clips[0]["first"].as_u64(), clips[0]["frames"].as_u64()),
        (Some(0), Some(3))
    );
    assert_eq!(clips[1]["name"], "high");
    assert_eq!(
        (clips[1]["first"].as_u64(), clips[1]["frames"].as_u64()),
        (Some(3), Some(2))
    );
    bake(&[SPIN.to_string()], "spin.baked");
    bake(&[HIGH.to_string()], "high.baked");

    for (clip, file) in [("spin", "spin.baked"), ("high", "high.baked")] {
        let bundled = play(
            d,
            "bundle.baked",
            &format!("--clip {clip}"),
            &format!("b-{clip}"),
        );
        let separate = play(d, file, "", &format!("s-{clip}"));
        assert!(!separate.is_empty());
        assert!(
            bundled == separate,
            "clip {clip}: the bundle's frames differ from the separate bake's"
        );
    }
    let size = |f: &str| std::fs::metadata(d.join(f)).unwrap().len();
    let (bundle, apart) = (
        size("bundle.baked"),
        size("spin.baked") + size("high.baked"),
    );
    assert!(bundle < apart, "bundle {bundle} B, separate {apart} B");
    eprintln!("bundle {bundle} B against {apart} B for the separate files");

    // record with the same paths, then merge: the same bundle (clips, index buffer, draws).
    let rec = ["record", SCENE, "--size", "48x32", "-o", "bundle.rec"];
    let mut a = rec.to_vec();
    let (spin, high) = (format!("spin={SPIN}"), format!("high={HIGH}"));
    a.extend(["--path", &spin, "--path", &high]);
    run(d, &a, true);
    run(d, &args("merge bundle.rec -o merged.baked"), true);
    let (baked, merged) = (read(d, "bundle.baked"), read(d, "merged.baked"));
    assert_eq!(baked.clips, merged.clips);
    assert_eq!(baked.copies, merged.copies);
    assert_eq!(baked.draws, merged.draws);
    assert_eq!(baked.frames, merged.frames);

    // verify rebuilds the scene as the bake split it, over all the bundle's frames.
    let v = run_json(d, &["verify", "bundle.baked", "--scene", SCENE]);
    assert_eq!(v["ok"], true, "{v}");
}

#[test]
fn a_frame_range_bakes_as_a_clip_of_those_frames() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let whole = format!("bake {SCENE} --path {SPIN} --size 48x32 -o whole.baked");
    run(d, &args(&whole), true);
    let range = format!("bake {SCENE} --path {SPIN} --size 48x32 --frames 1..3 -o range.baked");
    let v = run_json(d, &args(&range));
    assert_eq!(v["frames"], 2, "{v}");
    let clip = &v["clips"][0];
    assert_eq!(clip["name"], "main");
    assert_eq!(
        (clip["frames"].as_u64(), clip["path_first"].as_u64()),
        (Some(2), Some(1))
    );
    let of_range = play(d, "range.baked", "", "range");
    let of_whole = play(d, "whole.baked", "--frames 1..3", "whole");
    assert_eq!(of_range.len(), 2);
    assert!(
        of_range == of_whole,
        "the range's frames differ from the whole bake's"
    );
}

#[test]
fn paths_a_bundle_cannot_name_are_refused_before_recording() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let cases = [
        (
            format!("--path {SPIN} --path {HIGH}"),
            "the paths of a bundle are named",
        ),
        (
            format!("--path a={SPIN} --path a={HIGH}"),
            "two paths are named \"a\"",
        ),
        (
            format!("--path a={SPIN} --path b={HIGH} --frames 0..1"),
            "--frames takes a range of one path",
        ),
        (format!("--path {SPIN} --frames 2..9"), "frame range 2..9"),
    ];
    for (paths, needle) in cases {
        let line = format!("bake {SCENE} {paths} --size 32x32 -o x.baked");
        let out = run(d, &args(&line), false);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{line}: {err}");
        assert!(
            !d.join("x.baked.rec").exists() && !d.join("x.baked").exists(),
            "{line}"
        );
    }
}
