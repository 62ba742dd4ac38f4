//! Baking on several machines through the real binary: `record --shard I/N|auto`
//! in balanced frame ranges, `record --phase union` (G written once), phase 2 per shard and
//! `merge --join` give the bytes of a one-machine `bake`; every step refuses what does not
//! belong to it, naming the file; `merge` refuses recordings of different devices unless
//! `--allow-mixed-devices`, whose bake says so. The same chain on a real Slurm cluster is
//! `scripts/slurm/test-local-slurm.sh`.

use std::path::Path;
use std::time::{Duration, Instant};

use trisort_format::{Baked, FileKind, Recording};
use trisort_merger::synth::{split_frames, turntable, Turntable};

use crate::support::*;

/// The demo car's default path (48 frames) at a small size: what the shards record.
const SIZE: &str = "64x64";

/// `record demo --path demo --size SIZE` followed by `extra`.
fn record<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec!["record", "demo", "--path", "demo", "--size", SIZE];
    v.extend_from_slice(extra);
    v
}

/// The frames a recording's `--json` says it recorded.
fn frames_of(v: &serde_json::Value) -> (u64, u64) {
    let f = v["per_frame"].as_array().unwrap();
    let first = f.first().unwrap()["frame"].as_u64().unwrap();
    (first, first + f.len() as u64)
}

/// A command for the binary with no batch scheduler in its environment.
fn no_scheduler(d: &Path) -> std::process::Command {
    let mut c = trisort(d);
    for k in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_MIN",
        "SLURM_ARRAY_TASK_COUNT",
        "JOB_COMPLETION_INDEX",
        "TRISORT_SHARDS",
    ] {
        c.env_remove(k);
    }
    c
}

fn read(d: &Path, name: &str) -> Vec<u8> {
    std::fs::read(d.join(name)).unwrap()
}

/// Five shards of 48 frames (9, 10, 9, 10, 10: balanced, unequal), phase 1 each, the union,
/// phase 2 each (two of them told their shard by Slurm's and Kubernetes' variables) and
/// `merge --join`: the baked file and the joined recording equal `bake`'s byte for byte, and
/// the union equals a one-machine phase-1 recording of the whole path. Unions that miss a
/// shard or take a phase-2 recording are refused naming the file.
#[test]
fn five_shards_bake_the_one_machine_bytes() {
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let d = dir.path();
    run(
        d,
        &args(&format!(
            "bake demo --path demo --size {SIZE} -o local.baked"
        )),
        true,
    );
    let bounds = [0, 9, 19, 28, 38, 48];
    phase1_shards_record_balanced_ranges(d, &bounds);
    let vis: Vec<String> = (0..5).map(|i| format!("vis-{i}.rec")).collect();
    let vis: Vec<&str> = vis.iter().map(String::as_str).collect();
    union_equals_one_machines_phase1(d, &vis);
    bad_unions_and_phase2_settings_are_refused(d, &vis);
    phase2_shards_find_their_shard(d, &bounds);
    union_refuses_a_phase2_recording(d);
    join_gives_the_one_machine_bytes(d);
}

/// Phase 1 of each of the five shards records its balanced frame range.
fn phase1_shards_record_balanced_ranges(d: &Path, bounds: &[u64; 6]) {
    for i in 0..5 {
        let shard = format!("{i}/5");
        let v = run_json(
            d,
            &record(&[
                "--phase",
                "visibility",
                "--shard",
                &shard,
                "-o",
                "vis-{shard}.rec",
            ]),
        );
        assert_eq!(frames_of(&v), (bounds[i], bounds[i + 1]), "shard {shard}");
        assert!(d.join(format!("vis-{i}.rec")).is_file());
    }
}

/// The union of the five phase-1 recordings is a one-machine phase-1 recording's bytes.
fn union_equals_one_machines_phase1(d: &Path, vis: &[&str]) {
    let mut union = record(&["--phase", "union", "-o", "union.rec", "--visibility"]);
    union.extend_from_slice(vis);
    let v = run_json(d, &union);
    assert_eq!(v["frames"], 48);
    run(
        d,
        &record(&["--phase", "visibility", "-o", "whole-vis.rec"]),
        true,
    );
    assert!(
        read(d, "union.rec") == read(d, "whole-vis.rec"),
        "union = one machine's phase 1"
    );
}

