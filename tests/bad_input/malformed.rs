//! Recording and Baked files that decode but break what readers rely on: non-finite numbers,
//! ids and windows out of range, impossible settings. Each is named by the file's
//! `check_structure` message, by every command that reads it.

use trisort_format::container::FileKind;
use trisort_format::{Baked, DrawIndexedIndirectArgs, FrameWindow, Recording};

use super::{fails, good_files, write_rec};

/// An edit that breaks a valid recording.
type RecordingEdit = fn(&mut Recording);

/// An edit that breaks a valid baked file.
type BakedEdit = fn(&mut Baked);

/// Recordings that decode but break what readers rely on: each is named by
/// `Recording::check_structure`'s message.
#[test]
fn malformed_recordings_are_named_not_merged() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (good, _) = good_files(d);
    let cases = [non_finite_recordings(), broken_recordings()].concat();
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

/// Recordings with a NaN or infinity where a reader needs a finite number, as
/// `(name, edit, problem)`.
fn non_finite_recordings() -> Vec<(&'static str, RecordingEdit, &'static str)> {
    vec![
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
    ]
}

/// Recordings whose ids, frames or settings break the structure, as `(name, edit, problem)`.
fn broken_recordings() -> Vec<(&'static str, RecordingEdit, &'static str)> {
    vec![
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
    ]
}

/// Baked files that decode but break what the player and the validator rely on.
#[test]
fn malformed_baked_files_are_named_not_played() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (_, good) = good_files(d);
    let cases = [broken_baked_geometry_and_draws(), broken_baked_settings()].concat();
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

/// Baked files with non-finite geometry or cameras, or draws, windows and copies beyond what
/// a merge produces, as `(name, edit, problem)`.
fn broken_baked_geometry_and_draws() -> Vec<(&'static str, BakedEdit, &'static str)> {
    vec![
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
        // Per-frame work beyond what a merge produces (200,000 draws of the whole
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
    ]
}

/// Baked files with settings a reader would size images, targets and loops by out of range,
/// as `(name, edit, problem)`.
fn broken_baked_settings() -> Vec<(&'static str, BakedEdit, &'static str)> {
    vec![
        // Settings a reader would size images, targets and loops by (a width of 0
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
    ]
}
