//! Bad input for every reader, through the real binary: glTF scenes, TOML paths, Recording and
//! Baked files (truncated, wrong magic or version, checksum mismatch, header sizes that would
//! allocate gigabytes, forged lengths inside the payload, NaN and infinities, broken
//! structure) and mismatched recordings given to one merge. Each must end with exit 1, a
//! message naming the file and the problem, no panic, and no file left behind: no output, no temporary file, no
//! partial folder.

mod malformed;
mod scenes;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::Serialize;
use trisort_format::container::{encode, FileKind};
use trisort_format::{Baked, DeviceInfo, Phase, RecordSettings, Recording};
use trisort_merger::synth::{split_frames, turntable, Turntable};
use trisort_merger::{merge, MergeOptions};

use crate::support::*;

/// Every file under `dir`, relative, recursively.
fn files(dir: &Path) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            out.insert(p.strip_prefix(dir).unwrap().to_path_buf());
            if p.is_dir() {
                stack.push(p);
            }
        }
    }
    out
}

/// Runs `args` expecting failure with one of `codes`; the output must name `file` and
/// contain `problem` (case-insensitive), hold no panic, and the directory must be unchanged.
fn fails(dir: &Path, args: &[&str], codes: &[i32], file: &str, problem: &str) {
    let before = files(dir);
    let out = run(dir, args, false);
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let ctx = format!("trisort {}:\n{text}", args.join(" "));
    assert!(
        out.status.code().is_some_and(|c| codes.contains(&c)),
        "exit {:?}, expected one of {codes:?}; {ctx}",
        out.status.code()
    );
    assert!(!text.contains("panicked"), "{ctx}");
    assert!(
        text.contains(file),
        "the message does not name {file}; {ctx}"
    );
    assert!(
        text.to_lowercase().contains(&problem.to_lowercase()),
        "the message does not say {problem:?}; {ctx}"
    );
    let after = files(dir);
    assert_eq!(before, after, "files left behind; {ctx}");
}

fn small_turntable(seed: u64) -> Recording {
    turntable(&Turntable {
        objects: 4,
        sides: 6,
        frames: 12,
        samples: 48,
        degrees: 120.0,
        seed,
        ..Turntable::default()
    })
}

fn write_rec(dir: &Path, name: &str, rec: &Recording) {
    trisort_format::write_file_atomic(FileKind::Recording, &dir.join(name), rec).unwrap();
}

/// A valid recording `good.rec` and its bake `good.baked` in `dir`.
fn good_files(dir: &Path) -> (Recording, Baked) {
    let rec = small_turntable(7);
    let baked = merge(std::slice::from_ref(&rec), &MergeOptions::default())
        .unwrap()
        .lit(trisort_light::studio());
    write_rec(dir, "good.rec", &rec);
    trisort_format::write_file_atomic(FileKind::Baked, &dir.join("good.baked"), &baked).unwrap();
    (rec, baked)
}

/// Container corruptions of `bytes` as `(name, bytes, problem)`.
fn container_cases(bytes: &[u8]) -> Vec<(&'static str, Vec<u8>, &'static str)> {
    let mut v = vec![
        ("half", bytes[..bytes.len() / 2].to_vec(), "truncated"),
        ("header-only", bytes[..30].to_vec(), "truncated"),
        ("empty", Vec::new(), "wrong magic"),
    ];
    let mut b = bytes.to_vec();
    b[..8].copy_from_slice(b"NOTTRIS\0");
    v.push(("magic", b, "wrong magic"));
    let mut b = bytes.to_vec();
    b[8..12].copy_from_slice(&(trisort_format::FORMAT_VERSION + 1).to_le_bytes());
    v.push(("version", b, "is not supported (this trisort reads version"));
    let mut b = bytes.to_vec();
    let k = b.len() - 5;
    b[k] ^= 0x40;
    v.push(("checksum", b, "checksum mismatch"));
    // The payload hash does not cover the header: these reach the size checks.
    let mut b = bytes.to_vec();
    b[20..28].copy_from_slice(&(1u64 << 62).to_le_bytes());
    v.push(("huge", b, "exceeds the limit"));
    let mut b = bytes.to_vec();
    b[20..28].copy_from_slice(&(8u64 << 30).to_le_bytes());
    v.push(("8gib", b, "header says 8589934592"));
    let mut b = bytes.to_vec();
    b[12..20].copy_from_slice(&(u64::MAX - 3).to_le_bytes());
    v.push(("packed", b, "truncated or padded"));
    v
}

/// A command with its address space capped at 2 GiB where `prlimit` exists, so that a
/// reader which allocated what a header claims would abort instead of passing.
fn capped(args: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    if Path::new("/usr/bin/prlimit").exists() {
        let mut c = vec![
            "/usr/bin/prlimit".to_string(),
            format!("--as={}", 2u64 << 30),
            bin().display().to_string(),
        ];
        c.append(&mut v);
        c
    } else {
        v.insert(0, bin().display().to_string());
        v
    }
}

/// Like [`fails`] but through [`capped`].
fn fails_capped(dir: &Path, args: &[&str], file: &str, problem: &str) {
    let before = files(dir);
    let cmd = capped(args);
    let out = std::process::Command::new(&cmd[0])
        .args(&cmd[1..])
        .current_dir(dir)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let ctx = format!("{}:\n{text}", cmd.join(" "));
    assert_eq!(out.status.code(), Some(1), "{ctx}");
    assert!(!text.contains("panicked") && text.contains(file), "{ctx}");
    assert!(text.contains(problem), "no {problem:?}; {ctx}");
    assert_eq!(before, files(dir), "{ctx}");
}

