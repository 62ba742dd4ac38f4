//! A tiny sweep on the demo car: outputs exist and its figures agree with each other and with
//! what DESIGN guarantees at the recorded pattern.

use trisort_bench::sweep::{run, Factor, SweepConfig, SweepPoint, SweepReport, CSV_COLUMNS};

#[test]
fn tiny_sweep_writes_consistent_outputs() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let scene = trisort_scene::demo_car(10_000);
    let timeline = trisort_paths::load(
        "orbit:frames=4,degrees=30,elevation=15,distance=2.75",
        &scene,
        &Default::default(),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep-out");
    let config = SweepConfig {
        frames: vec![0, 3],
        factors: vec![
            Factor::Segment,
            Factor::RecordSize,
            Factor::GlassOpacity,
            Factor::Bridge,
        ],
        ..SweepConfig::new((64, 64), 4)
    };
    let lines = std::cell::RefCell::new(Vec::new());
    let report = run(&gpu, &working(&scene, &timeline), &config, &out, &|s| {
        lines.borrow_mut().push(s.to_string())
    })
    .unwrap();
    let lines = lines.into_inner();
    assert!(lines.len() >= report.points.len(), "{lines:?}");

    // Factors run in the canonical order, whatever order they were asked in.
    let factors: Vec<&str> = report.points.iter().map(|p| p.factor.as_str()).collect();
    let mut expected = vec!["record-size"; 3];
    expected.extend(["glass-opacity"; 3]);
    expected.extend(["bridge"; 3]);
    expected.extend(["segment"; 4]);
    assert_eq!(factors, expected);

    check_outputs(&report, &out);

    // The default point is one bake, measured once: identical figures under every factor.
    let defaults: Vec<&SweepPoint> = report.points.iter().filter(|p| p.is_default).collect();
    assert_eq!(defaults.len(), 4);
    let d = defaults[0];
    for p in &defaults {
        assert_eq!(
            (p.baked_bytes, p.index_triangles, p.pixels_differing),
            (d.baked_bytes, d.index_triangles, d.pixels_differing)
        );
        assert_eq!(p.merge_seconds, d.merge_seconds);
    }
    let value = |f: &str, v: &str| {
        report
            .points
            .iter()
            .find(|p| p.factor == f && p.value.starts_with(v))
            .unwrap()
    };
    assert!(value("record-size", "1x").is_default);
    assert!(value("record-size", "0.5x (32x32)").record_seconds > 0.0);
    assert!(value("segment", "64").is_default);
    assert!(value("bridge", "visible").is_default);
    // `visible` draws exactly each frame's V_f, for more copies.
    assert_eq!(value("bridge", "visible").drawn_not_visible_mean, 0.0);
    assert!(
        value("bridge", "visible").index_triangles >= value("bridge", "hidden").index_triangles
    );

    for p in &report.points {
        check_point(p, d, 2 * 64 * 64);
    }

    // Draws along the path: the default bake's, every frame.
    assert_eq!(report.draws_along_path.len(), 4);
    assert_eq!(report.path_frames, 4);
    assert_eq!(
        report.draws_along_path.iter().map(|x| x.1).max().unwrap(),
        d.draws_per_frame_max
    );
    let mean = report
        .draws_along_path
        .iter()
        .map(|x| x.1 as f64)
        .sum::<f64>()
        / 4.0;
    assert!((mean - d.draws_per_frame_mean).abs() < 1e-9);
    assert!(!report.default_merge.is_empty());
}

