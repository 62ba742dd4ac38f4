//! Scaling benchmark: the quick configuration runs on the GPU, its rows are
//! consistent and every output is written. Timings are measured, never asserted.

use trisort_bench::scaling::{
    self, growth, growth_exponent, path_spec, ScalingConfig, ScalingRow, AXIS_FRAMES,
    AXIS_FRAMES_SEGMENTED, AXIS_SYNTHETIC, AXIS_TRIANGLES,
};

#[test]
fn slope_of_a_power_law() {
    let pts: Vec<(f64, f64)> = [1.0_f64, 10.0, 100.0]
        .iter()
        .map(|&x| (x, 3.0 * x.powf(1.5)))
        .collect();
    assert!((growth_exponent(&pts).unwrap() - 1.5).abs() < 1e-12);
    assert_eq!(growth_exponent(&pts[..1]), None);
    assert_eq!(growth_exponent(&[(1.0, 1.0), (1.0, 2.0)]), None);
    let with_nan = growth_exponent(&[(1.0, f64::NAN), (2.0, 1.0), (4.0, 4.0)]).unwrap();
    assert!((with_nan - 2.0).abs() < 1e-12);
}

#[test]
fn path_placeholders() {
    assert_eq!(
        path_spec("orbit:frames={frames},degrees={frames*3.6}", 30).unwrap(),
        "orbit:frames=30,degrees=108"
    );
    assert_eq!(path_spec("orbit:frames=4", 9).unwrap(), "orbit:frames=4");
    assert!(path_spec("orbit:frames={n}", 3).is_err());
    assert!(path_spec("orbit:frames={frames", 3).is_err());
    assert!(path_spec("orbit:frames={frames*x}", 3).is_err());
}

/// Checks what every row must satisfy, whatever the timing.
fn check_row(r: &ScalingRow) {
    assert!(r.unique_visible > 0, "{r:?}");
    assert!(r.unique_visible <= r.triangles, "{r:?}");
    assert!(r.index_triangles >= r.unique_visible, "{r:?}");
    assert!(
        r.merge_seconds.is_finite() && r.merge_seconds >= 0.0,
        "{r:?}"
    );
    assert!(r.draws_per_frame_max >= 1, "{r:?}");
    assert!(
        r.draws_per_frame_mean <= f64::from(r.draws_per_frame_max),
        "{r:?}"
    );
    assert!(r.layers_mean >= 2.0, "{r:?}");
    if let Some(c) = r.merge_cpu_seconds {
        assert!(c >= 0.0, "{r:?}");
    }
    if r.axis == AXIS_SYNTHETIC {
        assert!(r.record_seconds.is_nan() && r.record_seconds_per_frame.is_nan());
        assert_eq!(r.record_cpu_seconds, None);
    } else {
        if cfg!(target_os = "linux") {
            assert!(r.record_cpu_seconds.unwrap() >= 0.0, "{r:?}");
        }
        assert!(r.record_seconds > 0.0, "{r:?}");
        let per_frame = r.record_seconds / f64::from(r.frames);
        assert!(
            (r.record_seconds_per_frame - per_frame).abs() < 1e-12,
            "{r:?}"
        );
    }
    if let Some(m) = r.peak_rss_mib {
        assert!(m > 0.0, "{r:?}");
    }
}

#[test]
fn quick_configuration_runs_and_writes_consistent_outputs() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let config = ScalingConfig::quick();
    let progress = |s: &str| eprintln!("{s}");

    let tri = scaling::triangles(&gpu, &config, &progress).unwrap();
    assert_eq!(tri.len(), config.triangle_counts.len());
    for (r, &asked) in tri.iter().zip(&config.triangle_counts) {
        eprintln!("{r:?}");
        check_row(r);
        assert_eq!(r.axis, AXIS_TRIANGLES);
        assert_eq!(r.frames, config.triangle_axis_frames);
        // The demo car has about the triangles asked for (within a few per cent).
        let off = (r.triangles as f64 / f64::from(asked) - 1.0).abs();
        assert!(off < 0.1, "asked {asked}, got {}", r.triangles);
    }
    assert!(tri[0].triangles < tri[1].triangles);

    let fr = scaling::frames(&gpu, &config, &progress).unwrap();
    assert_eq!(
        fr.len(),
        2 * config.frame_counts.len() + config.synthetic_frames.len()
    );
    let (real, synth) = fr.split_at(2 * config.frame_counts.len());
    let car = tri[0].triangles; // the 10 k car, as on the triangle axis
    for (pair, &n) in real.chunks(2).zip(&config.frame_counts) {
        let (one, seg) = (&pair[0], &pair[1]);
        for r in pair {
            eprintln!("{r:?}");
            check_row(r);
            assert_eq!(r.frames, n);
            assert_eq!(r.triangles, car);
            // A frame's window needs at most as many draws as there are frames.
            assert!(r.draws_per_frame_max <= n);
        }
        assert_eq!(one.axis, AXIS_FRAMES);
        assert_eq!(seg.axis, AXIS_FRAMES_SEGMENTED);
        // The same recording, merged twice.
        assert_eq!(one.record_seconds, seg.record_seconds);
        assert_eq!(one.unique_visible, seg.unique_visible);
        assert_eq!(one.layers_mean, seg.layers_mean);
    }
    for (r, &n) in synth.iter().zip(&config.synthetic_frames) {
        eprintln!("{r:?}");
        check_row(r);
        assert_eq!(r.axis, AXIS_SYNTHETIC);
        assert_eq!(r.frames, n);
        assert_eq!(r.triangles, 24 * 16);
        // Segments bound the draws per frame.
        assert!(r.draws_per_frame_max <= config.segment, "{r:?}");
        assert_eq!(r.layers_mean, 2.0);
    }

    let dir = tempfile::tempdir().unwrap();
    let mut rows = tri.clone();
    rows.extend(fr.iter().cloned());
    scaling::write_outputs(&rows, dir.path(), "quick").unwrap();
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "scaling-quick-frames.svg",
            "scaling-quick-index.svg",
            "scaling-quick-triangles.svg",
            "scaling-quick.csv",
            "scaling-quick.json",
        ],
        "no temporary file is left"
    );
    let csv = std::fs::read_to_string(dir.path().join("scaling-quick.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), rows.len() + 1);
    let columns = lines[0].split(',').count();
    assert!(lines.iter().all(|l| l.split(',').count() == columns));
    assert!(lines[1].starts_with("triangles,"));
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("scaling-quick.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(json["rows"].as_array().unwrap().len(), rows.len());
    assert_eq!(json["rows"][0]["axis"], "triangles");
    assert!(json["rows"][rows.len() - 1]["record_seconds"].is_null());
    let g = json["growth"].as_array().unwrap();
    assert_eq!(g.len(), growth(&rows).len());
    assert!(g
        .iter()
        .any(|s| s["axis"] == "triangles" && s["y"] == "record_seconds"));
    assert!(g
        .iter()
        .any(|s| s["axis"] == "frames" && s["y"] == "merge_seconds"));
    for svg in names.iter().filter(|n| n.ends_with(".svg")) {
        let text = std::fs::read_to_string(dir.path().join(svg)).unwrap();
        assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
        assert!(text.contains("<circle"), "{svg} has no data points");
    }
}
