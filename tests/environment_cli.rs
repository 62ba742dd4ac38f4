//! `--environment` through the real binary: a bake lit by an .hdr file says so in `inspect`,
//! the default is the built-in studio, and a bad .hdr fails naming the file with no output.

use std::path::Path;

use image::codecs::hdr::HdrEncoder;
use image::Rgb;

use crate::support::*;

/// Writes a 32 × 16 equirectangular HDR image, bright above and dim below.
fn write_sky(path: &Path) {
    let (w, h) = (32, 16);
    let pixels: Vec<Rgb<f32>> = (0..w * h)
        .map(|i| {
            if i / w < h / 2 {
                Rgb([3.0, 2.5, 2.0])
            } else {
                Rgb([0.2; 3])
            }
        })
        .collect();
    let mut out = Vec::new();
    HdrEncoder::new(&mut out).encode(&pixels, w, h).unwrap();
    std::fs::write(path, out).unwrap();
}

const BAKE: &str = "bake demo:2000 --path orbit:frames=2,degrees=20 --size 32x32 --samples 1";

#[test]
fn bake_and_merge_store_the_environment_they_are_given() {
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let d = dir.path();
    write_sky(&d.join("sky.hdr"));
    let mut bake = args(BAKE);
    bake.extend(["-o", "sky.baked", "--environment", "sky.hdr"]);
    let v = run_json(d, &bake);
    assert_eq!(v["environment"]["name"], "sky.hdr", "{v}");
    let i = run_json(d, &["inspect", "sky.baked"]);
    let e = &i["environment"];
    assert_eq!(e["name"], "sky.hdr", "{i}");
    assert_eq!(
        (e["width"].as_u64(), e["height"].as_u64()),
        (Some(128), Some(64))
    );
    assert_eq!(e["levels"], 6);
    // 128×64 + 64×32 + … + 4×2 texels of 8 bytes.
    assert_eq!(e["bytes"], 10_920 * 8);
    assert!(e["sun"].is_null(), "an .hdr file has no sun: {e}");
    // `verify --environment` makes the light anew and compares: the .hdr file it
    // was baked with passes, the studio does not.
    let v = run_json(d, &["verify", "sky.baked", "--environment", "sky.hdr"]);
    assert_eq!(
        (v["ok"].as_bool(), &v["environment"]["difference"]),
        (Some(true), &serde_json::Value::Null),
        "{v}"
    );
    let out = run(
        d,
        &["verify", "sky.baked", "--environment", "studio"],
        false,
    );
    assert_eq!(out.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&out.stdout).contains("is not studio: named \"sky.hdr\""));

    // Merging the recording again: the studio by default and by name.
    for extra in [&[][..], &["--environment", "studio"][..]] {
        let mut merge = vec!["merge", "sky.baked.rec", "-o", "studio.baked"];
        merge.extend(extra);
        run(d, &merge, true);
        let e = &run_json(d, &["inspect", "studio.baked"])["environment"];
        assert_eq!(e["name"], "studio", "{e}");
        assert!(
            e["sun"]["direction"].is_array(),
            "the studio has a sun: {e}"
        );
    }
}

#[test]
fn a_bad_hdr_file_fails_naming_it_and_leaves_no_output() {
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let d = dir.path();
    write_sky(&d.join("sky.hdr"));
    let good = std::fs::read(d.join("sky.hdr")).unwrap();
    std::fs::write(d.join("cut.hdr"), &good[..good.len() / 2]).unwrap();
    std::fs::write(d.join("photo.hdr"), b"\xff\xd8\xff\xe0 a JPEG").unwrap();
    for (file, problem) in [
        ("cut.hdr", "truncated or corrupt"),
        ("photo.hdr", "not a Radiance HDR image"),
        ("missing.hdr", "cannot read"),
    ] {
        let mut bake = args(BAKE);
        bake.extend(["-o", "out.baked", "--environment", file]);
        let out = run(d, &bake, false);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(file) && err.contains(problem), "{file}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        for left in ["out.baked", "out.baked.rec"] {
            assert!(!d.join(left).exists(), "{file}: {left} was written");
        }
    }
    // merge refuses it before writing the baked file or the joined recording.
    run(d, &args(&format!("{BAKE} -o ok.baked")), true);
    let out = run(
        d,
        &args("merge ok.baked.rec -o out.baked --join joined.rec --environment cut.hdr"),
        false,
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("cut.hdr"));
    assert!(!d.join("out.baked").exists() && !d.join("joined.rec").exists());
}
