//! SVG charts of benchmark figures (plotters' SVG backend).
//!
//! Text is written as SVG `<text>` elements and laid out with plotters' built-in crude
//! estimate of text width (no `ttf`/`ab_glyph`, so no font files and no system font
//! libraries); the viewer picks the actual `sans-serif` font. The legend sits in a column
//! of its own to the right of the plot, so it never hides data.
//!
//! Robust to degenerate input: empty series, non-finite points (skipped), a single point or
//! all-equal values (the range is padded), and zero or negative values on a log axis
//! (skipped, and the number of points left out is written under the chart). A log axis whose
//! positive values span less than a factor of 10 is drawn linear: plotters labels only powers
//! of ten, which would leave it with one label or none.

use std::ops::Range;
use std::path::Path;

use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::BenchError;

/// One named series of (x, y) points.
#[derive(Debug, Clone, Default)]
pub struct Series {
    /// Legend entry; an empty name gets no legend entry.
    pub name: String,
    /// The points, drawn in this order. Non-finite points are skipped.
    pub points: Vec<(f64, f64)>,
}

/// A chart: title, axis labels and scales, series.
#[derive(Debug, Clone, Default)]
pub struct Chart {
    /// Caption above the chart.
    pub title: String,
    /// Label of the horizontal axis.
    pub x_label: String,
    /// Label of the vertical axis.
    pub y_label: String,
    /// Logarithmic horizontal axis (points with x ≤ 0 are left out). Drawn linear, with every
    /// point, where the positive values span less than a factor of 10.
    pub log_x: bool,
    /// Logarithmic vertical axis (points with y ≤ 0 are left out); linear as for `log_x`.
    pub log_y: bool,
    /// The series, one colour and marker shape each.
    pub series: Vec<Series>,
}

/// How series are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Lines through the points, with a marker at every point.
    Lines,
    /// Markers only (scatter).
    Points,
}

/// Width and height of the SVG in pixels.
const SIZE: (u32, u32) = (960, 600);

/// Colours (Tableau 10), picked by series index.
const COLOURS: [(u8, u8, u8); 10] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];

/// Number of distinct marker shapes; with 10 colours, 40 series are distinguishable.
const SHAPES: usize = 4;

fn colour(index: usize) -> RGBColor {
    let (r, g, b) = COLOURS[index % COLOURS.len()];
    RGBColor(r, g, b)
}

fn shape(index: usize) -> usize {
    (index / COLOURS.len()) % SHAPES
}

/// Writes `chart` as an SVG file atomically (temp file + rename); errors name the file.
pub fn write_svg(path: &Path, chart: &Chart, style: Style) -> Result<(), BenchError> {
    write_svg_labelled(path, chart, style, &[])
}

/// [`write_svg`] with a short text label beside points: `labels[s][k]` labels point `k` of
/// series `s` (missing or empty strings: no label).
pub fn write_svg_labelled(
    path: &Path,
    chart: &Chart,
    style: Style,
    labels: &[Vec<String>],
) -> Result<(), BenchError> {
    let svg = render_svg(chart, style, labels)
        .map_err(|e| BenchError::Invalid(format!("{}: plotting failed: {e}", path.display())))?;
    write_atomic(path, svg.as_bytes())
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename,
/// so that a reader never sees a partial file.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), BenchError> {
    let io = |source| BenchError::Io {
        path: path.to_path_buf(),
        source,
    };
    let name = path
        .file_name()
        .ok_or_else(|| BenchError::Invalid(format!("{}: not a file name", path.display())))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp{}", std::process::id()));
    let tmp = path.with_file_name(tmp_name);
    if let Err(e) = std::fs::write(&tmp, bytes) {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(e));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })
}

