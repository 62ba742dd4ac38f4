//! `play --self-check` and `--subpixel-offset` through the real binary: an honest
//! bake of the demo car shows no hole at its recorded pattern; the same bake with one visible
//! triangle removed from frame 0 shows one there (exit 3, per-frame `holes`); a shifted
//! projection opens holes that `verify --subpixel-offset` measures against the exact
//! reference shifted the same way.

use std::path::Path;

use trisort_format::{Baked, FileKind, Recording};

use crate::support::*;

const SCENE: &str = "demo:10000";

/// `baked` without its `k`-th copy: every draw after it starts 3 indices earlier, the draw
/// holding it is one triangle shorter.
fn without_copy(baked: &Baked, k: usize) -> Baked {
    let mut b = baked.clone();
    b.copies.remove(k);
    let at = 3 * k as u32;
    for d in &mut b.draws {
        if d.first_index > at {
            d.first_index -= 3;
        } else if d.first_index + d.index_count > at {
            d.index_count -= 3;
        }
    }
    b
}

#[test]
fn self_check_finds_a_removed_visible_triangle_and_offsets_open_holes() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    run(
        d,
        &args(&format!(
            "bake {SCENE} --path orbit:frames=2,degrees=40 --size 64x64 --samples 4 -o car.baked"
        )),
        true,
    );
    let honest = run_json(d, &args("play car.baked --mode depth --self-check"));
    let frames = honest["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 2);
    for f in frames {
        assert_eq!(f["holes"], 0, "{honest}");
    }
    assert_eq!(honest["self_check"]["ok"], true);

    // Frame 0's opaque visible triangle that nothing lies in front of (no edge into it) and
    // that lies in front of the most samples (the recording's edges), cut out of the frame's
    // draws. (Opaque and uncovered: see-through glass, recorded at opacity 0, shows the
    // background in depth mode, so neither it nor what lies behind it changes a pixel.)
    let baked: Baked = trisort_format::read_file(FileKind::Baked, &d.join("car.baked")).unwrap();
    let rec: Recording =
        trisort_format::read_file(FileKind::Recording, &d.join("car.baked.rec")).unwrap();
    let f0 = &rec.frames[0];
    let g = &baked.geometry;
    let opaque = |t: u32| {
        let local = baked.scene_ids.binary_search(&t).unwrap();
        let m = &g.materials[g.vertices[g.triangles[local][0] as usize].material as usize];
        m.alpha_mode == trisort_format::AlphaMode::Opaque && m.transmission == 0.0
    };
    let front = f0
        .visible
        .iter()
        .filter(|&&t| opaque(t) && !f0.edges.iter().any(|e| e.to == t))
        .max_by_key(|&&t| {
            let w: u32 = f0
                .edges
                .iter()
                .filter(|e| e.from == t)
                .map(|e| e.weight)
                .sum();
            (w, std::cmp::Reverse(t))
        })
        .copied()
        .unwrap();
    let local = baked.scene_ids.binary_search(&front).unwrap() as u32;
    let w = baked.frames[0];
    let k = baked.draws[w.first as usize..(w.first + w.count) as usize]
        .iter()
        .flat_map(|a| a.first_index / 3..(a.first_index + a.index_count) / 3)
        .find(|&k| baked.copies[k as usize] == local)
        .expect("frame 0 draws its visible triangle");
    let forged = without_copy(&baked, k as usize);
    trisort_format::write_file_atomic(FileKind::Baked, &d.join("forged.baked"), &forged).unwrap();
    let out = run(
        d,
        &args("play forged.baked --mode depth --self-check --frames 0..1 --json"),
        false,
    );
    assert_eq!(out.status.code(), Some(3));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["frames"][0]["holes"].as_u64().unwrap() > 0, "{v}");
    assert_eq!(v["self_check"]["ok"], false);
    // The text report names the frame.
    let out = run(
        d,
        &args("play forged.baked --self-check --frames 0..1"),
        false,
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("frame 0:") && text.contains("hole pixels"),
        "{text}"
    );

    // A quarter-pixel shift: the self-check and the shifted exact reference both see holes.
    let shifted = run(
        d,
        &args("play car.baked --self-check --subpixel-offset 1/4,-1/8 --json"),
        false,
    );
    let v: serde_json::Value = serde_json::from_slice(&shifted.stdout).unwrap();
    assert_eq!(v["subpixel_offset"], serde_json::json!([0.25, -0.125]));
    let holes: u64 = v["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["holes"].as_u64().unwrap())
        .sum();
    assert!(holes > 0, "{v}");
    let verified = run_json(
        d,
        &args("verify car.baked --scene demo:10000 --recording car.baked.rec --mode depth --subpixel-offset 0.25,-0.125 --measure-only --allow-unverified"),
    );
    assert_eq!(verified["at_recorded_pattern"], false);
    let differing: u64 = verified["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["pixels_differing"].as_u64().unwrap())
        .sum();
    // Every hole the file's own triangles show is a pixel the exact reference disagrees with;
    // the reference also sees triangles that are not in the file at all.
    assert!(differing >= holes, "{differing} < {holes}");
    // Zero offset is the recorded pattern.
    let zero = run_json(
        d,
        &args("verify car.baked --scene demo:10000 --recording car.baked.rec --mode depth --subpixel-offset 0,0"),
    );
    assert_eq!(zero["at_recorded_pattern"], true);
    assert_eq!(zero["ok"], true);
}

#[test]
fn a_bad_subpixel_offset_is_refused() {
    let Some(dir) = gpu_tempdir() else { return };
    for bad in ["1", "a,b", "1/0,0", "100,0", "nan,0"] {
        let out = run(
            dir.path(),
            &["play", "missing.baked", "--subpixel-offset", bad],
            false,
        );
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("offset"), "{bad}: {err}");
    }
}

