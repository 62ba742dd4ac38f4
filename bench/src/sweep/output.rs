//! The sweep's outputs: `sweep.csv`, `sweep.json` and the plots.

use std::path::Path;

use super::{SweepPoint, SweepReport};
use crate::plot::{write_atomic, write_svg, write_svg_labelled, Chart, Series, Style};
use crate::BenchError;

/// The CSV columns, in order.
pub const CSV_COLUMNS: [&str; 21] = [
    "factor",
    "value",
    "is_default",
    "record_seconds",
    "merge_seconds",
    "bake_seconds",
    "bake_includes_record",
    "baked_bytes",
    "index_triangles",
    "unique_visible",
    "unordered_samples",
    "drawn_not_visible_mean",
    "draws_per_frame_mean",
    "draws_per_frame_max",
    "play_ms_mean",
    "play_ms_max",
    "wall_ms_mean",
    "pixels_differing",
    "pixels_differing_fraction",
    "max_channel_diff",
    "flip_mean",
];

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn csv_float(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        String::new()
    }
}

/// The sweep's points as CSV (a header line, then one line per point; missing figures empty).
pub fn to_csv(points: &[SweepPoint]) -> String {
    let mut out = CSV_COLUMNS.join(",");
    out.push('\n');
    for p in points {
        let fields = [
            csv_field(&p.factor),
            csv_field(&p.value),
            p.is_default.to_string(),
            csv_float(p.record_seconds),
            csv_float(p.merge_seconds),
            csv_float(p.bake_seconds),
            p.bake_includes_record.to_string(),
            p.baked_bytes.to_string(),
            p.index_triangles.to_string(),
            p.unique_visible.to_string(),
            p.unordered_samples.to_string(),
            csv_float(p.drawn_not_visible_mean),
            csv_float(p.draws_per_frame_mean),
            p.draws_per_frame_max.to_string(),
            csv_float(p.play_ms_mean),
            csv_float(p.play_ms_max),
            csv_float(p.wall_ms_mean),
            p.pixels_differing.to_string(),
            csv_float(p.pixels_differing_fraction),
            p.max_channel_diff.to_string(),
            csv_float(p.flip_mean),
        ];
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// The columns of `sweep-robust.csv`, in order.
pub const ROBUST_CSV_COLUMNS: [&str; 11] = [
    "value",
    "condition",
    "source_triangles_per_frame",
    "index_triangles",
    "baked_bytes",
    "record_seconds",
    "holes",
    "holes_fraction",
    "blend_differing",
    "order_errors",
    "pixels_differing_at_pattern",
];

/// The `robust` factor's points played off their pattern as CSV: one line per point and
/// condition ([`super::robustness`]).
pub fn robust_csv(points: &[SweepPoint]) -> String {
    let mut out = ROBUST_CSV_COLUMNS.join(",");
    out.push('\n');
    for p in points {
        for e in &p.robustness {
            let fields = [
                csv_field(&p.value),
                csv_field(&e.condition),
                csv_float(p.source_triangles_per_frame),
                p.index_triangles.to_string(),
                p.baked_bytes.to_string(),
                csv_float(p.record_seconds),
                e.holes.to_string(),
                csv_float(e.holes_fraction),
                e.blend_differing.to_string(),
                e.order_errors.to_string(),
                p.pixels_differing.to_string(),
            ];
            out.push_str(&fields.join(","));
            out.push('\n');
        }
    }
    out
}

/// One series per factor, in the order the factors ran, with each point's value as label.
fn per_factor(
    points: &[SweepPoint],
    x: impl Fn(&SweepPoint) -> f64,
    y: impl Fn(&SweepPoint) -> f64,
) -> (Vec<Series>, Vec<Vec<String>>) {
    let mut series: Vec<Series> = Vec::new();
    let mut labels: Vec<Vec<String>> = Vec::new();
    for p in points {
        let k = match series.iter().position(|s| s.name == p.factor) {
            Some(k) => k,
            None => {
                series.push(Series {
                    name: p.factor.clone(),
                    points: Vec::new(),
                });
                labels.push(Vec::new());
                series.len() - 1
            }
        };
        series[k].points.push((x(p), y(p)));
        let short = p.value.split(" (").next().unwrap_or(&p.value);
        labels[k].push(if p.is_default {
            format!("{short}*")
        } else {
            short.to_string()
        });
    }
    (series, labels)
}

pub(super) fn write_outputs(
    report: &SweepReport,
    segment_draws: &[(String, Vec<u32>)],
    out_dir: &Path,
) -> Result<(), BenchError> {
    write_atomic(
        &out_dir.join("sweep.csv"),
        to_csv(&report.points).as_bytes(),
    )?;
    let json = serde_json::to_string_pretty(report)
        .map_err(|e| BenchError::Invalid(format!("sweep.json: {e}")))?;
    write_atomic(&out_dir.join("sweep.json"), json.as_bytes())?;

    let subtitle = format!(
        "{}x{} {}x, {} frames compared",
        report.size.0,
        report.size.1,
        report.samples,
        report.frames.len()
    );
    // Error (pixels differing) against a cost, one labelled series per factor.
    let error_vs = |file: &str, cost: &str, x_label: &str, x: fn(&SweepPoint) -> f64| {
        let (series, labels) = per_factor(&report.points, x, |p| p.pixels_differing_fraction);
        let chart = Chart {
            title: format!("Sweep: error vs {cost} ({subtitle}; * default)"),
            x_label: x_label.into(),
            y_label: "pixels differing from the exact reference (fraction)".into(),
            log_x: true,
            log_y: false,
            series,
        };
        write_svg_labelled(&out_dir.join(file), &chart, Style::Points, &labels)
    };
    error_vs(
        "sweep-error-vs-bake-time.svg",
        "bake time",
        "bake seconds (record + merge; merge only for merge factors)",
        |p| p.bake_seconds,
    )?;
    error_vs(
        "sweep-error-vs-baked-size.svg",
        "baked size",
        "baked file size (MiB)",
        |p| p.baked_bytes as f64 / (1024.0 * 1024.0),
    )?;
    if report.points.iter().any(|p| !p.robustness.is_empty()) {
        write_atomic(
            &out_dir.join("sweep-robust.csv"),
            robust_csv(&report.points).as_bytes(),
        )?;
        // Holes against triangles per frame, one series per condition, labelled by value.
        let mut series: Vec<Series> = Vec::new();
        let mut labels: Vec<Vec<String>> = Vec::new();
        for p in report.points.iter().filter(|p| !p.robustness.is_empty()) {
            for e in &p.robustness {
                let k = match series.iter().position(|s| s.name == e.condition) {
                    Some(k) => k,
                    None => {
                        series.push(Series {
                            name: e.condition.clone(),
                            points: Vec::new(),
                        });
                        labels.push(Vec::new());
                        series.len() - 1
                    }
                };
                series[k]
                    .points
                    .push((p.source_triangles_per_frame, e.holes_fraction));
                labels[k].push(p.value.clone());
            }
        }
        write_svg_labelled(
            &out_dir.join("sweep-holes-vs-triangles.svg"),
            &Chart {
                title: format!("Robust recording: holes off the recorded pattern ({subtitle})"),
                x_label: "visible triangles per frame (Σ|V_f| / frames)".into(),
                y_label: "hole pixels (fraction)".into(),
                log_x: false,
                log_y: false,
                series,
            },
            Style::Points,
            &labels,
        )?;
    }
    let along = |name: String, draws: &[u32]| Series {
        name,
        points: draws
            .iter()
            .enumerate()
            .map(|(f, &d)| (f as f64, d as f64))
            .collect(),
    };
    let mut series = vec![Series {
        name: format!("default ({})", report.default_merge),
        points: report
            .draws_along_path
            .iter()
            .map(|&(f, d)| (f as f64, d as f64))
            .collect(),
    }];
    series.extend(segment_draws.iter().map(|(n, d)| along(n.clone(), d)));
    write_svg(
        &out_dir.join("sweep-draws-along-path.svg"),
        &Chart {
            title: format!(
                "Draws per frame along the path ({} frames)",
                report.path_frames
            ),
            x_label: "frame".into(),
            y_label: "indirect draws".into(),
            log_x: false,
            log_y: false,
            series,
        },
        Style::Lines,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_has_one_line_per_point_and_quotes_commas() {
        let p = SweepPoint {
            factor: "strategy-layout".into(),
            value: "a,b".into(),
            is_default: false,
            record_seconds: 1.0,
            merge_seconds: 0.5,
            bake_seconds: 0.5,
            bake_includes_record: false,
            baked_bytes: 10,
            index_triangles: 3,
            unique_visible: 2,
            unordered_samples: 0,
            drawn_not_visible_mean: 0.0,
            draws_per_frame_mean: 1.5,
            draws_per_frame_max: 2,
            play_ms_mean: f64::NAN,
            play_ms_max: f64::NAN,
            wall_ms_mean: 2.0,
            pixels_differing: 0,
            pixels_differing_fraction: 0.0,
            max_channel_diff: 0,
            flip_mean: 0.0,
            source_triangles_per_frame: 2.5,
            robustness: vec![],
        };
        let mut robust = p.clone();
        robust.value = "conservative".into();
        robust.robustness = vec![super::super::robustness::ConditionError {
            condition: "offset 1/16".into(),
            holes: 3,
            holes_fraction: 0.25,
            blend_differing: 5,
            order_errors: 2,
        }];
        let lines = robust_csv(&[p.clone(), robust]);
        assert_eq!(
            lines.lines().collect::<Vec<_>>(),
            [
                ROBUST_CSV_COLUMNS.join(",").as_str(),
                "conservative,offset 1/16,2.5,3,10,1,3,0.25,5,2,0"
            ]
        );
        let csv = to_csv(&[p.clone(), p]);
        let lines: Vec<_> = csv.lines().collect();
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0].split(',').count(), CSV_COLUMNS.len());
        assert!(lines[1].starts_with("strategy-layout,\"a,b\",false,1,0.5,0.5,false,10,"));
        assert!(lines[1].contains(",2,,,2,0,0,0,0"), "{}", lines[1]);
    }
}
