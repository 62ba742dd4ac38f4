//! Clips through the real binary, on a bundle made by hand (a 3-frame bake whose frames are
//! relisted as two clips, `a` = frame 0 and `b` = frames 1..3): `play --clip b` writes the
//! clip's frames numbered from 0, byte for byte the frames `play --frames 1..3` writes of the
//! whole file; `--frames` counts within the clip; an unknown clip fails naming the file and
//! its clips; `inspect` lists both clips, as text and as JSON.

use std::path::Path;

use trisort_format::{Baked, Clip, FileKind};

use crate::support::*;

/// Bakes a 3-frame orbit and rewrites it as a bundle of the clips `a` (frame 0, 24 fps) and
/// `b` (frames 1..3, 5 fps, from frame 1 of its path).
fn two_clip_bundle(d: &Path) {
    let bake = "bake demo:400 --path orbit:frames=3,degrees=60 --size 48x32 -o x.baked";
    run(d, &args(bake), true);
    let path = d.join("x.baked");
    let mut baked: Baked = trisort_format::read_file(FileKind::Baked, &path).unwrap();
    assert_eq!(baked.frames.len(), 3);
    let clip = |name: &str, first, count, fps, path_first| Clip {
        name: name.into(),
        first,
        count,
        fps: Some(fps),
        path_hash: baked.path_hash,
        path_first,
    };
    baked.clips = vec![clip("a", 0, 1, 24.0, 0), clip("b", 1, 2, 5.0, 1)];
    baked.check_structure().unwrap();
    trisort_format::write_file_atomic(FileKind::Baked, &path, &baked).unwrap();
}

/// The PNG files of a directory, by name.
fn pngs(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png"))
        .collect();
    names.sort();
    names
}

fn bytes(dir: &Path, frame: u32) -> Vec<u8> {
    std::fs::read(dir.join(format!("frame-{frame:05}.png"))).unwrap()
}

#[test]
fn play_clip_writes_the_clips_frames_numbered_within_it() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    two_clip_bundle(d);

    let whole = run_json(d, &args("play x.baked --frames 1..3 --out-dir whole"));
    assert_eq!(whole["clip"], serde_json::Value::Null, "{whole}");
    let played = run_json(d, &args("play x.baked --clip b --out-dir b"));
    assert_eq!(played["clip"], "b", "{played}");
    let numbers: Vec<_> = (played["frames"].as_array().unwrap().iter())
        .map(|f| f["frame"].as_u64().unwrap())
        .collect();
    assert_eq!(numbers, [0, 1], "{played}");
    assert_eq!(pngs(&d.join("b")), ["frame-00000.png", "frame-00001.png"]);
    for local in 0..2 {
        assert!(
            bytes(&d.join("b"), local) == bytes(&d.join("whole"), local + 1),
            "clip b's frame {local} is not the file's frame {}",
            local + 1
        );
    }

    // --frames counts from the clip's first frame.
    let one = run_json(
        d,
        &args("play x.baked --clip b --frames 1..2 --out-dir one"),
    );
    assert_eq!(one["frames"][0]["frame"], 1, "{one}");
    assert_eq!(pngs(&d.join("one")), ["frame-00001.png"]);
    assert!(bytes(&d.join("one"), 1) == bytes(&d.join("whole"), 2));
    // Past the clip's end: refused, though the file has the frame.
    run(d, &args("play x.baked --clip a --frames 0..2"), false);

    // The first clip plays the file's frame 0 under its own name.
    run(d, &args("play x.baked --clip a --out-dir a"), true);
    assert_eq!(pngs(&d.join("a")), ["frame-00000.png"]);

    let out = run(d, &args("play x.baked --clip nope"), false);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("x.baked")
            && stderr.contains("no clip named \"nope\"; the file's clips: a, b"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn inspect_lists_the_clips() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    two_clip_bundle(d);
    let v = run_json(d, &args("inspect x.baked"));
    assert_eq!(
        v["clips"],
        serde_json::json!([
            {"name": "a", "first": 0, "frames": 1, "fps": 24.0, "path_first": 0},
            {"name": "b", "first": 1, "frames": 2, "fps": 5.0, "path_first": 1},
        ]),
        "{v}"
    );
    let out = run(d, &args("inspect x.baked"), true);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("clips 2"), "{text}");
    assert!(
        text.contains("a: frames 0..1 (1 frame), 24 fps\n"),
        "{text}"
    );
    assert!(
        text.contains("b: frames 1..3 (2 frames), 5 fps, from frame 1 of its path"),
        "{text}"
    );
}

/// `play --window --clip b` starts at clip `b` and plays at its rate; `--json` names the clip
/// and counts the last frame within it. An unknown clip is refused before a window opens.
#[test]
fn window_starts_at_a_clip_and_plays_at_its_rate() {
    use crate::window_cli::{tools_missing, under_xvfb};
    use std::time::Duration;
    if tools_missing(&["xvfb-run"]) {
        return;
    }
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    two_clip_bundle(d);
    let play = args("play x.baked --window --clip b --window-frames 3 --json");
    let (code, stdout, stderr) = under_xvfb(d, &play, Duration::from_secs(120));
    assert_eq!(code, Some(0), "{stdout}\n--- stderr\n{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["clip"], "b", "{v}");
    assert_eq!(v["fps"], 5.0, "{v}");
    assert_eq!(v["presented_frames"], 3, "{v}");
    assert!(v["last_frame"].as_u64().is_some_and(|f| f < 2), "{v}");
    assert!(stderr.contains("Tab/C next clip"), "{stderr}");

    let unknown = args("play x.baked --window --clip nope");
    let (code, _, stderr) = under_xvfb(d, &unknown, Duration::from_secs(120));
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("x.baked") && stderr.contains("the file's clips: a, b"),
        "{stderr}"
    );
}