/// A union missing shard 3, and phase 2 with other settings than phase 1's, are refused.
fn bad_unions_and_phase2_settings_are_refused(d: &Path, vis: &[&str]) {
    // A union missing shard 3, and one given a phase-2 recording, are refused.
    let mut missing = record(&["--phase", "union", "-o", "bad.rec", "--visibility"]);
    missing.extend(vis.iter().filter(|v| **v != "vis-3.rec"));
    let err = refused(d, &missing);
    assert!(
        err.contains("frame 38") || err.contains("comes next"),
        "{err}"
    );
    assert!(!d.join("bad.rec").exists());

    // Phase 2 with other settings than phase 1's is refused, naming the difference.
    let o = run(
        d,
        &record(&[
            "--samples",
            "1",
            "--phase",
            "graphs",
            "--shard",
            "0/5",
            "--visibility",
            "union.rec",
            "-o",
            "bad.rec",
        ]),
        false,
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("union.rec") && err.contains("samples \"4\" vs \"1\""),
        "{err}"
    );
    assert!(!d.join("bad.rec").exists());
}

/// Phase 2 of each shard, two told their shard by Slurm's and Kubernetes' variables, covers
/// its balanced range.
fn phase2_shards_find_their_shard(d: &Path, bounds: &[u64; 6]) {
    for i in 0..5u64 {
        let out = format!("graphs-{i}.rec");
        let mut c = no_scheduler(d);
        let mut a = record(&["--phase", "graphs", "--visibility", "union.rec", "-o", &out]);
        let fixed = format!("{i}/5");
        match i {
            // Slurm: an array 7-11 (task ids need not start at 0).
            0 => {
                c.env("SLURM_ARRAY_TASK_ID", "7")
                    .env("SLURM_ARRAY_TASK_MIN", "7")
                    .env("SLURM_ARRAY_TASK_COUNT", "5");
                a.extend(["--shard", "auto"]);
            }
            // Kubernetes: an Indexed Job of 5 completions.
            1 => {
                c.env("JOB_COMPLETION_INDEX", "1")
                    .env("TRISORT_SHARDS", "5");
                a.extend(["--shard", "auto"]);
            }
            _ => a.extend(["--shard", fixed.as_str()]),
        }
        let o = c.args(&a).arg("--json").output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let i = i as usize;
        assert_eq!(
            frames_of(&v),
            (bounds[i], bounds[i + 1]),
            "phase 2 of shard {i}"
        );
    }
}

/// A union given a phase-2 recording is refused, naming it.
fn union_refuses_a_phase2_recording(d: &Path) {
    let err = refused(
        d,
        &record(&[
            "--phase",
            "union",
            "-o",
            "bad.rec",
            "--visibility",
            "graphs-0.rec",
        ]),
    );
    assert!(
        err.contains("graphs-0.rec") && err.contains("not a phase-1"),
        "{err}"
    );
}

/// `merge --join` of the shards, given out of order, writes the one-machine bytes; without
/// --join the bake names the five recordings.
fn join_gives_the_one_machine_bytes(d: &Path) {
    // Given out of order: join sorts the shards by frame.
    run(
        d,
        &args("merge graphs-3.rec graphs-1.rec graphs-0.rec graphs-4.rec graphs-2.rec --join sharded.baked.rec -o sharded.baked"),
        true,
    );
    assert!(
        read(d, "sharded.baked.rec") == read(d, "local.baked.rec"),
        "joined recording"
    );
    assert!(
        read(d, "sharded.baked") == read(d, "local.baked"),
        "baked file"
    );
    // Without --join the bake names the five recordings: the same draws, another file.
    run(
        d,
        &args(
            "merge graphs-0.rec graphs-1.rec graphs-2.rec graphs-3.rec graphs-4.rec -o five.baked",
        ),
        true,
    );
    let five: Baked = trisort_format::read_file(FileKind::Baked, &d.join("five.baked")).unwrap();
    let local: Baked = trisort_format::read_file(FileKind::Baked, &d.join("local.baked")).unwrap();
    assert_eq!(five.recording_hashes.len(), 5);
    assert_eq!((five.copies, five.draws), (local.copies, local.draws));
}

