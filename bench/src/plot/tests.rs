//! The plots' ranges, labels and SVG output.
use super::*;

fn chart(series: Vec<Series>, log_x: bool, log_y: bool) -> Chart {
    Chart {
        title: "Error vs bake time".into(),
        x_label: "bake seconds".into(),
        y_label: "pixels differing".into(),
        log_x,
        log_y,
        series,
    }
}

fn series(name: &str, points: &[(f64, f64)]) -> Series {
    Series {
        name: name.into(),
        points: points.to_vec(),
    }
}

fn write(c: &Chart, style: Style) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("chart.svg");
    write_svg(&path, c, style).unwrap();
    // No temporary file is left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..svg.len().min(200)]);
    assert!(svg.trim_end().ends_with("</svg>"));
    assert_balanced(&svg);
    svg
}

/// Every opened tag is closed, in order (the backend writes no comments or CDATA).
fn assert_balanced(svg: &str) {
    let mut stack = Vec::new();
    let mut rest = svg;
    while let Some(start) = rest.find('<') {
        let end = rest[start..].find('>').expect("unterminated tag") + start;
        let tag = &rest[start + 1..end];
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(
                stack.pop(),
                Some(name.trim().to_string()),
                "mismatched </{name}>"
            );
        } else if !tag.ends_with('/') && !tag.starts_with('?') {
            let name = tag.split_whitespace().next().unwrap().to_string();
            stack.push(name);
        }
        rest = &rest[end + 1..];
    }
    assert!(stack.is_empty(), "unclosed tags {stack:?}");
}

#[test]
fn lines_with_title_axes_and_legend() {
    let c = chart(
        vec![
            series("record size", &[(1.0, 10.0), (2.0, 4.0), (4.0, 1.0)]),
            series("samples & <more>", &[(0.5, 3.0), (1.5, 2.0)]),
        ],
        false,
        false,
    );
    let svg = write(&c, Style::Lines);
    for text in ["Error vs bake time", "bake seconds", "pixels differing"] {
        assert!(svg.contains(text), "missing {text}");
    }
    assert!(svg.contains("record size"));
    assert!(svg.contains("samples &amp; &lt;more&gt;"));
    assert!(svg.contains("<polyline") || svg.contains("<path"));
    assert!(svg.contains("<circle"));
}

#[test]
fn degenerate_inputs_do_not_panic() {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let cases = vec![
        vec![],
        vec![series("empty", &[])],
        vec![series("one", &[(3.0, 7.0)])],
        vec![series("equal", &[(2.0, 2.0), (2.0, 2.0), (2.0, 2.0)])],
        vec![series("zeros", &[(0.0, 0.0), (0.0, 0.0)])],
        vec![series("non-finite", &[(nan, 1.0), (1.0, inf), (-inf, nan)])],
        vec![series(
            "mixed",
            &[(nan, 1.0), (1.0, 2.0), (2.0, inf), (3.0, 1.0)],
        )],
        vec![series("huge", &[(1e300, -1e300), (-1e300, 1e300)])],
        vec![series("tiny", &[(1e-300, 5e-324), (2e-300, 1e-320)])],
        vec![series("", &[(1.0, 1.0), (2.0, 3.0)])],
    ];
    for s in cases {
        for (lx, ly) in [(false, false), (true, false), (false, true), (true, true)] {
            for style in [Style::Lines, Style::Points] {
                let c = chart(s.clone(), lx, ly);
                let svg = write(&c, style);
                assert!(svg.contains("Error vs bake time"));
                for s in &c.series {
                    assert!(svg.contains(&s.name));
                }
            }
        }
    }
}

#[test]
fn log_axes_leave_out_non_positive_values_and_say_so() {
    let c = chart(
        vec![series(
            "error",
            &[
                (0.0, 5.0),
                (1.0, 0.0),
                (2.0, -1.0),
                (10.0, 100.0),
                (100.0, 1000.0),
            ],
        )],
        true,
        true,
    );
    let svg = write(&c, Style::Points);
    assert!(svg.contains("3 points with a value ≤ 0 not shown"), "{svg}");
    // Decade ticks are labelled.
    assert!(svg.contains(">\n100\n<") || svg.contains(">100<") || svg.contains("100\n"));
    // Only the two positive points are drawn (plus the legend marker).
    assert_eq!(svg.matches("<circle").count(), 3);
    // A linear chart of the same data shows every point and has no note.
    let lin = write(&chart(c.series.clone(), false, false), Style::Points);
    assert!(!lin.contains("not shown"));
    assert_eq!(lin.matches("<circle").count(), 6);
}

#[test]
fn narrow_log_ranges_are_drawn_linear_and_decades_are_labelled() {
    // 0.28 … 0.37: under a decade, so linear, every point shown, several labels.
    let narrow = chart(
        vec![series("size", &[(0.28, 1.0), (0.37, 2.0), (0.0, 3.0)])],
        true,
        false,
    );
    let svg = write(&narrow, Style::Points);
    assert!(!svg.contains("not shown"));
    assert_eq!(svg.matches("<circle").count(), 4);
    // 0.002 … 0.9 on a log axis: the decades 0.001, 0.01, 0.1 and 1 are all labelled.
    let wide = chart(vec![series("t", &[(0.002, 1.0), (0.9, 2.0)])], true, false);
    let svg = write(&wide, Style::Points);
    for label in ["0.001", "0.01", "0.1", "1"] {
        let text = format!(">\n{label}\n</text>");
        assert!(svg.contains(&text), "missing tick {label}");
    }
}

#[test]
fn many_series_get_distinct_styles() {
    let s: Vec<Series> = (0..25)
        .map(|i| series(&format!("s{i}"), &[(i as f64, 1.0 + i as f64)]))
        .collect();
    let svg = write(&chart(s, false, false), Style::Points);
    for i in 0..25 {
        assert!(svg.contains(&format!("s{i}")));
    }
    let styles: std::collections::HashSet<_> = (0..40).map(|i| (colour(i), shape(i))).collect();
    assert_eq!(styles.len(), 40);
}

#[test]
fn point_labels_are_drawn_beside_drawable_points() {
    let c = chart(
        vec![
            series("size", &[(1.0, 1.0), (f64::NAN, 2.0), (3.0, 0.5)]),
            series("other", &[(2.0, 2.0)]),
        ],
        false,
        false,
    );
    let labels = vec![vec!["half".to_string(), "gone".into(), "double".into()]];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("l.svg");
    write_svg_labelled(&path, &c, Style::Points, &labels).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert_balanced(&svg);
    assert!(svg.contains("half") && svg.contains("double"));
    assert!(!svg.contains("gone"), "the NaN point's label is skipped");
}

#[test]
fn errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("missing-dir").join("chart.svg");
    let err = write_svg(&path, &chart(vec![], false, false), Style::Lines).unwrap_err();
    assert!(err.to_string().contains("chart.svg"), "{err}");
}

#[test]
fn numbers_are_short() {
    assert_eq!(format_number(0.0), "0");
    assert_eq!(format_number(1.0), "1");
    assert_eq!(format_number(0.5), "0.5");
    assert_eq!(format_number(1234.5678), "1235");
    assert_eq!(format_number(0.012345), "0.01235");
    assert_eq!(format_number(2_500_000.0), "2.5e6");
    assert_eq!(format_number(0.0001), "1e-4");
    assert_eq!(format_number(-3.25), "-3.25");
}