/// Sum of per-frame `holes` of `play BAKED --self-check --subpixel-offset OFFSET --json`, and
/// whether it exited 0.
fn self_check_holes(dir: &std::path::Path, baked: &str, offset: &str) -> (u64, bool) {
    let out = trisort(dir)
        .args([
            "play",
            baked,
            "--self-check",
            "--subpixel-offset",
            offset,
            "--json",
        ])
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!("{e}: {}", String::from_utf8_lossy(&out.stderr));
    });
    let holes = v["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["holes"].as_u64().unwrap())
        .sum();
    (holes, out.status.success())
}

/// The default bake (the conformant raster profile) opens no hole and stays exact within
/// its tolerance (no hole; in blend mode no pixel off by more than 1/255, on lavapipe and on
/// llvmpipe-GL); the browser profile none within its wider ±1/8 px box, for more triangles.
#[test]
fn a_conservative_bake_stays_exact_and_opens_no_hole_within_its_tolerance() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    bake_the_raster_profiles(d);
    the_profiled_bakes_verify(d);
    moved_by_an_eighth_plain_has_holes_robust_none(d);
    the_default_within_its_tolerance_has_no_hole(d);
    the_default_within_its_tolerance_stays_exact_in_blend(d);
    the_browser_bake_within_its_box_and_beyond_tolerances(d);
}

/// Bakes plain (`--conservative=false`), default, browser and robust bakes: each reports its
/// raster profile, and the wider the box the more triangles it keeps.
fn bake_the_raster_profiles(d: &Path) {
    let bake = format!("bake {SCENE} --path orbit:frames=2,degrees=40 --size 64x64 --samples 4");
    let plain = run_json(
        d,
        &[args(&bake), args("-o plain.baked --conservative=false")].concat(),
    );
    // The default records conservatively for a conformant GPU: ±1/512 px for transforms
    // and a 1/512 px snap (8 bits), depth at the sample.
    let default = run_json(d, &[args(&bake), vec!["-o", "default.baked"]].concat());
    assert_eq!(
        default["raster_profile"],
        serde_json::json!({
            "name": "conformant", "tolerance": 1.0 / 512.0, "subpixel_bits": [8, 8],
            "depth_at": "sample", "size": [64, 64], "samples": 4,
            "sample_locations": "standard", "conservative": true, "patterns": 1,
        }),
        "{default}"
    );
    assert_eq!(
        default["robust"],
        serde_json::json!({"patterns": 1, "tolerance": 1.0 / 512.0, "conservative": true}),
        "{default}"
    );
    let browser = run_json(
        d,
        &[
            args(&bake),
            args("-o browser.baked --raster-profile browser"),
        ]
        .concat(),
    );
    assert_eq!(browser["raster_profile"]["name"], "browser", "{browser}");
    assert_eq!(browser["raster_profile"]["depth_at"], "pixel", "{browser}");
    assert_eq!(
        browser["raster_profile"]["subpixel_bits"],
        serde_json::json!([4, 8])
    );
    let robust = run_json(
        d,
        &[
            args(&bake),
            args("-o robust.baked --conservative --robust 2 --robust-tolerance 0.125"),
        ]
        .concat(),
    );
    assert_eq!(
        robust["robust"],
        serde_json::json!({"patterns": 2, "tolerance": 0.125, "conservative": true}),
        "{robust}"
    );
    assert_eq!(
        plain["raster_profile"]["name"], "exact",
        "--conservative=false is the exact profile: {plain}"
    );
    assert_eq!(plain["robust"]["conservative"], false, "{plain}");
    let tris = |v: &serde_json::Value| v["source_triangles"].as_u64().unwrap();
    assert!(tris(&robust) > tris(&plain), "{robust}\n{plain}");
    assert!(tris(&default) > tris(&plain), "{default}\n{plain}");
    assert!(tris(&browser) > tris(&default), "{browser}\n{default}");
}