/// The sweep's files in `out`: CSV and JSON with one entry per point, the three plots with
/// their titles and every factor in the error plot's legend, and nothing else.
fn check_outputs(report: &SweepReport, out: &std::path::Path) {
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let csv_lines: Vec<&str> = csv.lines().collect();
    assert_eq!(csv_lines.len(), report.points.len() + 1);
    assert_eq!(csv_lines[0], CSV_COLUMNS.join(","));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sweep.json")).unwrap()).unwrap();
    assert_eq!(
        json["points"].as_array().unwrap().len(),
        report.points.len()
    );
    assert_eq!(json["device"], report.device);
    for (name, title) in [
        ("sweep-error-vs-bake-time.svg", "error vs bake time"),
        ("sweep-error-vs-baked-size.svg", "error vs baked size"),
        ("sweep-draws-along-path.svg", "Draws per frame"),
    ] {
        let svg = std::fs::read_to_string(out.join(name)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains(title), "{name}");
    }
    let error_plot = std::fs::read_to_string(out.join("sweep-error-vs-bake-time.svg")).unwrap();
    for f in ["record-size", "glass-opacity", "bridge", "segment"] {
        assert!(error_plot.contains(f), "legend lacks {f}");
    }
    // Nothing else is left in the folder (no temporary files).
    assert_eq!(std::fs::read_dir(out).unwrap().count(), 5);
}

/// One point's figures against each other and against the default point `d`; `frames_px`
/// is the pixels of the compared frames.
fn check_point(p: &SweepPoint, d: &SweepPoint, frames_px: u64) {
    let what = format!("{} = {}", p.factor, p.value);
    // Merge factors reuse the default recording; recording factors pay for theirs.
    if p.factor == "bridge" || p.factor == "segment" {
        assert!(!p.bake_includes_record, "{what}");
        assert_eq!(p.bake_seconds, p.merge_seconds, "{what}");
        assert_eq!(p.record_seconds, d.record_seconds, "{what}");
        assert_eq!(p.unique_visible, d.unique_visible, "{what}");
    } else {
        assert!(p.bake_includes_record, "{what}");
        assert!(
            (p.bake_seconds - (p.record_seconds + p.merge_seconds)).abs() < 1e-9,
            "{what}"
        );
    }
    // Rule 1: every triangle of G is drawn somewhere.
    assert!(p.index_triangles >= p.unique_visible, "{what}");
    assert!(p.unique_visible > 0, "{what}");
    assert!(p.baked_bytes > 0, "{what}");
    assert!(p.draws_per_frame_max >= 1, "{what}");
    assert!(
        p.draws_per_frame_mean <= p.draws_per_frame_max as f64,
        "{what}"
    );
    assert!(p.wall_ms_mean > 0.0, "{what}");
    assert!(p.pixels_differing <= frames_px, "{what}");
    assert!(
        (p.pixels_differing_fraction - p.pixels_differing as f64 / frames_px as f64).abs() < 1e-12,
        "{what}"
    );
    assert!((0.0..=1.0).contains(&p.flip_mean), "{what}");
    assert_eq!(p.pixels_differing == 0, p.max_channel_diff == 0, "{what}");
    // At the recorded pattern (playback size and samples, same device, the point's own
    // glass opacity) a bake without unordered samples matches the exact reference within
    // 1/255 (the one rounding of the 8-bit store). Only the record-size points leave the pattern.
    let at_pattern = p.factor != "record-size" || p.value.starts_with("1x");
    if at_pattern && p.unordered_samples == 0 {
        assert!(p.max_channel_diff <= 1, "{what}: {p:?}");
    }
}

#[test]
fn bad_configurations_are_refused_before_any_work() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let scene = trisort_scene::demo_car(2_000);
    let timeline = trisort_paths::load("orbit:frames=2", &scene, &Default::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let base = SweepConfig::new((32, 32), 4);
    for (config, needle) in [
        (
            SweepConfig {
                frames: vec![5],
                ..base.clone()
            },
            "frame 5",
        ),
        (
            SweepConfig {
                samples: 2,
                ..base.clone()
            },
            "samples",
        ),
        (
            SweepConfig {
                size: (0, 32),
                ..base.clone()
            },
            "size",
        ),
        (
            SweepConfig {
                saturation: 0.0,
                ..base.clone()
            },
            "saturation",
        ),
    ] {
        let e = run(
            &gpu,
            &working(&scene, &timeline),
            &config,
            dir.path(),
            &|_| {},
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains(needle), "{e}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// The scene and path as given (no split): what these tests sweep.
fn working(
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
) -> trisort_bake::Working {
    trisort_bake::Working::whole(scene.clone(), timeline.clone(), None, 0.0)
}
