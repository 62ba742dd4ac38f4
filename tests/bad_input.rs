//! Bad input for every reader, through the real binary: glTF scenes, TOML paths, Recording and
//! Baked files (truncated, wrong magic or version, checksum mismatch, header sizes that would
//! allocate gigabytes, forged lengths inside the payload, NaN and infinities, broken
//! structure) and mismatched recordings given to one merge. Each must end with exit 1, a
//! message naming the file and the problem, no panic, and no file left behind: no output, no temporary file, no
//! partial folder.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::Serialize;
use trisort_format::container::{encode, FileKind};
use trisort_format::{
    Baked, DeviceInfo, DrawIndexedIndirectArgs, FrameWindow, Phase, RecordSettings, Recording,
};
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

/// Recordings that decode but break what readers rely on: each is named by
/// `Recording::check_structure`'s message.
#[test]
fn malformed_recordings_are_named_not_merged() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (good, _) = good_files(d);
    type Edit = fn(&mut Recording);
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "nan-view",
            |r| r.frame_states[0].camera.view[12] = f64::NAN,
            "view matrix is not finite",
        ),
        (
            "inf-far",
            |r| r.frame_states[3].camera.zfar = Some(f64::INFINITY),
            "zfar inf",
        ),
        (
            "nan-fov",
            |r| r.frame_states[1].camera.yfov = f64::NAN,
            "yfov NaN",
        ),
        (
            "nan-pose",
            |r| {
                r.frame_states[2].poses.push(trisort_format::NodePose {
                    node: 0,
                    local: [f64::NAN; 16],
                })
            },
            "pose is not finite",
        ),
        (
            "inf-vertex",
            |r| r.geometry.vertices[0].position[1] = f32::INFINITY,
            "non-finite position",
        ),
        (
            "nan-color",
            |r| r.geometry.materials[0].base_color[0] = f32::NAN,
            "non-finite factor",
        ),
        (
            "id-beyond-scene",
            |r| {
                let n = r.scene_triangles;
                r.unique_visible.push(n);
            },
            "but the scene has",
        ),
        (
            "visible-outside-g",
            |r| {
                let t = (0..r.scene_triangles)
                    .find(|t| r.unique_visible.binary_search(t).is_err())
                    .unwrap();
                r.frames[0].visible = vec![t];
            },
            "is not in G",
        ),
        (
            "unsorted",
            |r| r.frames[1].visible.reverse(),
            "not strictly ascending",
        ),
        (
            "edge-outside-g",
            |r| {
                let t = (0..r.scene_triangles)
                    .find(|t| r.unique_visible.binary_search(t).is_err())
                    .unwrap();
                r.frames[2].edges.push(trisort_format::Edge {
                    from: t,
                    to: t + 1,
                    weight: 1,
                });
                r.frames[2].edges.sort();
            },
            "leaves G",
        ),
        (
            "gap",
            |r| {
                r.frames.remove(4);
            },
            "must be contiguous",
        ),
        (
            "beyond-path",
            |r| r.frame_states.truncate(5),
            "beyond the path's 5 frames",
        ),
        (
            "vertex-index",
            |r| r.geometry.triangles[0][1] = 1 << 30,
            "refers to a vertex beyond",
        ),
        (
            "geometry-count",
            |r| {
                r.geometry.triangles.pop();
            },
            "triangles for the",
        ),
        (
            "samples",
            |r| r.settings.samples = 3,
            "samples are impossible",
        ),
        (
            "bits",
            |r| r.settings.robust.profile.subpixel_bits_max = 99,
            "sub-pixel",
        ),
    ];
    for (name, edit, problem) in cases {
        let mut r = good.clone();
        edit(&mut r);
        let file = format!("{name}.rec");
        write_rec(d, &file, &r);
        fails(
            d,
            &["merge", &file, "-o", "out.baked"],
            &[1],
            &file,
            problem,
        );
        fails(d, &["inspect", &file], &[1], &file, problem);
        fails(
            d,
            &["verify", "good.baked", "--recording", &file],
            &[1],
            &file,
            problem,
        );
        std::fs::remove_file(d.join(&file)).unwrap();
    }
}

