//! `trisort verify`'s reports: the JSON scripts read (keys listed in README's CLI contract)
//! and the text a person reads, from the graph rules' report and the images' report.

use std::fmt::Write as _;
use std::path::Path;

use serde_json::{json, Value};
use trisort_verify::GraphReport;

use crate::frames::ImageReport;
use crate::ImageCheck;

/// `verify --json`: `ok`, the frames (each with its graph figures beside its image figures),
/// the graph rules' findings and the image check's settings.
pub fn json_report(
    ok: bool,
    graph: Option<&GraphReport>,
    images: Option<&(ImageReport, ImageCheck)>,
) -> Value {
    let graph_frame = |f: u32| graph.and_then(|g| g.frames.iter().find(|r| r.frame == f));
    let frames: Vec<Value> = match images {
        Some((report, _)) => report
            .frames
            .iter()
            .map(|fr| {
                let mut v = serde_json::to_value(fr).expect("report serializes");
                if let Some(g) = graph_frame(fr.frame) {
                    v["graph_violations"] = json!(g.graph_violations);
                    v["graph"] = serde_json::to_value(g).expect("report serializes");
                }
                v
            })
            .collect(),
        None => graph
            .map(|g| {
                g.frames
                    .iter()
                    .map(|f| serde_json::to_value(f).expect("report serializes"))
                    .collect()
            })
            .unwrap_or_default(),
    };
    let mut out = json!({ "ok": ok, "frames": frames });
    if let Some(g) = graph {
        out["graph_ok"] = json!(g.ok);
        out["problems"] = json!(g.problems);
        out["bad_copies"] = json!(g.bad_copies);
        out["depth_only"] = json!(g.depth_only);
        out["bridge"] = json!({ "claimed": g.bridge_claimed, "derived": g.bridge_derived });
    }
    if let Some((report, check)) = images {
        out["images_ok"] = json!(report.ok);
        out["mode"] = json!(check.mode.name());
        out["shading"] = json!(check.shading.name());
        out["tonemap"] = json!(check.tone_map.name());
        out["size"] = json!([check.size.0, check.size.1]);
        out["samples"] = json!(check.samples);
        out["at_recorded_pattern"] = json!(report.at_recorded_pattern);
        out["played_on_recording_device"] = json!(!report.on_other_device);
        out["max_error"] = json!(check.max_error);
        out["captured"] = json!(check.captured);
        out["subpixel_offset"] = json!(check.subpixel_offset);
        out["unordered_from_recording"] = json!(graph.is_some());
    }
    out
}