/// The points of one series that can be drawn on the chart's axes.
fn drawable<'l>(
    points: &[(f64, f64)],
    labels: Option<&'l Vec<String>>,
    log_x: bool,
    log_y: bool,
) -> (Vec<(f64, f64)>, Vec<&'l str>, usize) {
    let mut left_out_log = 0;
    let (kept, kept_labels) = points
        .iter()
        .copied()
        .enumerate()
        .filter(|&(_, (x, y))| {
            if !x.is_finite() || !y.is_finite() {
                return false;
            }
            if (log_x && x <= 0.0) || (log_y && y <= 0.0) {
                left_out_log += 1;
                return false;
            }
            true
        })
        .map(|(k, p)| {
            let label = labels.and_then(|l| l.get(k)).map_or("", |l| l.as_str());
            (p, label)
        })
        .unzip();
    (kept, kept_labels, left_out_log)
}

/// A padded linear range covering `values` (finite).
fn linear_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if lo > hi {
        return 0.0..1.0;
    }
    let span = hi - lo;
    let scale = lo.abs().max(hi.abs());
    if span <= scale * 1e-9 || !span.is_finite() {
        let pad = if scale > 0.0 { scale * 0.1 } else { 1.0 };
        return (lo - pad)..(hi + pad);
    }
    let pad = span * 0.05;
    let (lo2, hi2) = (lo - pad, hi + pad);
    // Keep a non-negative quantity's axis from starting just below zero.
    let lo2 = if lo >= 0.0 && lo2 < 0.0 { 0.0 } else { lo2 };
    if lo2.is_finite() && hi2.is_finite() {
        lo2..hi2
    } else {
        lo..hi
    }
}

/// A log range covering `values` (finite, positive), widened to whole decades so that
/// plotters always finds tick marks.
fn log_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if lo > hi {
        return 1.0..10.0;
    }
    let lo_exp = lo.log10().floor().clamp(-300.0, 299.0);
    let mut hi_exp = hi.log10().ceil().clamp(-299.0, 300.0);
    if hi_exp <= lo_exp {
        hi_exp = lo_exp + 1.0;
    }
    // A hair below the lower decade, so that rounding in plotters' tick search keeps it.
    10f64.powf(lo_exp) * (1.0 - 1e-9)..10f64.powf(hi_exp)
}

/// Whether a log axis is worth drawing: the positive finite values span at least a factor of
/// 10. Below that plotters' log axis labels at most one tick (it labels powers of ten only),
/// so the axis is drawn linear.
fn spans_a_decade(values: impl Iterator<Item = f64>) -> bool {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    lo <= hi && hi / lo >= 10.0
}

/// A short tick label: at most 4 significant digits, exponent form for very large or small.
pub fn format_number(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if !(1e-3..1e6).contains(&a) {
        let s = format!("{v:.2e}");
        // 1.00e6 -> 1e6, 2.50e-4 -> 2.5e-4
        if let Some((m, e)) = s.split_once('e') {
            let m = m.trim_end_matches('0').trim_end_matches('.');
            return format!("{m}e{e}");
        }
        return s;
    }
    let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Renders the chart to an SVG string.
fn render_svg(chart: &Chart, style: Style, labels: &[Vec<String>]) -> Result<String, String> {
    let all = || chart.series.iter().flat_map(|s| s.points.iter().copied());
    let log_x = chart.log_x && spans_a_decade(all().map(|p| p.0));
    let log_y = chart.log_y && spans_a_decade(all().map(|p| p.1));
    let mut left_out = 0;
    let series: Vec<Series3<'_>> = chart
        .series
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let (pts, point_labels, n) = drawable(&s.points, labels.get(i), log_x, log_y);
            left_out += n;
            (i, s.name.as_str(), pts, point_labels)
        })
        .collect();
    let xs = || series.iter().flat_map(|s| s.2.iter().map(|p| p.0));
    let ys = || series.iter().flat_map(|s| s.2.iter().map(|p| p.1));
    let note = (left_out > 0).then(|| {
        format!(
            "{left_out} point{} with a value ≤ 0 not shown on the log axis",
            if left_out == 1 { "" } else { "s" }
        )
    });

    let x_lin = linear_range(xs());
    let y_lin = linear_range(ys());
    let x_log = log_range(xs());
    let y_log = log_range(ys());
    let mut svg = String::new();
    match (log_x, log_y) {
        (false, false) => draw(&mut svg, chart, style, &series, note, x_lin, y_lin)?,
        (true, false) => draw(
            &mut svg,
            chart,
            style,
            &series,
            note,
            x_log.log_scale(),
            y_lin,
        )?,
        (false, true) => draw(
            &mut svg,
            chart,
            style,
            &series,
            note,
            x_lin,
            y_log.log_scale(),
        )?,
        (true, true) => draw(
            &mut svg,
            chart,
            style,
            &series,
            note,
            x_log.log_scale(),
            y_log.log_scale(),
        )?,
    }
    Ok(svg)
}