/// Baked files that decode but break what the player and the validator rely on.
#[test]
fn malformed_baked_files_are_named_not_played() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (_, good) = good_files(d);
    type Edit = fn(&mut Baked);
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "nan-vertex",
            |b| b.geometry.vertices[2].position[0] = f32::NAN,
            "non-finite position",
        ),
        (
            "nan-view",
            |b| b.frame_states[1].camera.view[0] = f64::NAN,
            "view matrix is not finite",
        ),
        (
            "zero-near",
            |b| b.frame_states[0].camera.znear = 0.0,
            "znear 0",
        ),
        (
            "inf-rest",
            |b| b.geometry.nodes[0].rest[13] = f64::NEG_INFINITY,
            "rest transform is not finite",
        ),
        (
            "draw-outside",
            |b| b.draws[0].index_count = 3 * (b.copies.len() as u32 + 1),
            "outside the index buffer",
        ),
        (
            "window-outside",
            |b| b.frames[2].first = u32::MAX,
            "outside the draw list",
        ),
        // Per-frame work beyond what a merge produces (issue 28: 200,000 draws of the whole
        // buffer in one frame held play and verify past 60 s).
        (
            "200k-draws",
            |b| {
                let whole = DrawIndexedIndirectArgs {
                    index_count: 3 * b.copies.len() as u32,
                    ..b.draws[0]
                };
                let first = b.draws.len() as u32;
                b.draws.extend(std::iter::repeat_n(whole, 200_000));
                b.frames[1] = FrameWindow {
                    first,
                    count: 200_000,
                };
            },
            "frame 1 has 200000 draws, more than a merge gives",
        ),
        (
            "buffer-twice",
            |b| {
                let whole = DrawIndexedIndirectArgs {
                    index_count: 3 * b.copies.len() as u32,
                    first_index: 0,
                    ..b.draws[0]
                };
                let first = b.draws.len() as u32;
                b.draws.extend([whole, whole]);
                b.frames[0] = FrameWindow { first, count: 2 };
            },
            "more than the",
        ),
        (
            "copy-beyond",
            |b| b.copies[0] = u32::MAX,
            "refers to a triangle beyond",
        ),
        (
            "short-states",
            |b| {
                b.frame_states.pop();
            },
            "per-frame lists differ",
        ),
        // Settings a reader would size images, targets and loops by (issue 28: a width of 0
        // made `play --out-dir` panic in the image library).
        ("zero-width", |b| b.settings.width = 0, "settings 0x"),
        (
            "huge-height",
            |b| b.settings.height = u32::MAX,
            "x4294967295 is out of range",
        ),
        (
            "no-layers",
            |b| b.settings.max_layers = 0,
            "max layers must be at least 1",
        ),
        (
            "nan-tolerance",
            |b| b.settings.robust.tolerance = f32::NAN,
            "robust tolerance NaN px",
        ),
        (
            "no-patterns",
            |b| b.settings.robust.patterns = 0,
            "the number of sample patterns must be",
        ),
    ];
    for (name, edit, problem) in cases {
        let mut b = good.clone();
        edit(&mut b);
        let file = format!("{name}.baked");
        trisort_format::write_file_atomic(FileKind::Baked, &d.join(&file), &b).unwrap();
        fails(d, &["inspect", &file], &[1], &file, problem);
        // A malformed file is an error (exit 1), not a failed verification (exit 3): verify
        // checks the structure before it verifies anything.
        fails(
            d,
            &["verify", &file, "--recording", "good.rec"],
            &[1],
            &file,
            problem,
        );
        fails(
            d,
            &["play", &file, "--out-dir", "frames"],
            &[1],
            &file,
            problem,
        );
        std::fs::remove_file(d.join(&file)).unwrap();
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

/// A scene for the path and scene cases: the demo car exported as glTF binary.
fn car_glb(dir: &Path) -> Vec<u8> {
    let scene = trisort_scene::demo_car::demo_car(10_000);
    trisort_scene::export::export_glb(&scene, &dir.join("car.glb")).unwrap();
    std::fs::read(dir.join("car.glb")).unwrap()
}

#[test]
fn bad_path_files_fail_before_recording() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    car_glb(d);
    let key = "[[camera.key]]\nframe = 0\neye = [6, 2, 6]\ntarget = [0, 0.5, 0]\n";
    let cases = [
        ("syntax", "[camera\n".to_string(), "bad.toml:1:"),
        ("nan", key.replace("eye = [6, 2, 6]", "eye = [nan, 2, 6]"), "not a finite number"),
        ("inf", format!("[camera]\nzfar = inf\n{key}"), "not a finite number"),
        ("zero", format!("frames = 0\n{key}"), "zero frames"),
        ("huge", format!("frames = 1000000000\n{key}"), "1000000"),
        ("node", format!("{key}[[node]]\nname = \"DriverDor\"\naxis = [0, 1, 0]\nkey = [{{ frame = 0, angle = 10 }}]\n"), "no node named \"DriverDor\""),
        ("clip", format!("[camera]\nznear = 2\nzfar = 1\n{key}"), "0 < znear < zfar"),
        ("unknown", format!("speed = 3\n{key}"), "unknown field"),
    ];
    for (name, text, problem) in cases {
        std::fs::write(d.join("bad.toml"), text).unwrap();
        fails(
            d,
            &[
                "bake",
                "car.glb",
                "--path",
                "bad.toml",
                "-o",
                "out.baked",
                "--size",
                "8x8",
            ],
            &[1],
            "bad.toml",
            problem,
        );
        let _ = name;
    }
    std::fs::remove_file(d.join("bad.toml")).unwrap();
    fails(
        d,
        &[
            "bake",
            "car.glb",
            "--path",
            "missing.toml",
            "-o",
            "out.baked",
        ],
        &[1],
        "missing.toml",
        "cannot read",
    );
}

