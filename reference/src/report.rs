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