/// `verify`'s text report: the graph rules' verdict and findings, then a line per checked
/// frame of the images (`baked` names the file; `measure_only`: nothing was verified).
pub fn text_report(
    baked: &Path,
    graph: Option<&GraphReport>,
    images: Option<&(ImageReport, ImageCheck)>,
    measure_only: bool,
) -> String {
    let mut out = String::new();
    if let Some(report) = graph {
        let bad: Vec<_> = report.frames.iter().filter(|f| !f.ok()).collect();
        let _ = writeln!(
            out,
            "graph rules: {} ({} frames checked, {} with problems, {} unordered samples)",
            if report.ok { "OK" } else { "FAILED" },
            report.frames.len(),
            bad.len(),
            report
                .frames
                .iter()
                .map(|f| f.unordered_samples)
                .sum::<u64>()
        );
        let _ = writeln!(
            out,
            "  order checked against: {}",
            match (report.checked, report.depth_only) {
                ("depth", _) => "the edges depth mode needs (a depth-only file, checked for --mode depth: ties, and edges behind translucent fragments)",
                (_, true) => "every edge of E_f (a depth-only file checked for blend: it plays right only in depth mode; --mode depth checks it for that)",
                _ => "every edge of E_f",
            }
        );
        let _ = writeln!(
            out,
            "  bridge: the file claims {}, its draws need {}",
            report.bridge_claimed, report.bridge_derived
        );
        for p in &report.problems {
            let _ = writeln!(out, "  {p}");
        }
        for f in bad.iter().take(20) {
            let _ = writeln!(out, "  frame {}: {:?}", f.frame, f);
        }
    }
    if let Some((report, check)) = images {
        let bad = report.frames.iter().filter(|f| !f.ok).count();
        let _ = writeln!(
            out,
            "{} of {} ({} mode, {}x{}, {}x MSAA, {}): {} ({} frames checked, {} failing)",
            if check.captured {
                "captured frames"
            } else {
                "images"
            },
            baked.display(),
            check.mode,
            check.size.0,
            check.size.1,
            check.samples,
            if measure_only {
                "measured only: NOTHING VERIFIED, no frame can fail".to_string()
            } else if report.at_recorded_pattern && report.on_other_device {
                "recorded pattern, played on another device than recorded: checked all the same"
                    .to_string()
            } else if report.at_recorded_pattern {
                "recorded pattern".to_string()
            } else {
                format!(
                    "off the recorded pattern, max error {}/255",
                    check.max_error.unwrap_or(0)
                )
            },
            if measure_only {
                "measured"
            } else if report.ok {
                "OK"
            } else {
                "FAILED"
            },
            report.frames.len(),
            if measure_only { 0 } else { bad }
        );
        let _ = writeln!(
            out,
            "  holes: differing pixels where the reference's nearest fragment is of a triangle the file does not draw; order: other differing ordered pixels"
        );
        let _ = writeln!(
            out,
            "  unordered (excused) pixels: {}",
            if graph.is_some() {
                "those with a sample on a cycle of the recording's E_f"
            } else {
                "none (no --recording)"
            }
        );
        let _ = writeln!(
            out,
            "  frame  ok  differing  ordered  max  max_ord  psnr   flip     unordered  holes  order  srgb8_max"
        );
        for f in &report.frames {
            let c = &f.comparison;
            let _ = writeln!(
                out,
                "  {:5}  {:3} {:9}  {:7}  {:3}  {:7}  {:5.1}  {:.5}  {:9}  {:5}  {:5}  {}",
                f.frame,
                match (measure_only, f.ok) {
                    (true, _) => "-",
                    (false, true) => "yes",
                    (false, false) => "NO",
                },
                c.pixels_differing,
                c.pixels_differing_ordered,
                c.max_channel_diff,
                c.max_channel_diff_ordered,
                c.psnr,
                c.flip_mean,
                f.unordered_samples,
                f.hole_pixels,
                f.order_error_pixels,
                f.srgb8
                    .map(|s| s.max_channel_diff.to_string())
                    .unwrap_or_else(|| "-".into())
            );
        }
    }
    out
}

