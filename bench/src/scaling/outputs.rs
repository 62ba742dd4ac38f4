//! The scaling run's outputs: CSV, JSON with the growth exponents, and SVG plots.

use std::path::Path;

use serde_json::json;

use super::{
    growth, growth_exponent, ScalingRow, AXIS_FRAMES, AXIS_FRAMES_SEGMENTED, AXIS_SYNTHETIC,
    AXIS_TRIANGLES,
};
use crate::plot::{write_svg, Chart, Series, Style};
use crate::BenchError;

/// The CSV columns, in [`ScalingRow`]'s field order.
const CSV_HEADER: &str = "axis,triangles,frames,unique_visible,record_seconds,\
record_seconds_per_frame,merge_seconds,index_triangles,index_per_unique_visible,\
draws_per_frame_mean,draws_per_frame_max,peak_rss_mib,layers_mean,record_cpu_seconds,\
merge_cpu_seconds";

/// A number for the CSV: empty when not finite.
fn csv_number(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        String::new()
    }
}

/// The rows as CSV (header first; `index_per_unique_visible` added after `index_triangles`).
pub fn to_csv(rows: &[ScalingRow]) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for r in rows {
        let fields = [
            r.axis.clone(),
            r.triangles.to_string(),
            r.frames.to_string(),
            r.unique_visible.to_string(),
            csv_number(r.record_seconds),
            csv_number(r.record_seconds_per_frame),
            csv_number(r.merge_seconds),
            r.index_triangles.to_string(),
            csv_number(r.index_ratio()),
            csv_number(r.draws_per_frame_mean),
            r.draws_per_frame_max.to_string(),
            r.peak_rss_mib.map_or(String::new(), csv_number),
            csv_number(r.layers_mean),
            r.record_cpu_seconds.map_or(String::new(), csv_number),
            r.merge_cpu_seconds.map_or(String::new(), csv_number),
        ];
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// Writes `bytes` to `path` atomically.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), BenchError> {
    trisort_format::container::write_bytes_atomic(path, bytes).map_err(|e| match e {
        trisort_format::FormatError::Io { path, source } => BenchError::Io { path, source },
        other => BenchError::Invalid(other.to_string()),
    })
}

/// The points `(x, y)` of `rows` on `axis` with positive, finite coordinates (log axes).
fn points(
    rows: &[ScalingRow],
    axis: &str,
    x: impl Fn(&ScalingRow) -> f64,
    y: impl Fn(&ScalingRow) -> f64,
) -> Vec<(f64, f64)> {
    rows.iter()
        .filter(|r| r.axis == axis)
        .map(|r| (x(r), y(r)))
        .filter(|(a, b)| a.is_finite() && b.is_finite() && *a > 0.0 && *b > 0.0)
        .collect()
}

/// Writes `scaling-NAME.csv`, `scaling-NAME.json` (the rows and the growth exponents of
/// [`growth`]) and the plots, each atomically: `scaling-NAME-triangles.svg` (record and merge
/// seconds against triangles, log-log), `scaling-NAME-frames.svg` (record seconds per frame
/// and merge seconds against frames, log-log) and `scaling-NAME-index.svg` (index/|G|
/// against frames), each only when `rows` hold its axis. Creates `out_dir` if needed.
pub fn write_outputs(rows: &[ScalingRow], out_dir: &Path, name: &str) -> Result<(), BenchError> {
    std::fs::create_dir_all(out_dir).map_err(|source| BenchError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let file = |suffix: &str| out_dir.join(format!("scaling-{name}{suffix}"));
    write_atomic(&file(".csv"), to_csv(rows).as_bytes())?;
    let json = json!({
        "name": name,
        "rows": rows,
        "growth": growth(rows),
    });
    let text = serde_json::to_string_pretty(&json)
        .map_err(|e| BenchError::Invalid(format!("JSON: {e}")))?;
    write_atomic(&file(".json"), text.as_bytes())?;

    let has = |axis: &str| rows.iter().any(|r| r.axis == axis);
    if has(AXIS_TRIANGLES) {
        let c = log_x_chart(
            rows,
            [
                "Bake cost against scene triangles",
                "scene triangles",
                "seconds",
            ],
            (|r| r.triangles as f64, true),
            &[
                ("record", AXIS_TRIANGLES, |r| r.record_seconds),
                ("record (CPU time)", AXIS_TRIANGLES, |r| {
                    r.record_cpu_seconds.unwrap_or(f64::NAN)
                }),
                ("merge", AXIS_TRIANGLES, |r| r.merge_seconds),
            ],
        );
        write_svg(&file("-triangles.svg"), &c, Style::Lines)?;
    }
    if has(AXIS_FRAMES) || has(AXIS_FRAMES_SEGMENTED) || has(AXIS_SYNTHETIC) {
        let frames = |r: &ScalingRow| f64::from(r.frames);
        let c = log_x_chart(
            rows,
            ["Bake cost against frames", "frames", "seconds"],
            (frames, true),
            &[
                ("record s/frame", AXIS_FRAMES, |r| {
                    r.record_seconds_per_frame
                }),
                ("merge s (one matrix)", AXIS_FRAMES, |r| r.merge_seconds),
                ("merge s (segments)", AXIS_FRAMES_SEGMENTED, |r| {
                    r.merge_seconds
                }),
                ("merge s (synthetic, segments)", AXIS_SYNTHETIC, |r| {
                    r.merge_seconds
                }),
            ],
        );
        write_svg(&file("-frames.svg"), &c, Style::Lines)?;
        let c = log_x_chart(
            rows,
            [
                "Copies per triangle of G against frames",
                "frames",
                "index triangles / |G|",
            ],
            (frames, false),
            &[
                ("demo car, one matrix", AXIS_FRAMES, ScalingRow::index_ratio),
                (
                    "demo car, segments",
                    AXIS_FRAMES_SEGMENTED,
                    ScalingRow::index_ratio,
                ),
                (
                    "synthetic, segments",
                    AXIS_SYNTHETIC,
                    ScalingRow::index_ratio,
                ),
            ],
        );
        write_svg(&file("-index.svg"), &c, Style::Lines)?;
    }
    Ok(())
}

/// One plotted line of a scaling chart: its label, the axis whose rows it shows, and y.
type Line = (&'static str, &'static str, fn(&ScalingRow) -> f64);

/// A chart of `rows` with a logarithmic x axis: `[title, x label, y label]`, x and whether y
/// is logarithmic, and one series per line that has points, named with its log-log slope.
fn log_x_chart(
    rows: &[ScalingRow],
    [title, x_label, y_label]: [&str; 3],
    (x, log_y): (fn(&ScalingRow) -> f64, bool),
    lines: &[Line],
) -> Chart {
    Chart {
        title: title.into(),
        x_label: x_label.into(),
        y_label: y_label.into(),
        log_x: true,
        log_y,
        series: lines
            .iter()
            .map(|&(label, axis, y)| {
                let pts = points(rows, axis, x, y);
                let slope = growth_exponent(&pts)
                    .map_or(String::new(), |e| format!(" (log-log slope {e:.2})"));
                Series {
                    name: format!("{label}{slope}"),
                    points: pts,
                }
            })
            .filter(|s| !s.points.is_empty())
            .collect(),
    }
}
