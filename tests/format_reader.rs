//! docs/FORMAT.md's independent reader (docs/format_reader.py, Python, written from the
//! specification alone) parses a fresh bake and an ORDER file; its counts must equal
//! `inspect --json`'s and `export-order --json`'s.

use std::path::Path;
use std::process::{Command, Output};

use crate::export_order::export_order_json;
use crate::support::{args, gpu_tempdir, run, run_json, scene};

/// A Python 3 with the `zstandard` module (Debian's python3-zstandard lives under
/// /usr/bin/python3), or `None` to skip; CI (scripts/ensure-c-host.sh installs it) requires one.
fn python() -> Option<&'static str> {
    let found = ["python3", "/usr/bin/python3"].into_iter().find(|p| {
        Command::new(p)
            .args(["-c", "import zstandard"])
            .output()
            .is_ok_and(|o| o.status.success())
    });
    if found.is_none() {
        assert!(
            std::env::var_os("CI").is_none(),
            "no python3 with zstandard: run scripts/ensure-c-host.sh"
        );
        eprintln!("skipping: no python3 with the zstandard module");
    }
    found
}

/// Runs docs/format_reader.py on `file`.
fn run_reader(python: &str, file: &Path) -> Output {
    let reader = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/format_reader.py");
    Command::new(python).arg(reader).arg(file).output().unwrap()
}

/// docs/format_reader.py's figures of `file`, which it must read.
fn read(python: &str, file: &Path) -> serde_json::Value {
    let out = run_reader(python, file);
    assert!(
        out.status.success(),
        "format_reader.py {} failed:\n{}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn the_independent_reader_parses_a_fresh_bake_and_agrees_with_inspect() {
    let Some(python) = python() else { return };
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    run(
        d,
        &args("bake demo:10000 --path orbit:frames=5,degrees=90 --size 64x64 --samples 4 -o car.baked"),
        true,
    );
    let ours = read(python, &d.join("car.baked"));
    let inspect = run_json(d, &["inspect", "car.baked"]);
    for key in [
        "frames",
        "index_triangles",
        "unique_visible",
        "draws_per_frame_max",
        "unordered_samples",
        "strategy",
        "layout",
        "split_intersections",
    ] {
        assert_eq!(ours[key], inspect[key], "{key}");
    }
    assert_eq!(ours["stats_index_triangles"], inspect["index_triangles"]);
    assert_eq!(ours["triangles"], ours["unique_visible"]);
    assert_eq!(ours["format_version"], 7);
    // Version 5: the raster profile, as inspect reports it.
    let profile = &inspect["raster_profile"];
    assert_eq!(ours["raster_profile"]["name"], profile["name"]);
    assert_eq!(ours["raster_profile"]["depth_at"], profile["depth_at"]);
    assert_eq!(
        serde_json::json!([
            ours["raster_profile"]["subpixel_bits_min"],
            ours["raster_profile"]["subpixel_bits_max"]
        ]),
        profile["subpixel_bits"]
    );
    assert_eq!(ours["textures"], 1, "the demo car's licence plate");
    // Version 4: the plate is sRGB with its mips (64x16 down to 1x1), the file has its light.
    assert_eq!(ours["srgb_textures"], 1);
    assert_eq!(ours["mip_levels"], serde_json::json!([6]));
    let plate: u64 = (0..7)
        .map(|k| (64u64 >> k).max(1) * (16u64 >> k).max(1) * 4)
        .sum();
    assert_eq!(ours["texture_bytes"], plate);
    assert_eq!(ours["tangents"], 0, "no normal textures on the demo car");
    let environment = &ours["environment"];
    assert!(
        environment["levels"].as_u64().unwrap() >= 1,
        "{environment}"
    );
    assert!(environment["width"].as_u64().unwrap() >= 1, "{environment}");
    assert_eq!(ours["fps"], inspect["fps"]);
    assert_eq!(ours["fps"], 30.0, "the generators' default rate");
    assert_eq!(ours["variants"], serde_json::json!([]));
    assert_eq!(
        (ours["width"].as_u64(), ours["samples"].as_u64()),
        (Some(64), Some(4))
    );

    // A damaged file is refused with the file named, not misread.
    let mut bytes = std::fs::read(d.join("car.baked")).unwrap();
    bytes.truncate(bytes.len() - 1);
    std::fs::write(d.join("cut.baked"), &bytes).unwrap();
    let out = run_reader(python, &d.join("cut.baked"));
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cut.baked"));
}

/// The reader reads the older versions trisort reads (tests/data/, written by the trisort of
/// their version) with the same counts as `inspect`, which migrates them; the clip it reports
/// for a file without clips is the one trisort reads it with.
#[test]
fn the_independent_reader_reads_the_older_versions_in_tests_data() {
    let Some(python) = python() else { return };
    let dir = tempfile::tempdir().unwrap();
    for (file, version) in [
        ("format4.baked", 4),
        ("format5.baked", 5),
        ("format6.baked", 6),
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(file);
        let ours = read(python, &path);
        assert_eq!(ours["format_version"], version);
        let inspect = run_json(dir.path(), &["inspect", path.to_str().unwrap()]);
        for key in ["frames", "index_triangles", "unique_visible", "fps"] {
            assert_eq!(ours[key], inspect[key], "{file}: {key}");
        }
        assert_eq!(
            ours["clips"][0]["name"], inspect["clips"][0]["name"],
            "{file}"
        );
        assert_eq!(
            ours["clips"][0]["count"], inspect["clips"][0]["frames"],
            "{file}"
        );
    }
}

/// The reader checks the lengths FORMAT.md states: a mip level one byte short, or a texture
/// without its full mip chain, is refused (trisort's own check refuses them too), naming the
/// texture (and level).
#[test]
fn the_independent_reader_refuses_a_mip_level_of_the_wrong_length() {
    let Some(python) = python() else { return };
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    run(
        d,
        &args("bake demo:10000 --path orbit:frames=2,degrees=10 --size 32x32 --samples 1 -o car.baked"),
        true,
    );
    let path = d.join("car.baked");
    use trisort_format::container::{encode, read_file, write_bytes_atomic, FileKind};
    let mut baked: trisort_format::Baked = read_file(FileKind::Baked, &path).unwrap();
    baked.geometry.textures[0].mips[2].pop();
    assert!(baked
        .geometry
        .check_structure()
        .unwrap_err()
        .problem
        .contains("mip level 3"));
    let bad = d.join("short-mip.baked");
    write_bytes_atomic(&bad, &encode(FileKind::Baked, &baked)).unwrap();
    let out = run_reader(python, &bad);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("short-mip.baked") && err.contains("texture 0 mip 3"),
        "{err}"
    );
    // The chain is not optional: a texture stored without it is refused by both readers.
    baked.geometry.textures[0].mips.clear();
    let name = baked.geometry.textures[0].name.clone();
    let ours = baked.geometry.check_structure().unwrap_err().problem;
    assert!(
        ours.contains(&format!("texture 0 {name:?}")) && ours.contains("has 0 mip levels"),
        "{ours}"
    );
    let bare = d.join("no-mips.baked");
    write_bytes_atomic(&bare, &encode(FileKind::Baked, &baked)).unwrap();
    let out = run_reader(python, &bare);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no-mips.baked")
            && err.contains("0 mip levels, the full chain down to 1x1 has 6"),
        "{err}"
    );
}