/// The robust, default and browser bakes are valid and exact at their recorded pattern.
fn the_profiled_bakes_verify(d: &Path) {
    // Still valid bakes, exact at their recorded pattern.
    for b in ["robust", "default", "browser"] {
        run(
            d,
            &args(&format!("verify {b}.baked --recording {b}.baked.rec")),
            true,
        );
    }
    run(
        d,
        &args("verify robust.baked --recording robust.baked.rec --scene demo:10000 --mode depth"),
        true,
    );
}

/// Moved by 1/8 px, the plain bake shows holes, the robust one (±1/8 px) none.
fn moved_by_an_eighth_plain_has_holes_robust_none(d: &Path) {
    let (plain_holes, plain_ok) = self_check_holes(d, "plain.baked", "1/8,0");
    assert!(plain_holes > 0 && !plain_ok, "{plain_holes}");
    let (robust_holes, robust_ok) = self_check_holes(d, "robust.baked", "1/8,0");
    assert_eq!((robust_holes, robust_ok), (0, true));
}

/// The default bake moved within its tolerance opens no hole, on lavapipe and on
/// llvmpipe-GL.
fn the_default_within_its_tolerance_has_no_hole(d: &Path) {
    // The default, moved anywhere within its tolerance: no hole, and in blend mode no pixel
    // differs from the exact reference moved alike beyond what the recorded pattern shows.
    for offset in ["1/512,0", "0,-1/512", "-1/512,1/512", "1/1024,1/512"] {
        assert_eq!(
            self_check_holes(d, "default.baked", offset),
            (0, true),
            "the default bake moved by {offset} px"
        );
    }
    // The same bake (recorded on lavapipe-Vulkan) on llvmpipe-GL: no hole either.
    for offset in ["1/512,0", "-1/512,1/512"] {
        let out = trisort(d)
            .args(["play", "default.baked", "--backend", "gl", "--self-check"])
            .args(["--subpixel-offset", offset, "--json"])
            .output()
            .unwrap();
        let Ok(v) = serde_json::from_slice::<serde_json::Value>(&out.stdout) else {
            let err = String::from_utf8_lossy(&out.stderr);
            if std::env::var(trisort_testkit::REQUIRE_GPU_ENV).as_deref() == Ok("1") {
                panic!("no GL adapter and TRISORT_REQUIRE_GPU=1: {err}");
            }
            eprintln!("skipping the GL part: {err}");
            break;
        };
        assert_eq!(v["backend"], "Gl", "{v}");
        assert_eq!(v["self_check"]["holes"], 0, "GL, moved by {offset} px: {v}");
        assert!(out.status.success());
    }
}

/// The default bake moved within its tolerance differs from the exact reference moved alike
/// by at most 1/255 in blend mode.
fn the_default_within_its_tolerance_stays_exact_in_blend(d: &Path) {
    // In blend mode, no pixel differs from the exact reference moved alike by more than
    // 1/255 (`--max-error 1`: such a frame fails), on lavapipe and, played there, on
    // llvmpipe-GL: the grown capture's order holds wherever the moved samples fall.
    let gl = std::env::var(trisort_testkit::REQUIRE_GPU_ENV).as_deref() == Ok("1");
    for (offset, backend) in [
        ("1/512,0", "auto"),
        ("0,-1/512", "auto"),
        ("-1/512,1/512", "auto"),
        ("1/512,1/512", "auto"),
        ("-1/512,-1/512", "auto"),
        ("1/1024,1/512", "auto"),
        ("1/512,0", "gl"),
        ("-1/512,-1/512", "gl"),
    ] {
        if backend == "gl" && !gl {
            // The GL part needs llvmpipe-GL, which CI installs; elsewhere it may be missing.
            continue;
        }
        let v = run_json(
            d,
            &[
                args(&format!(
                    "verify default.baked --recording default.baked.rec --scene {SCENE}"
                )),
                args("--mode blend --max-error 1 --backend"),
                vec![backend, "--subpixel-offset", offset],
            ]
            .concat(),
        );
        assert_eq!(v["at_recorded_pattern"], false, "{v}");
        for f in v["frames"].as_array().unwrap() {
            assert_eq!(
                f["pixels_over_tolerance_ordered"], 0,
                "blend, moved by {offset} px on {backend}: {f}"
            );
        }
    }
}

