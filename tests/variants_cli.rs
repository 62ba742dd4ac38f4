//! Material variants and the stored frame rate, end to end on CarConcept:
//! a 64x64 bake of a 2-frame orbit stores the path's fps and the three
//! `KHR_materials_variants` tables; `play --variant` draws each, and `verify --variant
//! --frames-dir` checks those very frames against the exact reference drawn with the
//! variant's materials (so the variant covers what the default covers, pixel for pixel); a
//! variant that would change what decides visibility is refused, naming it and the material.

use std::path::Path;

use trisort_format::{AlphaMode, Baked, FileKind};

use crate::support::*;

/// Frames of the bake: one, since every `verify` below draws CarConcept's exact reference
/// for each (about 3 s a frame at 64² on lavapipe).
const FRAMES: usize = 1;

/// The frames `play --out-dir` wrote, as RGBA8 pixels.
fn frames(dir: &Path) -> Vec<Vec<u8>> {
    (0..FRAMES)
        .map(|f| {
            let png = dir.join(format!("frame-{f:05}.png"));
            image::open(&png).unwrap().into_rgba8().into_raw()
        })
        .collect()
}

fn differing(a: &[u8], b: &[u8]) -> usize {
    a.chunks(4).zip(b.chunks(4)).filter(|(x, y)| x != y).count()
}

#[test]
fn car_concept_variants_play_exactly_and_the_bake_keeps_its_fps() {
    let Some(car) = scene("CarConcept") else {
        return;
    };
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let names = ["Carmine Candy", "Pearly Swirly", "Torched Graphite"];
    bake_stores_fps_and_variants(d, &car, names);
    each_variant_plays_and_verifies(d, &car, names);
    webgl2_tier_and_default_verify(d, &car, names);
    unknown_variant_lists_the_files(d);
    forged_visibility_variant_is_refused(d);
}

/// Bakes the car at 24 fps; `inspect` shows the fps and the three variants.
fn bake_stores_fps_and_variants(d: &Path, car: &str, names: [&str; 3]) {
    let path = format!("orbit:frames={FRAMES}");
    let mut bake = bake_args(car, &path, "64x64", "4", "car.baked");
    // Unsplit (faster to verify: the reference needs no split scene); the recording's cycles
    // excuse the pixels where triangles pass through each other.
    bake.extend(["--fps", "24", "--keep-intersections"]);
    run(d, &bake, true);

    let info = run_json(d, &["inspect", "car.baked"]);
    assert_eq!(info["fps"], 24.0);
    assert_eq!(info["variants"], serde_json::json!(names));
    assert_eq!(info["variants_refused"], serde_json::json!({}));
}

/// `play --variant` recolours every variant but Carmine Candy (the default look); each
/// recoloured one verifies against the reference with its materials.
fn each_variant_plays_and_verifies(d: &Path, car: &str, names: [&str; 3]) {
    let played = run_json(d, &args("play car.baked --out-dir default"));
    assert_eq!(played["variant"], serde_json::Value::Null);
    let default = frames(&d.join("default"));
    for (k, name) in names.into_iter().enumerate() {
        let out = format!("v{k}");
        let played = run_json(
            d,
            &["play", "car.baked", "--variant", name, "--out-dir", &out],
        );
        assert_eq!(played["variant"], name);
        let shown = frames(&d.join(&out));
        for f in 0..FRAMES {
            let n = differing(&shown[f], &default[f]);
            // Carmine Candy maps every material to itself (the file's default look).
            if k == 0 {
                assert_eq!(n, 0, "{name} frame {f}");
            } else {
                assert!(n > 100, "{name} frame {f}: only {n} pixels changed colour");
            }
        }
        if k == 0 {
            continue; // its frames are the default's, verified below
        }
        // The played frames against the reference with the variant's materials, at the
        // recorded pattern: the same coverage and order, other colours.
        run(
            d,
            &[
                "verify",
                "car.baked",
                "--recording",
                "car.baked.rec",
                "--scene",
                car,
                "--variant",
                name,
                "--frames-dir",
                &out,
            ],
            true,
        );
    }
}

/// The WebGL2 tier draws a variant alike; the default check fails on a variant's frames and
/// still passes on the default.
fn webgl2_tier_and_default_verify(d: &Path, car: &str, names: [&str; 3]) {
    // The data-texture tier (WebGL2 limits) rewrites its material texels alike.
    let played = run_json(
        d,
        &[
            "play",
            "car.baked",
            "--variant",
            names[1],
            "--limits",
            "webgl2",
            "--out-dir",
            "webgl2",
        ],
    );
    assert_eq!(played["bindings"], "textures");
    assert_eq!(frames(&d.join("webgl2")), frames(&d.join("v1")));
    // The check can fail: a recoloured variant's frames are not the default look.
    run(
        d,
        &["verify", "car.baked", "--scene", car, "--frames-dir", "v1"],
        false,
    );
    // And the default still verifies.
    run(
        d,
        &[
            "verify",
            "car.baked",
            "--recording",
            "car.baked.rec",
            "--scene",
            car,
        ],
        true,
    );
}

/// An unknown variant: the error lists the file's.
fn unknown_variant_lists_the_files(d: &Path) {
    let out = run(d, &args("play car.baked --variant Chrome"), false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "no material variant \"Chrome\": the file's variants are \"Carmine Candy\", \
             \"Pearly Swirly\", \"Torched Graphite\""
        ),
        "{err}"
    );
}

/// A forged variant that turns a paint into a blended one is refused, naming the variant
/// and both materials, before any frame is written.
fn forged_visibility_variant_is_refused(d: &Path) {
    let mut baked: Baked =
        trisort_format::read_file(FileKind::Baked, &d.join("car.baked")).unwrap();
    let g = &mut baked.geometry;
    let slot = g
        .materials
        .iter()
        .position(|m| m.name == "Paint 1 Carmine")
        .unwrap();
    let mut blended = g.materials[slot].clone();
    blended.name = "Forged glaze".into();
    blended.alpha_mode = AlphaMode::Blend;
    g.materials.push(blended);
    let forged = (g.materials.len() - 1) as u32;
    for v in &mut g.variants {
        v.materials.push(forged);
    }
    g.variants[1].materials[slot] = forged;
    trisort_format::write_file_atomic(FileKind::Baked, &d.join("forged.baked"), &baked).unwrap();
    let out = run(
        d,
        &[
            "play",
            "forged.baked",
            "--variant",
            "Pearly Swirly",
            "--out-dir",
            "forged",
        ],
        false,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    for needle in [
        "forged.baked",
        "variant \"Pearly Swirly\"",
        "\"Paint 1 Carmine\"",
        "\"Forged glaze\"",
        "alpha mode",
    ] {
        assert!(err.contains(needle), "{err} lacks {needle}");
    }
    assert!(
        !d.join("forged").exists(),
        "frames written before the refusal"
    );
    // inspect says so too; the other variants still play.
    let info = run_json(d, &["inspect", "forged.baked"]);
    let refused = info["variants_refused"].as_object().unwrap();
    assert_eq!(refused.keys().collect::<Vec<_>>(), ["Pearly Swirly"]);
    run(
        d,
        &["play", "forged.baked", "--variant", "Torched Graphite"],
        true,
    );
}