#[test]
fn corrupted_recordings_are_refused_by_every_reader() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    good_files(d);
    let bytes = std::fs::read(d.join("good.rec")).unwrap();
    for (name, b, problem) in container_cases(&bytes) {
        let file = format!("{name}.rec");
        std::fs::write(d.join(&file), &b).unwrap();
        fails_capped(d, &["merge", &file, "-o", "out.baked"], &file, problem);
        fails_capped(
            d,
            &["verify", "good.baked", "--recording", &file],
            &file,
            problem,
        );
        // inspect sniffs the magic: without one it tries the file as a scene.
        let problem = if b.starts_with(b"TRISREC\0") {
            problem
        } else {
            ""
        };
        fails_capped(d, &["inspect", &file], &file, problem);
        std::fs::remove_file(d.join(&file)).unwrap();
    }
    // A baked file where a recording is expected.
    fails(
        d,
        &["merge", "good.baked", "-o", "out.baked"],
        &[1],
        "good.baked",
        "not a trisort recording",
    );
}

#[test]
fn corrupted_baked_files_are_refused_by_every_reader() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    good_files(d);
    let bytes = std::fs::read(d.join("good.baked")).unwrap();
    for (name, b, problem) in container_cases(&bytes) {
        let file = format!("{name}.baked");
        std::fs::write(d.join(&file), &b).unwrap();
        fails_capped(
            d,
            &["verify", &file, "--recording", "good.rec"],
            &file,
            problem,
        );
        fails_capped(d, &["play", &file, "--out-dir", "frames"], &file, problem);
        let problem = if b.starts_with(b"TRISBAK\0") {
            problem
        } else {
            ""
        };
        fails_capped(d, &["inspect", &file], &file, problem);
        std::fs::remove_file(d.join(&file)).unwrap();
    }
}

/// The start of a Recording's postcard encoding, up to its `frame_states` vector: followed by
/// a length, it forges a payload that claims any number of frame states.
#[derive(Serialize)]
struct RecordingHead {
    tool_version: String,
    scene_hash: [u8; 32],
    path_hash: [u8; 32],
    settings: RecordSettings,
    device: DeviceInfo,
    phase: Phase,
    scene_triangles: u32,
    frame_states_len: u64,
}

#[test]
fn a_forged_length_inside_a_valid_container_allocates_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let head = RecordingHead {
        tool_version: "0.1.0".into(),
        scene_hash: [0; 32],
        path_hash: [0; 32],
        settings: RecordSettings::default(),
        device: DeviceInfo::default(),
        phase: Phase::Graphs,
        scene_triangles: 1,
        frame_states_len: 1 << 40,
    };
    std::fs::write(d.join("forged.rec"), encode(FileKind::Recording, &head)).unwrap();
    for args in [
        &["merge", "forged.rec", "-o", "out.baked"][..],
        &["inspect", "forged.rec"],
    ] {
        fails_capped(d, args, "forged.rec", "corrupted payload");
    }
}

#[test]
fn mismatched_recordings_are_not_merged() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let rec = small_turntable(7);
    let parts = split_frames(&rec, &[0, 6]);
    write_rec(d, "a.rec", &parts[0]);
    write_rec(d, "b.rec", &parts[1]);
    // The two halves merge.
    run(d, &["merge", "a.rec", "b.rec", "-o", "ab.baked"], true);
    std::fs::remove_file(d.join("ab.baked")).unwrap();
    let other = split_frames(&small_turntable(8), &[0, 6]);
    write_rec(d, "other.rec", &other[1]);
    let overlap = split_frames(&rec, &[0, 4]);
    write_rec(d, "overlap.rec", &overlap[1]);
    let mut moved = parts[1].clone();
    moved.path_hash[0] ^= 1;
    write_rec(d, "moved.rec", &moved);
    let mut wide = parts[1].clone();
    wide.settings.width = 2;
    write_rec(d, "wide.rec", &wide);
    let mut phase1 = parts[1].clone();
    phase1.phase = Phase::Visibility;
    phase1.geometry = Default::default();
    for f in &mut phase1.frames {
        f.covered.clear();
        f.edges.clear();
        f.ties.clear();
    }
    write_rec(d, "phase1.rec", &phase1);
    let cases: &[(&[&str], &str, &str)] = &[
        (&["a.rec", "other.rec"], "other.rec", "scene hash"),
        (
            &["a.rec", "overlap.rec"],
            "overlap.rec",
            "covers frames 4..12, but frame 6 comes next",
        ),
        (&["a.rec", "a.rec"], "a.rec", "but frame 6 comes next"),
        (&["a.rec"], "a.rec", "cover frames 0..6 of a 12-frame path"),
        (
            &["b.rec"],
            "b.rec",
            "covers frames 6..12, but frame 0 comes next",
        ),
        (&["a.rec", "moved.rec"], "moved.rec", "path hash"),
        (
            &["a.rec", "wide.rec"],
            "wide.rec",
            "size \"1x1\" vs \"2x1\"",
        ),
        (&["a.rec", "phase1.rec"], "phase1.rec", "no graphs"),
    ];
    for (inputs, file, problem) in cases {
        let mut args = vec!["merge"];
        args.extend_from_slice(inputs);
        args.extend_from_slice(&["-o", "out.baked"]);
        fails(d, &args, &[1], file, problem);
    }
}