/// A shard's phase 2 interrupted after its first frame (the other frames' result files are
/// taken by folders, so the failure point does not depend on timing) exits 1 naming the file
/// and keeps what it finished; the rerun resumes and writes the uninterrupted shard's bytes.
#[test]
fn an_interrupted_shard_resumes_to_identical_bytes() {
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let d = dir.path();
    run(
        d,
        &record(&["--phase", "visibility", "-o", "vis.rec"]),
        true,
    );
    let shard = record(&[
        "--phase",
        "graphs",
        "--visibility",
        "vis.rec",
        "--shard",
        "1/4",
    ]);
    let with_out = |out: &'static str| {
        let mut a = shard.clone();
        a.extend(["-o", out]);
        a
    };
    run(d, &with_out("clean.rec"), true);
    // Kill a run as soon as its partial folder exists, then block frames 13..24 of phase 2.
    let mut child = trisort(d)
        .args(with_out("resumed.rec"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let partial = d.join("resumed.rec.partial");
    let t0 = Instant::now();
    while !partial.join("key").exists() && t0.elapsed() < Duration::from_secs(120) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "finished before the kill"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let mut planted = vec![];
    for f in 13..24 {
        let name = partial.join(format!("graph-{f:07}"));
        if !name.exists() {
            std::fs::create_dir_all(name.join("in-the-way")).unwrap();
            planted.push(name);
        }
    }
    let out = trisort(d).args(with_out("resumed.rec")).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("graph-00000"), "names the file: {err}");
    assert!(partial.join("graph-0000012").is_file(), "frame 12 kept");
    for p in &planted {
        std::fs::remove_dir_all(p).unwrap();
    }
    let out = run(d, &with_out("resumed.rec"), true);
    assert!(String::from_utf8_lossy(&out.stderr).contains("resuming"));
    assert!(read(d, "resumed.rec") == read(d, "clean.rec"));
    assert!(!partial.exists());
}

/// Bad shards are refused before any GPU work: `--shard auto` outside a scheduler, or with
/// half of a scheduler's variables or a malformed one (exit 1, naming the variables);
/// `I/N` out of range or with `--frames` (exit 2, the command line); more shards than frames.
#[test]
fn bad_shards_are_refused_naming_the_cause() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fail = |env: &[(&str, &str)], shard: &str, code: i32, expect: &str| {
        let mut c = no_scheduler(d);
        for (k, v) in env {
            c.env(k, v);
        }
        let o = c
            .args(record(&[
                "--phase",
                "visibility",
                "--shard",
                shard,
                "-o",
                "x.rec",
            ]))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{shard} {env:?}: {err}");
        assert!(err.contains(expect), "{shard} {env:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(!d.join("x.rec").exists());
    };
    fail(&[], "auto", 1, "SLURM_ARRAY_TASK_ID");
    fail(
        &[("SLURM_ARRAY_TASK_ID", "2")],
        "auto",
        1,
        "SLURM_ARRAY_TASK_COUNT",
    );
    fail(
        &[
            ("SLURM_ARRAY_TASK_ID", "two"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ],
        "auto",
        1,
        "SLURM_ARRAY_TASK_ID=\"two\" is not a number",
    );
    fail(
        &[("JOB_COMPLETION_INDEX", "0")],
        "auto",
        1,
        "TRISORT_SHARDS",
    );
    fail(
        &[("JOB_COMPLETION_INDEX", "4"), ("TRISORT_SHARDS", "4")],
        "auto",
        1,
        "out of range",
    );
    fail(&[], "4/4", 2, "bad shard");
    fail(&[], "0/0", 2, "bad shard");
    fail(&[], "1", 2, "bad shard");
    fail(&[], "0/49", 1, "use at most 48");
    let o = no_scheduler(d)
        .args(record(&[
            "--shard", "0/2", "--frames", "0..4", "-o", "x.rec",
        ]))
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = no_scheduler(d)
        .args(record(&["--phase", "union", "-o", "x.rec"]))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("--visibility"), "{err}");
}

/// The stderr of `trisort ARGS` in `d`, which must fail.
fn refused(d: &Path, args: &[&str]) -> String {
    String::from_utf8_lossy(&run(d, args, false).stderr).into_owned()
}