#[test]
fn bad_scene_files_fail_before_recording() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bytes = car_glb(d);
    std::fs::write(d.join("cut.glb"), &bytes[..bytes.len() * 2 / 3]).unwrap();
    let gltf = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
        "bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[{"byteLength":36,"uri":"gone.bin"}]}"#;
    std::fs::write(d.join("external.gltf"), gltf).unwrap();
    for file in ["cut.glb", "external.gltf"] {
        fails(
            d,
            &[
                "bake",
                file,
                "--path",
                "orbit:frames=2",
                "-o",
                "out.baked",
                "--size",
                "8x8",
            ],
            &[1],
            file,
            "",
        );
    }
}

/// A one-node glTF scene (one triangle, its buffer beside it as `tri.bin`).
fn one_node_gltf(dir: &Path) {
    let corners: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let bin: Vec<u8> = corners.iter().flat_map(|c| c.to_le_bytes()).collect();
    std::fs::write(dir.join("tri.bin"), bin).unwrap();
    let gltf = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
        "bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[{"byteLength":36,"uri":"tri.bin"}]}"#;
    std::fs::write(dir.join("tri.gltf"), gltf).unwrap();
}

/// A scene with fewer nodes than a baked file's poses name (the demo path opens the car's
/// door, node 1; this scene has one node) is the wrong scene, said as such by every command
/// that reads a scene with a baked file or recording, not an index out of range in the
/// intersection split.
#[test]
fn a_scene_with_fewer_nodes_than_the_poses_is_named_not_indexed() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    run(
        d,
        &args("bake demo:3000 --path demo --size 16x16 -o car.baked"),
        true,
    );
    run(
        d,
        &args("record demo:3000 --path demo --size 16x16 --phase visibility -o vis.rec"),
        true,
    );
    one_node_gltf(d);
    let wrong = "is not the scene car.baked was made over";
    fails(
        d,
        &args("verify car.baked --scene tri.gltf"),
        &[1],
        "tri.gltf",
        wrong,
    );
    fails(
        d,
        &args("verify car.baked --scene tri.gltf --json"),
        &[1],
        "(1 nodes)",
        wrong,
    );
    fails(
        d,
        &args("verify car.baked --recording car.baked.rec --scene tri.gltf"),
        &[1],
        "tri.gltf",
        "is not the scene car.baked.rec was made over",
    );
    fails(
        d,
        &args("export-order car.baked --scene tri.gltf -o car.order"),
        &[1],
        "tri.gltf",
        "not the scene car.baked was baked from",
    );
    fails(
        d,
        &args("record tri.gltf --path orbit:frames=3 --size 16x16 --phase graphs --visibility vis.rec -o g.rec"),
        &[1],
        "vis.rec",
        "recorded from another scene or path",
    );
}

/// `--path gltf:animation=NAME,camera=NAME` naming what the scene lacks fails before
/// recording, saying what the scene has.
#[test]
fn gltf_path_selection_names_what_the_scene_lacks() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    car_glb(d);
    for (path, problem) in [
        (
            "gltf:animation=drive",
            "no animation named \"drive\" (its animations: none)",
        ),
        (
            "gltf:camera=top",
            "no camera named \"top\" (its cameras: none)",
        ),
        (
            "gltf:zoom=2",
            "unknown parameter (known: animation, camera)",
        ),
    ] {
        fails(
            d,
            &[
                "bake",
                "car.glb",
                "--path",
                path,
                "-o",
                "out.baked",
                "--size",
                "8x8",
            ],
            &[1],
            path,
            problem,
        );
    }
}

/// A missing file is named once with its cause once: the format errors carry the cause in
/// their message and as their source, and the CLI prints the chain without repeating it.
#[test]
fn a_missing_file_names_its_cause_once() {
    let dir = tempfile::tempdir().unwrap();
    for cmd in ["inspect", "play", "verify"] {
        let out = run(dir.path(), &[cmd, "missing.baked"], false);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("missing.baked"), "{cmd}: {err}");
        let cause = "No such file or directory";
        assert_eq!(err.matches(cause).count(), 1, "{cmd}: {err}");
    }
}
