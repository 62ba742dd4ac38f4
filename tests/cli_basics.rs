//! The CLI's contract: subcommands, scene inspection counts, clear errors.

use crate::support::*;

#[test]
fn help_lists_every_subcommand() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(dir.path(), &["--help"], true);
    let text = String::from_utf8_lossy(&out.stdout);
    for cmd in [
        "inspect", "record", "merge", "bake", "play", "verify", "bench", "demo",
    ] {
        assert!(text.contains(cmd), "--help lacks {cmd}:\n{text}");
    }
}

#[test]
fn inspect_counts_every_shared_scene() {
    let expected = [
        ("CarConcept", 213347),
        ("GlassVaseFlowers", 14036),
        ("CesiumMilkTruck", 3624),
        ("AlphaBlendModeTest", 61),
        ("StanfordBunny", 144046),
        ("FpsMap", 58758),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (name, triangles) in expected {
        let Some(path) = scene(name) else { continue };
        let v = run_json(dir.path(), &["inspect", &path]);
        assert_eq!(v["triangles"], triangles, "{name}");
        for key in [
            "zero_area_triangles",
            "meshes",
            "nodes",
            "materials",
            "animations",
            "cameras",
        ] {
            assert!(v[key].is_u64(), "{name}: inspect --json lacks {key}");
        }
    }
}

#[test]
fn bad_scene_files_fail_cleanly_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("junk.glb");
    std::fs::write(&junk, b"glTF\x02\x00\x00\x00garbage that is not a glb").unwrap();
    let missing = dir.path().join("missing.glb");
    for f in [&junk, &missing] {
        let out = run(dir.path(), &["inspect", f.to_str().unwrap()], false);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1));
        assert!(
            err.contains(f.file_name().unwrap().to_str().unwrap()),
            "error does not name the file: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn unbuilt_or_bad_arguments_exit_non_zero() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(
        dir.path(),
        &[
            "record", "x.glb", "--path", "orbit:", "-o", "o.rec", "--size", "0x5",
        ],
        false,
    );
    assert_eq!(out.status.code(), Some(2), "usage errors exit 2");
}