/// Writes the synthetic turntable's frames 0..2, 2..6, 6..9 as `r0.rec`…`r2.rec`, after
/// `forge` changed them; returns the whole recording.
fn write_parts(d: &Path, forge: impl Fn(usize, &mut Recording)) -> Recording {
    let rec = turntable(&Turntable {
        objects: 4,
        sides: 10,
        frames: 9,
        samples: 64,
        ..Turntable::default()
    });
    for (k, mut p) in split_frames(&rec, &[0, 2, 6]).into_iter().enumerate() {
        forge(k, &mut p);
        let path = d.join(format!("r{k}.rec"));
        trisort_format::write_file_atomic(FileKind::Recording, &path, &p).unwrap();
    }
    rec
}

const PARTS: &str = "merge r0.rec r1.rec r2.rec -o out.baked";

/// `merge` refuses frame ranges recorded on another device, driver or backend, naming the
/// file and both values, and says how to merge anyway; `--allow-mixed-devices` merges them
/// with a warning and a baked device of `mixed: …` naming each device's frames; any other
/// difference (size, samples) is refused even then; `--join` never mixes.
#[test]
fn mixed_devices_are_refused_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_parts(d, |k, p| {
        if k == 1 {
            p.device.adapter = "NVIDIA H200".into();
            p.device.driver = "NVIDIA 550.54".into();
        }
    });
    let err = refused(d, &args(PARTS));
    for want in [
        "r1.rec",
        "r0.rec",
        "another device",
        "NVIDIA H200",
        "NVIDIA 550.54",
        "--allow-mixed-devices",
    ] {
        assert!(err.contains(want), "{want}: {err}");
    }
    assert!(!d.join("out.baked").exists());
    let mut join = args(PARTS);
    join.extend(["--join", "joined.rec"]);
    let o = run(d, &join, false);
    assert!(!d.join("joined.rec").exists());
    drop(o);
    let mut join_mixed = join.clone();
    join_mixed.push("--allow-mixed-devices");
    assert_eq!(run(d, &join_mixed, false).status.code(), Some(2));

    let mut allow = args(PARTS);
    allow.push("--allow-mixed-devices");
    let o = run(d, &allow, true);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("warning") && err.contains("r1.rec") && err.contains("NVIDIA H200"),
        "{err}"
    );
    let baked: Baked = trisort_format::read_file(FileKind::Baked, &d.join("out.baked")).unwrap();
    assert!(
        baked.device.adapter.starts_with("mixed: "),
        "{:?}",
        baked.device
    );
    assert!(
        baked.device.adapter.contains("NVIDIA H200 (frames 2..6)"),
        "{:?}",
        baked.device
    );
    assert!(
        baked.device.driver.contains("NVIDIA 550.54 (frames 2..6)"),
        "{:?}",
        baked.device
    );
    let inspect = run_json(d, &args("inspect out.baked"));
    assert!(
        inspect["device"].as_str().unwrap().starts_with("mixed: "),
        "{inspect}"
    );

    // Size and samples are never mixed.
    std::fs::remove_file(d.join("out.baked")).unwrap();
    write_parts(d, |k, p| {
        if k == 2 {
            p.settings.width *= 2;
            p.settings.samples = 5 - p.settings.samples;
            p.device.adapter = "NVIDIA H200".into();
        }
    });
    let err = refused(d, &allow);
    assert!(
        err.contains("r2.rec") && err.contains("size") && err.contains("samples"),
        "{err}"
    );
    assert!(!d.join("out.baked").exists());
}

/// `merge --join` of frame ranges (given in any order) writes the whole recording's bytes
/// and bakes the whole recording's bytes; without a GPU, on the synthetic turntable.
#[test]
fn merge_join_is_the_whole_recording() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let rec = write_parts(d, |_, _| {});
    trisort_format::write_file_atomic(FileKind::Recording, &d.join("whole.rec"), &rec).unwrap();
    run(d, &args("merge whole.rec -o whole.baked"), true);
    run(
        d,
        &args("merge r2.rec r0.rec r1.rec --join joined.rec -o joined.baked"),
        true,
    );
    assert!(read(d, "joined.rec") == read(d, "whole.rec"));
    assert!(read(d, "joined.baked") == read(d, "whole.baked"));
    // A missing range is refused, naming the files, and nothing is written.
    let err = refused(d, &args("merge r0.rec r2.rec --join j.rec -o j.baked"));
    assert!(
        err.contains("r2.rec") && err.contains("comes next"),
        "{err}"
    );
    assert!(!d.join("j.rec").exists() && !d.join("j.baked").exists());
}
