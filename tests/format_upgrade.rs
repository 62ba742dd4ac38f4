//! Baked files of the two format versions before this one (tests/data/, each written by the
//! trisort of its version) still inspect, play and verify, and `trisort upgrade` rewrites them
//! in the current version with the same frames: verify gives the same figures and play the
//! same PNGs before and after. A version older than those is refused, naming the versions read.

use std::path::{Path, PathBuf};

use trisort_format::FORMAT_VERSION;

use crate::support::{args, gpu_tempdir, run, run_json};

/// A file of tests/data/.
fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The format version in a container's header (bytes 8..12).
fn version_of(file: &Path) -> u32 {
    let bytes = std::fs::read(file).unwrap();
    u32::from_le_bytes(bytes[8..12].try_into().unwrap())
}

/// The PNG files `play` wrote into `dir`, by name.
fn pngs(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "png"))
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&p).unwrap())
        })
        .collect();
    out.sort();
    out
}

#[test]
fn files_of_the_two_previous_versions_play_verify_and_upgrade_unchanged() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    assert_eq!(
        FORMAT_VERSION, 7,
        "a new version: add a file of version 6's successor here"
    );
    for (file, version) in [
        ("format4.baked", 4),
        ("format5.baked", 5),
        ("format6.baked", 6),
    ] {
        std::fs::copy(data(file), d.join(file)).unwrap();
        assert_eq!(version_of(&d.join(file)), version, "{file}");
        let info = run_json(d, &["inspect", file]);
        assert_eq!(info["frames"], 3, "{file}: {info}");
        assert_eq!(info["clips"][0]["name"], "main", "{file}: {info}");
        let profile = &info["raster_profile"]["name"];
        // Version 4 left the profile implicit: its conservative ±1/8 px box, 4-bit snapping
        // included, reads as snap4 with the rest of the box as its tolerance.
        let expected = if version == 4 { "snap4" } else { "conformant" };
        assert_eq!(profile, expected, "{file}: {info}");
        let verify = |f: &str| run_json(d, &["verify", f, "--scene", "demo:400"]);
        let before = verify(file);
        assert_eq!(before["ok"], true, "{file}: {before}");

        let upgraded = format!("v{version}-upgraded.baked");
        let up = run_json(d, &["upgrade", file, "-o", &upgraded]);
        assert_eq!(up["from_version"], version, "{up}");
        assert_eq!(up["to_version"], FORMAT_VERSION, "{up}");
        assert_eq!(version_of(&d.join(&upgraded)), FORMAT_VERSION);
        let after = verify(&upgraded);
        assert_eq!(
            before["frames"], after["frames"],
            "{file}: verify's figures changed"
        );
        assert_eq!(before["ok"], after["ok"]);

        // Upgrading the upgraded file changes nothing.
        let again = format!("v{version}-again.baked");
        run(d, &["upgrade", &upgraded, "-o", &again], true);
        assert_eq!(
            std::fs::read(d.join(&upgraded)).unwrap(),
            std::fs::read(d.join(&again)).unwrap()
        );

        let (old_dir, new_dir) = (format!("play-{version}-old"), format!("play-{version}-new"));
        run(d, &["play", file, "--out-dir", &old_dir], true);
        run(d, &["play", &upgraded, "--out-dir", &new_dir], true);
        let (old, new) = (pngs(&d.join(&old_dir)), pngs(&d.join(&new_dir)));
        assert_eq!(old.len(), 3, "{file}");
        assert!(old == new, "{file}: the upgraded file plays other frames");
    }

    // Older than that: refused, naming the file, its version and the versions read; no output.
    let mut bytes = std::fs::read(data("format4.baked")).unwrap();
    bytes[8..12].copy_from_slice(&3u32.to_le_bytes());
    std::fs::write(d.join("format3.baked"), bytes).unwrap();
    let out = run(d, &args("upgrade format3.baked -o new.baked"), false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "format3.baked: format version 3 is not supported (this trisort reads versions 4 to 7)"
        ),
        "{err}"
    );
    assert!(!d.join("new.baked").exists());
}
