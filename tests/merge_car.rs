//! `trisort merge` on real recordings and `trisort inspect --matrix`, through the real binary:
//! CarConcept, 12 frames of an orbit at 128×128, merged with every strategy × layout, each
//! checked by the independent validator; the matrix picture of a baked file.

use std::path::Path;

use trisort_format::{Baked, FileKind, Recording};
use trisort_merger::{Choice, Layout, MergeOptions, Strategy};

use crate::support::*;

fn read_baked(path: &Path) -> Baked {
    trisort_format::read_file(FileKind::Baked, path).unwrap()
}

/// Issue 4: CarConcept, 12 frames of an orbit at 128×128 — every strategy × layout passes
/// the validator, and unique_visible ≤ index_triangles ≤ source_triangles. `auto` through the
/// binary keeps the best of them and `verify --recording` accepts it.
#[test]
fn car_concept_orbit_merges_validly_with_every_strategy_and_layout() {
    let Some(car) = scene("CarConcept") else {
        return;
    };
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let d = dir.path();
    run_json(
        d,
        &[
            "record",
            &car,
            "--path",
            "orbit:frames=12",
            "--size",
            "128x128",
            // Every strategy and layout merges this recording: at the recorded pattern only,
            // whose graphs are a ninth of the conservative default's at this size (the default's
            // merge is bake_play_cli's).
            "--conservative=false",
            "-o",
            "car.rec",
        ],
    );
    let rec: Recording =
        trisort_format::read_file(FileKind::Recording, &d.join("car.rec")).unwrap();
    let recs = std::slice::from_ref(&rec);
    let mut fewest = u64::MAX;
    for strategy in Strategy::ALL {
        for layout in Layout::ALL {
            let opts = MergeOptions {
                strategy: Choice::Only(strategy),
                layout: Choice::Only(layout),
                ..MergeOptions::default()
            };
            let baked = trisort_merger::merge(recs, &opts)
                .unwrap()
                .lit(trisort_light::studio());
            let report = trisort_verify::check_graph(recs, &baked);
            assert!(report.ok, "{strategy:?} {layout:?}: {:?}", report.problems);
            let s = &baked.stats;
            assert!(
                s.unique_visible <= s.index_triangles && s.index_triangles <= s.source_triangles,
                "{strategy:?} {layout:?}: {s:?}"
            );
            assert_eq!(s.unique_visible, rec.unique_visible.len() as u64);
            fewest = fewest.min(s.index_triangles);
        }
    }
    let v = run_json(d, &["merge", "car.rec", "-o", "car.trisort"]);
    assert_eq!(
        v["index_triangles"].as_u64(),
        Some(fewest),
        "auto keeps the best: {v}"
    );
    assert!(
        v["seconds"].as_f64().unwrap() > 0.0,
        "measured merge time: {v}"
    );
    let report = run_json(d, &["verify", "car.trisort", "--recording", "car.rec"]);
    assert_eq!(report["ok"], true, "{report}");
}

/// `inspect --matrix` draws every non-empty cell (i, j) of the upper triangle in a colour of
/// the map, leaves empty cells grey and the lower triangle white, and colours by count (a
/// turntable's cells differ, so the picture is not uniform). No GPU: the recording is
/// synthetic.
#[test]
fn inspect_matrix_draws_the_cells_coloured_by_count() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let rec = trisort_merger::synth::turntable(&trisort_merger::synth::Turntable {
        objects: 12,
        sides: 12,
        frames: 20,
        samples: 256,
        degrees: 120.0,
        ..Default::default()
    });
    trisort_format::write_file_atomic(FileKind::Recording, &d.join("synth.rec"), &rec).unwrap();
    let m = run_json(
        d,
        &[
            "merge",
            "synth.rec",
            "-o",
            "synth.trisort",
            "--strategy",
            "ibl",
        ],
    );
    assert!(
        m["seconds"].as_f64().unwrap() > 0.0,
        "measured merge time: {m}"
    );
    let v = run_json(d, &["inspect", "synth.trisort", "--matrix", "m.png"]);
    let info = &v["matrix"];
    let img = image::open(d.join("m.png")).unwrap().to_rgb8();
    assert_eq!(
        (img.width() as u64, img.height() as u64),
        (
            info["width"].as_u64().unwrap(),
            info["height"].as_u64().unwrap()
        )
    );
    let baked = read_baked(&d.join("synth.trisort"));
    let frames = baked.frames.len() as u32;
    assert_eq!(frames, 20);
    let cell = info["cell_pixels"].as_u64().unwrap() as u32;
    let origin = info["origin"].as_array().unwrap();
    let (ox, oy) = (
        origin[0].as_u64().unwrap() as u32,
        origin[1].as_u64().unwrap() as u32,
    );
    assert_eq!(info["frames_per_pixel"], 1);
    assert!(cell >= 2 && ox + frames * cell <= img.width() && oy + frames * cell <= img.height());
    let at = |i: u32, j: u32| {
        img.get_pixel(ox + j * cell + cell / 2, oy + i * cell + cell / 2)
            .0
    };
    let white = [255u8, 255, 255];
    let mut filled = std::collections::HashSet::new();
    let mut colours = std::collections::HashSet::new();
    for c in &baked.merge.cells {
        let p = at(c.first_frame, c.last_frame);
        assert_ne!(p, white, "cell ({}, {})", c.first_frame, c.last_frame);
        filled.insert((c.first_frame, c.last_frame));
        colours.insert(p);
    }
    assert_eq!(info["cells"].as_u64(), Some(baked.merge.cells.len() as u64));
    assert!(
        colours.len() >= 3,
        "counts differ, so colours do: {colours:?}"
    );
    let mut empty = None;
    for i in 0..frames {
        for j in 0..frames {
            let p = at(i, j);
            if j < i {
                assert_eq!(p, white, "lower triangle ({i}, {j})");
            } else if !filled.contains(&(i, j)) {
                assert!(!colours.contains(&p), "empty cell ({i}, {j}) looks filled");
                assert_eq!(*empty.get_or_insert(p), p, "empty cells share one colour");
            }
        }
    }
    assert!(
        empty.is_some(),
        "a 20-frame turntable leaves some cells empty"
    );
    // The legend: its colour bar runs from the largest count (top) to the smallest.
    let bar_x = ox + frames * cell + 16 + 8;
    let top = img.get_pixel(bar_x, oy).0;
    let bottom = img.get_pixel(bar_x, oy + frames * cell - 1).0;
    assert_ne!(top, bottom);
    assert!(info["min_triangles"].as_u64().unwrap() < info["max_triangles"].as_u64().unwrap());
}
