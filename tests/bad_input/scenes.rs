//! Bad scenes and paths: TOML paths, glTF files and `--path gltf:` selections that fail before
//! recording, a scene with fewer nodes than a baked file's poses, and a missing file named
//! with its cause once.

use std::path::Path;

use super::fails;
use crate::support::*;

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
