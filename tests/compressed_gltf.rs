//! glTF as real pipelines deliver it (issue 17, part 2), end to end: CarConcept packed by
//! gltfpack at test time — quantized (`KHR_mesh_quantization`), meshopt-compressed (`-cc`,
//! `EXT_meshopt_compression`), named nodes kept (`-kn`) — is inspected and recorded like the
//! original. The packed files hold 44 fewer triangles (gltfpack drops triangles that repeat a
//! vertex after welding; see scene's `import_compressed`), and positions snap to gltfpack's
//! 14-bit grid, so visible counts may move by a few triangles at silhouettes; the quantized
//! file and its meshopt-compressed copy hold the same triangles and see the same counts.

use std::path::Path;

use crate::support::*;

/// Visible triangles per frame and over the path of a recording (`inspect --json`).
fn visible(d: &Path, rec: &str) -> (Vec<u64>, u64) {
    let v = run_json(d, &["inspect", rec]);
    let per_frame = (v["per_frame"].as_array().unwrap().iter())
        .map(|f| f["visible"].as_u64().unwrap())
        .collect();
    (per_frame, v["unique_visible"].as_u64().unwrap())
}

#[test]
fn gltfpack_compressed_car_concept_records_like_the_original() {
    let Some(car) = scene("CarConcept") else {
        return;
    };
    let Some(gltfpack) = trisort_testkit::gltfpack() else {
        return;
    };
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let mut counts = Vec::new();
    for (name, options) in [
        ("original", None),
        ("q", Some(&[][..])),
        ("cc", Some(&["-cc"][..])),
        ("cckn", Some(&["-cc", "-kn"][..])),
    ] {
        let file = match options {
            None => car.clone(),
            Some(options) => {
                let out = d.join(format!("{name}.glb"));
                let status = std::process::Command::new(&gltfpack)
                    .arg("-i")
                    .arg(&car)
                    .arg("-o")
                    .arg(&out)
                    .args(options)
                    .status()
                    .unwrap();
                assert!(status.success(), "gltfpack {options:?}");
                out.display().to_string()
            }
        };
        let inspect = run_json(d, &["inspect", &file]);
        let triangles = if options.is_none() { 213_347 } else { 213_303 };
        assert_eq!(inspect["triangles"], triangles, "{name}: {inspect}");
        let rec = format!("{name}.rec");
        run(
            d,
            &[
                "record",
                &file,
                "--path",
                "orbit:frames=2",
                "--size",
                "64x64",
                "--phase",
                "visibility",
                "-o",
                &rec,
            ],
            true,
        );
        counts.push((name, visible(d, &rec)));
    }
    let (_, (original, original_unique)) = &counts[0];
    // The quantized file and its meshopt-compressed copy: the same triangles, the same counts.
    assert_eq!(counts[1].1, counts[2].1, "{counts:?}");
    for (name, (per_frame, unique)) in &counts[1..] {
        for (a, b) in per_frame.iter().zip(original) {
            assert!(
                a.abs_diff(*b) * 100 <= *b,
                "{name}: {per_frame:?} vs {original:?}"
            );
        }
        assert!(
            unique.abs_diff(*original_unique) * 100 <= *original_unique,
            "{name}: {unique} vs {original_unique}"
        );
    }
    eprintln!("visible per frame and over the path: {counts:?}");
}