/// A series ready to draw: index (colour, shape), name, drawable points, their labels.
type Series3<'s> = (usize, &'s str, Vec<(f64, f64)>, Vec<&'s str>);

fn draw<X, Y>(
    svg: &mut String,
    chart: &Chart,
    style: Style,
    series: &[Series3<'_>],
    note: Option<String>,
    x: X,
    y: Y,
) -> Result<(), String>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let e = |e: &dyn std::fmt::Display| e.to_string();
    let root = SVGBackend::with_string(svg, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    // Own text is anchored at its baseline (VPos::Bottom), so that it stays inside the
    // image also in renderers that ignore SVG's `dy` (ImageMagick's built-in one does).
    let (header, root) = root.split_vertically(40);
    header
        .draw_text(
            &chart.title,
            &("sans-serif", 22)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Bottom)),
            (SIZE.0 as i32 / 2, 30),
        )
        .map_err(|x| e(&x))?;
    let (root, footer) = match &note {
        Some(_) => root.split_vertically(root.dim_in_pixel().1 as i32 - 24),
        None => root.split_vertically(root.dim_in_pixel().1 as i32),
    };
    if let Some(note) = &note {
        footer
            .draw_text(
                note,
                &("sans-serif", 14)
                    .into_font()
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Left, VPos::Bottom)),
                (90, 18),
            )
            .map_err(|x| e(&x))?;
    }
    let names: Vec<&Series3<'_>> = series.iter().filter(|s| !s.1.is_empty()).collect();
    // Legend column: wide enough for the longest name at 14 px (≈ 7.5 px a character).
    let legend_w = if names.is_empty() {
        0
    } else {
        let longest = names.iter().map(|s| s.1.chars().count()).max().unwrap_or(0);
        (40 + longest as i32 * 15 / 2).clamp(100, 320)
    };
    let (plot_area, legend) = root.split_horizontally(root.dim_in_pixel().0 as i32 - legend_w);

    let mut ctx = ChartBuilder::on(&plot_area)
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(78)
        .build_cartesian_2d(x, y)
        .map_err(|x| e(&x))?;
    ctx.configure_mesh()
        .x_desc(chart.x_label.as_str())
        .y_desc(chart.y_label.as_str())
        .x_label_formatter(&|v| format_number(*v))
        .y_label_formatter(&|v| format_number(*v))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(200, 200, 200))
        .draw()
        .map_err(|x| e(&x))?;

    for (i, _, pts, _) in series {
        let c = colour(*i);
        if style == Style::Lines && pts.len() > 1 {
            // Segment by segment: some SVG renderers (ImageMagick's built-in one) fill a
            // polyline of more than two points despite `fill="none"`.
            ctx.draw_series(
                pts.windows(2)
                    .map(|w| PathElement::new(vec![w[0], w[1]], c.stroke_width(2))),
            )
            .map_err(|x| e(&x))?;
        }
        draw_markers(&mut ctx, *i, pts).map_err(|x| e(&x))?;
    }
    // Point labels after every series.
    let shown = shown_labels(series, |p| ctx.backend_coord(p));
    for ((i, ..), shown) in series.iter().zip(shown) {
        let font = ("sans-serif", 12)
            .into_font()
            .color(&colour(*i))
            .pos(Pos::new(HPos::Left, VPos::Bottom));
        ctx.draw_series(
            shown.into_iter().map(|(p, l)| {
                EmptyElement::at(p) + Text::new(l.to_string(), (6, -4), font.clone())
            }),
        )
        .map_err(|x| e(&x))?;
    }

    // Legend: one row per named series.
    for (row, (i, name)) in names.iter().map(|s| (s.0, s.1)).enumerate() {
        let y = 40 + row as i32 * 22;
        let c = colour(i);
        if style == Style::Lines {
            legend
                .draw(&PathElement::new(vec![(4, y), (28, y)], c.stroke_width(2)))
                .map_err(|x| e(&x))?;
        }
        legend_marker(&legend, i, (16, y)).map_err(|x| e(&x))?;
        legend
            .draw_text(
                name,
                &("sans-serif", 14)
                    .into_font()
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Left, VPos::Center)),
                (36, y),
            )
            .map_err(|x| e(&x))?;
    }
    root.present().map_err(|x| e(&x))?;
    Ok(())
}