/// The browser bake opens no hole within its ±1/8 px box; beyond their tolerances the
/// default and the plain bakes do.
fn the_browser_bake_within_its_box_and_beyond_tolerances(d: &Path) {
    for offset in ["1/16,0", "1/8,0", "0,-1/8", "-0.1,0.1"] {
        assert_eq!(
            self_check_holes(d, "browser.baked", offset),
            (0, true),
            "the browser bake moved by {offset} px"
        );
    }
    // Moved by 1/16 px, far beyond its tolerance, the default bake is no longer hole-free
    // on this scene, as the pattern-only bake is not at 1/512 px: the profile's box is what
    // it pays for.
    assert!(self_check_holes(d, "default.baked", "1/16,0").0 > 0);
    assert!(self_check_holes(d, "plain.baked", "1/512,1/512").0 > 0);
}

/// `play` checks the device against the bake's raster profile: lavapipe satisfies the
/// conformant one (8 sub-pixel bits by the API and by the probe, standard positions); a probe
/// run on a shifted pattern does not, which gives a warning naming the sample positions, and
/// `--strict-profile` refuses to play.
#[test]
fn play_checks_the_device_against_the_raster_profile() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    run(
        d,
        &args(&format!(
            "bake {SCENE} --path orbit:frames=1 --size 48x48 --samples 4 -o car.baked"
        )),
        true,
    );
    let inspect = run_json(d, &args("inspect car.baked"));
    assert_eq!(inspect["raster_profile"]["name"], "conformant", "{inspect}");
    let v = run_json(d, &args("play car.baked"));
    let c = &v["profile_check"];
    assert_eq!(c["ok"], true, "{c}");
    assert_eq!(c["differences"], serde_json::json!([]));
    assert_eq!(c["profile"]["name"], "conformant");
    assert_eq!(
        c["probe"]["consistent_subpixel_bits"],
        serde_json::json!([8]),
        "{c}"
    );
    if v["backend"] == "Vulkan" {
        assert_eq!(c["api"]["subpixel_bits"], 8, "{c}");
        assert_eq!(c["api"]["standard_sample_locations"], true, "{c}");
    }
    // The probe moved by 1/64 px, as the player is: no longer the standard positions.
    let out = trisort(d)
        .args(["play", "car.baked", "--json", "--subpixel-offset", "1/64,0"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let c = &v["profile_check"];
    assert_eq!(c["ok"], false, "{c}");
    let why = c["differences"][0].as_str().unwrap();
    assert!(why.starts_with("sample positions"), "{why}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("outside the raster profile `conformant`")
            && stderr.contains("sample positions"),
        "{stderr}"
    );
    let stderr = refused(
        d,
        "play car.baked --strict-profile --subpixel-offset 1/64,0 --out-dir frames",
    );
    assert!(
        stderr.contains("--strict-profile") && stderr.contains("sample positions"),
        "{stderr}"
    );
    assert!(!d.join("frames").join("frame-00000.png").exists());
    // A profile asking for what no device here has: 4-bit snapping only.
    run(
        d,
        &args(&format!(
            "bake {SCENE} --path orbit:frames=1 --size 48x48 --samples 4 --raster-profile snap4 --subpixel-bits 4 -o snap.baked"
        )),
        true,
    );
    let stderr = refused(d, "play snap.baked --strict-profile");
    assert!(
        stderr.contains("sub-pixel precision") && stderr.contains("asks 4"),
        "{stderr}"
    );
    // Contradicting options are refused before anything is recorded.
    let stderr = refused(
        d,
        &format!(
            "bake {SCENE} --path orbit:frames=1 --size 48x48 --raster-profile browser --conservative=false -o x.baked"
        ),
    );
    assert!(stderr.contains("--raster-profile exact"), "{stderr}");
    assert!(!d.join("x.baked").exists());
}

/// The stderr of `trisort LINE` run in `dir`, which must fail ([`run`] checks that).
fn refused(dir: &std::path::Path, line: &str) -> String {
    String::from_utf8_lossy(&run(dir, &args(line), false).stderr).into_owned()
}