/// `verify --junit FILE`: JUnit XML for CI systems. One test suite named after the baked file;
/// a test case per checked frame (`frame N`: failed when its graph rules or its image check
/// failed, the failure saying which figures; skipped when the images were only measured, with
/// no graph rule to judge), and a test case `graph rules (whole file)` for the file-wide
/// findings (copies, structure, hashes). Each case's `system-out` holds its figures as JSON.
/// A frame's case names its clip (of `clips`) in its class name, `trisort.verify.STEM.CLIP`.
pub fn junit_report(
    baked: &Path,
    clips: &[trisort_format::Clip],
    graph: Option<&GraphReport>,
    images: Option<&(ImageReport, ImageCheck)>,
    measure_only: bool,
) -> String {
    let name = baked.display().to_string();
    let class = format!(
        "trisort.verify.{}",
        baked
            .file_stem()
            .map_or_else(|| "baked".into(), |s| s.to_string_lossy())
    );
    let mut cases: Vec<JunitCase> = Vec::new();
    let mut frames: Vec<u32> = graph.map_or_else(Vec::new, |g| {
        g.frames.iter().map(|f| f.frame).collect::<Vec<_>>()
    });
    if let Some((report, _)) = images {
        frames.extend(report.frames.iter().map(|f| f.frame));
    }
    frames.sort_unstable();
    frames.dedup();
    for frame in frames {
        let g = graph.and_then(|g| g.frames.iter().find(|f| f.frame == frame));
        let i = images.and_then(|(r, _)| r.frames.iter().find(|f| f.frame == frame));
        let mut failures = Vec::new();
        if let Some(g) = g.filter(|g| !g.ok()) {
            failures.push(format!(
                "graph rules: {} order violations, {} visible triangles not drawn, {} drawn \
                 twice, {} bridge violations{}",
                g.graph_violations,
                g.visible_missing,
                g.drawn_twice,
                g.bridge_violations,
                if g.truncated { ", peel truncated" } else { "" }
            ));
        }
        if let Some(i) = i.filter(|i| !i.ok && !measure_only) {
            failures.push(format!(
                "images: {} ordered pixels more than 1/255 off (largest {}/255), {} with a hole \
                 sample, {} in the wrong order; {} unordered samples",
                i.comparison.pixels_over_tolerance_ordered,
                i.comparison.max_channel_diff_ordered,
                i.hole_pixels,
                i.order_error_pixels,
                i.unordered_samples
            ));
        }
        let figures = json!({ "graph": g, "images": i });
        let clip = clips.iter().find(|c| c.frames().contains(&frame));
        cases.push(JunitCase {
            class: clip.map_or_else(|| class.clone(), |c| format!("{class}.{}", c.name)),
            name: format!("frame {frame}"),
            failure: (!failures.is_empty()).then(|| failures.join("; ")),
            skipped: failures.is_empty() && measure_only && i.is_some() && g.is_none(),
            out: figures.to_string(),
        });
    }
    if let Some(g) = graph {
        let frame_failed = g.frames.iter().any(|f| !f.ok());
        let whole_file = (!g.ok && !frame_failed) || g.bad_copies > 0;
        cases.push(JunitCase {
            class: class.clone(),
            name: "graph rules (whole file)".into(),
            failure: whole_file.then(|| {
                format!(
                    "{} copies drawn in no frame, in frames apart or where hidden; {}",
                    g.bad_copies,
                    g.problems.join("; ")
                )
            }),
            skipped: false,
            out: json!({ "problems": g.problems, "bad_copies": g.bad_copies }).to_string(),
        });
    }
    let failures = cases.iter().filter(|c| c.failure.is_some()).count();
    let skipped = cases.iter().filter(|c| c.skipped).count();
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let counts = format!(
        "tests=\"{}\" failures=\"{failures}\" errors=\"0\" skipped=\"{skipped}\"",
        cases.len()
    );
    let _ = writeln!(out, "<testsuites name=\"trisort verify\" {counts}>");
    let _ = writeln!(out, "  <testsuite name=\"{}\" {counts}>", xml(&name));
    for c in &cases {
        let _ = writeln!(
            out,
            "    <testcase classname=\"{}\" name=\"{}\">",
            xml(&c.class),
            xml(&c.name)
        );
        if let Some(f) = &c.failure {
            let _ = writeln!(
                out,
                "      <failure message=\"{}\" type=\"verify\">{}</failure>",
                xml(f),
                xml(f)
            );
        }
        if c.skipped {
            let _ = writeln!(
                out,
                "      <skipped message=\"images measured only (--measure-only)\"/>"
            );
        }
        let _ = writeln!(out, "      <system-out>{}</system-out>", xml(&c.out));
        let _ = writeln!(out, "    </testcase>");
    }
    out.push_str("  </testsuite>\n</testsuites>\n");
    out
}

/// One test case of [`junit_report`].
struct JunitCase {
    class: String,
    name: String,
    failure: Option<String>,
    skipped: bool,
    out: String,
}

/// `s` escaped for XML text and attribute values.
fn xml(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // Control characters are not allowed in XML 1.0.
            c if (c as u32) < 0x20 && !matches!(c, '\n' | '\t' | '\r') => out.push(' '),
            c => out.push(c),
        }
    }
    out
}