/// The point labels to draw, per series: a label is shown where its box (at (6, −4) from
/// its point, ≈ 7 px a character, 12 px high; `at` gives a point's pixel) overlaps no label
/// shown before it, so points that coincide show the first label of the cluster only.
fn shown_labels<'s>(
    series: &[Series3<'s>],
    at: impl Fn(&(f64, f64)) -> (i32, i32),
) -> Vec<Vec<((f64, f64), &'s str)>> {
    let mut taken: Vec<(i32, i32, i32, i32)> = Vec::new();
    series
        .iter()
        .map(|(_, _, pts, point_labels)| {
            let mut shown = Vec::new();
            for (&p, &l) in pts.iter().zip(point_labels) {
                if l.is_empty() {
                    continue;
                }
                let (px, py) = at(&p);
                let b = (
                    px + 5,
                    py - 17,
                    px + 7 + 7 * l.chars().count() as i32,
                    py - 3,
                );
                if taken
                    .iter()
                    .any(|t| b.0 < t.2 && t.0 < b.2 && b.1 < t.3 && t.1 < b.3)
                {
                    continue;
                }
                taken.push(b);
                shown.push((p, l));
            }
            shown
        })
        .collect()
}

fn marker_style(index: usize) -> ShapeStyle {
    let c = colour(index);
    match shape(index) {
        0 => c.filled(),
        1 => c.stroke_width(2),
        2 => c.filled(),
        _ => c.stroke_width(2),
    }
}

/// Markers at data points: filled circle, open circle, filled triangle, cross.
fn draw_markers<DB, X, Y>(
    ctx: &mut ChartContext<'_, DB, plotters::coord::cartesian::Cartesian2d<X, Y>>,
    index: usize,
    pts: &[(f64, f64)],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let st = marker_style(index);
    match shape(index) {
        0 | 1 => {
            ctx.draw_series(pts.iter().map(|&p| Circle::new(p, 4, st)))?;
        }
        2 => {
            ctx.draw_series(pts.iter().map(|&p| TriangleMarker::new(p, 5, st)))?;
        }
        _ => {
            ctx.draw_series(pts.iter().map(|&p| Cross::new(p, 4, st)))?;
        }
    }
    Ok(())
}

fn legend_marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    index: usize,
    at: (i32, i32),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let st = marker_style(index);
    match shape(index) {
        0 | 1 => area.draw(&Circle::new(at, 4, st)),
        2 => area.draw(&TriangleMarker::new(at, 5, st)),
        _ => area.draw(&Cross::new(at, 4, st)),
    }
}

#[cfg(test)]
mod tests;