#[test]
fn the_independent_reader_parses_an_order_file() {
    let Some(python) = python() else { return };
    let Some(truck) = scene("CesiumMilkTruck") else {
        return;
    };
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let mut bake =
        args("bake --path gltf --fps 4 --size 48x48 --samples 1 --keep-intersections -o t.baked");
    bake.insert(1, &truck);
    run(d, &bake, true);
    let v = export_order_json(d, "t.baked", &truck, "t.order");
    let ours = read(python, &d.join("t.order"));
    for key in ["frames", "ranges", "triangles", "split"] {
        assert_eq!(ours[key], v[key], "{key}");
    }
}

/// Version 7's block-compressed textures (`--textures`): the reader parses their blocks and
/// checks every level's length; a file whose level is cut short is refused.
#[test]
fn the_independent_reader_parses_block_compressed_textures() {
    let Some(python) = python() else { return };
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    for format in ["etc2", "bc7"] {
        let bake = format!(
            "bake demo:400 --path orbit:frames=2,degrees=30 --size 32x32 --textures {format} \
             -o {format}.baked"
        );
        run(d, &args(&bake), true);
        let ours = read(python, &d.join(format!("{format}.baked")));
        assert_eq!(ours["format_version"], 7, "{ours}");
    }
    // A level one block short, in a correct container: the reader's own length check.
    let mut baked: trisort_format::Baked =
        trisort_format::read_file(trisort_format::FileKind::Baked, &d.join("bc7.baked")).unwrap();
    let blocks = baked.geometry.textures[0].blocks.as_mut().unwrap();
    let level = &mut blocks.levels[0];
    level.truncate(level.len() - 16);
    let bytes = trisort_format::container::encode(trisort_format::FileKind::Baked, &baked);
    std::fs::write(d.join("short.baked"), bytes).unwrap();
    let out = run_reader(python, &d.join("short.baked"));
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("block level 0"), "{err}");
    // trisort refuses it too, naming the texture and the level.
    let out = run(d, &["inspect", "short.baked"], false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("short.baked") && err.contains("bc7 level 0"),
        "{err}"
    );
}
