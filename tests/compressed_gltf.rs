//! glTF as real pipelines deliver it, end to end: CarConcept packed at test
//! time by gltfpack — quantized (`KHR_mesh_quantization`), meshopt-compressed (`-cc`,
//! `EXT_meshopt_compression`), named nodes kept (`-kn`) — and by gltf-pipeline
//! (`KHR_draco_mesh_compression`, `-d`) is inspected and recorded like the original. The
//! gltfpack files hold 44 fewer triangles (it drops triangles that repeat a vertex after
//! welding), the Draco one 66 fewer (those with two corners at one position; see scene's
//! `import_compressed`), and positions snap to a 14-bit (gltfpack) or 11-bit (Draco) grid, so
//! visible counts may move by a few triangles at silhouettes; the quantized file and its
//! meshopt-compressed copy hold the same triangles and see the same counts.

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
fn compressed_car_concept_records_like_the_original() {
    let Some(car) = scene("CarConcept") else {
        return;
    };
    let Some(gltfpack) = trisort_testkit::gltfpack() else {
        return;
    };
    let Some(pipeline) = trisort_testkit::gltf_pipeline() else {
        return;
    };
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let mut counts = Vec::new();
    for (name, tool, options, triangles) in [
        ("original", None, &[][..], 213_347),
        ("q", Some(&gltfpack), &[][..], 213_303),
        ("cc", Some(&gltfpack), &["-cc"][..], 213_303),
        ("cckn", Some(&gltfpack), &["-cc", "-kn"][..], 213_303),
        ("draco", Some(&pipeline), &["-d"][..], 213_281),
    ] {
        let file = match tool {
            None => car.clone(),
            Some(tool) => {
                let out = d.join(format!("{name}.glb"));
                let status = std::process::Command::new(tool)
                    .arg("-i")
                    .arg(&car)
                    .arg("-o")
                    .arg(&out)
                    .args(options)
                    .status()
                    .unwrap();
                assert!(status.success(), "{} {options:?}", tool.display());
                out.display().to_string()
            }
        };
        let inspect = run_json(d, &["inspect", &file]);
        assert_eq!(inspect["triangles"], triangles, "{name}: {inspect}");
        // KHR_materials_variants survives both tools; inspect lists the names.
        let variants = ["Carmine Candy", "Pearly Swirly", "Torched Graphite"];
        assert_eq!(inspect["variants"], serde_json::json!(variants), "{name}");
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
                // The recorded pattern's visible sets: what the import decides. (The default
                // conservative set also depends on which triangles share corners, which the
                // intersection splitter decides per file order.)
                "--conservative=false",
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
