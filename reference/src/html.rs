//! `trisort verify --report DIR`: a self-contained HTML sign-off report (`DIR/index.html`).
//!
//! One file, inline CSS, no script, no network: the thumbnails (the player's frame, the
//! reference and a difference heat map, at most [`THUMB_WIDTH`] pixels wide) are embedded as
//! `data:image/png;base64,…`, so the single file can be attached to a ticket. Every string
//! from outside (file names, scene specs, clip names, settings) is escaped.
//!
//! Frames are listed worst first: failing frames before passing ones, then by ordered pixels
//! differing, largest ordered difference, graph violations and pixels differing (descending),
//! then by frame. Each row carries `data-frame`, `data-clip` and `data-verdict` attributes
//! and each figure a `data-key` (the `verify --json` key), so tools can read it back.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use trisort_format::Clip;
use trisort_verify::{FrameReport, GraphReport};

use crate::frames::{FramesError, ImageReport};
use crate::{FrameImageReport, ImageCheck, VerifiedFrame};

/// The widest thumbnail, in pixels (narrower frames keep their size).
pub const THUMB_WIDTH: u32 = 256;

/// A frame's thumbnails as PNG bytes: the player's (or captured) frame, the reference and
/// the difference heat map.
#[derive(Clone, Debug)]
pub struct Thumbnails {
    /// Thumbnail width in pixels.
    pub width: u32,
    /// Thumbnail height in pixels.
    pub height: u32,
    /// The player's frame (or the captured one), PNG.
    pub player: Vec<u8>,
    /// The exact reference, PNG.
    pub reference: Vec<u8>,
    /// The heat map of the largest colour-channel difference per pixel, PNG.
    pub heat: Vec<u8>,
}

/// The thumbnails of verified frame `v` (images of `size`).
pub fn thumbnails(v: &VerifiedFrame, size: (u32, u32)) -> Result<Thumbnails, FramesError> {
    let (w, h) = size;
    let (tw, th) = if w <= THUMB_WIDTH {
        (w, h)
    } else {
        (
            THUMB_WIDTH,
            ((h as u64 * THUMB_WIDTH as u64 / w as u64) as u32).max(1),
        )
    };
    let small = |rgba: &[u8]| -> Vec<u8> {
        match image::RgbaImage::from_raw(w, h, rgba.to_vec()) {
            Some(img) if (tw, th) != (w, h) => {
                image::imageops::resize(&img, tw, th, image::imageops::FilterType::Triangle)
                    .into_raw()
            }
            Some(img) => img.into_raw(),
            None => vec![0; (tw * th * 4) as usize],
        }
    };
    let heat = heat_map(
        &v.player,
        &v.reference.rgba8,
        &v.reference.unordered,
        size,
        (tw, th),
    );
    Ok(Thumbnails {
        width: tw,
        height: th,
        player: png(&small(&v.player), tw, th)?,
        reference: png(&small(&v.reference.rgba8), tw, th)?,
        heat: png(&heat, tw, th)?,
    })
}

/// PNG bytes of an RGBA8 thumbnail.
fn png(rgba8: &[u8], width: u32, height: u32) -> Result<Vec<u8>, FramesError> {
    crate::frames::encode_png(rgba8, width, height).map_err(|e| FramesError::Write {
        path: "thumbnail.png".into(),
        problem: format!("encoding: {e}"),
    })
}

/// The heat map at `thumb` size: each thumbnail pixel shows the largest colour-channel
/// difference over the frame pixels it covers (so that one differing pixel never vanishes in
/// the downscale): black where none differs, then dark blue (1/255), through red (about
/// 16/255) to yellow and white (255/255) on a logarithmic scale. A block whose largest
/// difference is on an unordered (excused) pixel only is drawn in grey.
pub fn heat_map(
    test: &[u8],
    reference: &[u8],
    unordered: &[bool],
    size: (u32, u32),
    thumb: (u32, u32),
) -> Vec<u8> {
    let (w, h) = (size.0 as usize, size.1 as usize);
    let (tw, th) = (thumb.0 as usize, thumb.1 as usize);
    let mut ordered = vec![0u8; tw * th];
    let mut excused = vec![0u8; tw * th];
    for y in 0..h {
        let ty = y * th / h.max(1);
        for x in 0..w {
            let p = y * w + x;
            let (Some(a), Some(b)) = (test.get(4 * p..4 * p + 4), reference.get(4 * p..4 * p + 4))
            else {
                continue;
            };
            let d = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
            let t = ty * tw + x * tw / w.max(1);
            if unordered.get(p).copied().unwrap_or(false) {
                excused[t] = excused[t].max(d);
            } else {
                ordered[t] = ordered[t].max(d);
            }
        }
    }
    ordered
        .iter()
        .zip(&excused)
        .flat_map(|(&d, &e)| {
            if d > 0 {
                let [r, g, b] = heat_colour(d);
                [r, g, b, 255]
            } else if e > 0 {
                [110, 110, 110, 255]
            } else {
                [0, 0, 0, 255]
            }
        })
        .collect()
}

/// The colour of a difference of `d`/255 (`d` > 0) on the heat map's scale.
fn heat_colour(d: u8) -> [u8; 3] {
    let t = (d as f32).ln() / 255f32.ln(); // 1/255 → 0, 255/255 → 1
    let stops: [(f32, [f32; 3]); 5] = [
        (0.0, [30.0, 40.0, 160.0]),
        (0.35, [150.0, 30.0, 150.0]),
        (0.5, [230.0, 30.0, 30.0]),
        (0.8, [255.0, 220.0, 0.0]),
        (1.0, [255.0, 255.0, 255.0]),
    ];
    for pair in stops.windows(2) {
        let ((t0, c0), (t1, c1)) = (pair[0], pair[1]);
        if t <= t1 {
            let k = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
            return [0, 1, 2].map(|i| (c0[i] + k * (c1[i] - c0[i])).round() as u8);
        }
    }
    [255, 255, 255]
}

/// A file the report identifies: what it is, its path, and its BLAKE3 hash (hex) where it is
/// a file (`None`: a built-in scene, with `note` saying so).
#[derive(Clone, Debug)]
pub struct ReportFile {
    /// The path or spec as given.
    pub path: String,
    /// BLAKE3 of its bytes, hex.
    pub blake3: Option<String>,
    /// What to say instead of a hash, or beside it.
    pub note: String,
}

/// What [`html_report`] writes.
pub struct HtmlReport<'a> {
    /// The baked file.
    pub baked: ReportFile,
    /// The scene (`--scene`), if given.
    pub scene: Option<ReportFile>,
    /// The recordings (`--recording`).
    pub recordings: Vec<ReportFile>,
    /// The version of the `trisort` that verified.
    pub tool_version: &'a str,
    /// The version of the tool that wrote the baked file.
    pub baked_tool_version: &'a str,
    /// The bake's settings and the raster profile, as rows (name, value).
    pub settings: Vec<(String, String)>,
    /// The raster profile in words.
    pub raster_profile: String,
    /// The file's clips.
    pub clips: &'a [Clip],
    /// The clip verified (`--clip`), if one.
    pub clip: Option<&'a str>,
    /// The overall verdict: whether `verify` exits 0.
    pub ok: bool,
    /// The verdict in words (as the text report ends).
    pub verdict: String,
    /// The graph rules' report.
    pub graph: Option<&'a GraphReport>,
    /// The image check's report.
    pub images: Option<&'a (ImageReport, ImageCheck)>,
    /// Images measured only: no frame passes or fails on its images.
    pub measure_only: bool,
    /// Thumbnails by frame.
    pub thumbnails: &'a BTreeMap<u32, Thumbnails>,
}

/// `s` escaped for HTML text and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c if c.is_control() && !matches!(c, '\n' | '\t') => out.push('\u{fffd}'),
            c => out.push(c),
        }
    }
    out
}

/// Standard base64 (RFC 4648, padded).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for (i, shift) in [18, 12, 6, 0].into_iter().enumerate() {
            if i <= chunk.len() {
                out.push(ALPHABET[(n >> shift & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// One frame's row.
struct Row<'a> {
    frame: u32,
    clip: &'a str,
    graph: Option<&'a FrameReport>,
    image: Option<&'a FrameImageReport>,
    /// `pass`, `fail` or `measured`.
    verdict: &'static str,
}

impl Row<'_> {
    /// Larger is worse (see the module documentation).
    fn severity(&self) -> (bool, u64, u8, u64, u64, std::cmp::Reverse<u32>) {
        let c = self.image.map(|i| &i.comparison);
        (
            self.verdict == "fail",
            c.map_or(0, |c| c.pixels_differing_ordered),
            c.map_or(0, |c| c.max_channel_diff_ordered),
            self.graph.map_or(0, |g| g.graph_violations),
            c.map_or(0, |c| c.pixels_differing),
            std::cmp::Reverse(self.frame),
        )
    }
}

/// The clip of frame `f` (empty where no clip covers it).
fn clip_name(clips: &[Clip], f: u32) -> &str {
    clips
        .iter()
        .find(|c| c.frames().contains(&f))
        .map_or("", |c| c.name.as_str())
}

const STYLE: &str = "body{font-family:system-ui,sans-serif;margin:1.5em;color:#222}\
h1{font-size:1.4em}h2{font-size:1.15em;margin-top:1.6em}\
table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #ccc;padding:3px 6px;\
text-align:right;vertical-align:middle}th{background:#f2f2f2}td.l,th.l{text-align:left}\
.pass{background:#dff3df}.fail{background:#f8d4d4;font-weight:bold}.measured{background:#eee}\
.banner{padding:.6em 1em;font-size:1.2em;display:inline-block}\
code{font-family:ui-monospace,monospace;word-break:break-all}\
img{image-rendering:pixelated;width:160px;height:auto;display:block}\
figure{margin:0;display:inline-block}figcaption{font-size:.75em;text-align:center}\
.legend{font-size:.9em;max-width:60em}";

/// The report as one HTML document.
pub fn html_report(r: &HtmlReport<'_>) -> String {
    let rows = rows(r);
    let mut o = String::new();
    head_and_files(&mut o, r);
    settings_and_check(&mut o, r);
    clips_table(&mut o, r, &rows);
    frames_table(&mut o, r, &rows);
    o.push_str(LEGEND);
    o
}

/// The rows of every frame either check reports, worst first.
fn rows<'a>(r: &HtmlReport<'a>) -> Vec<Row<'a>> {
    let mut frames: Vec<u32> = r
        .graph
        .map_or_else(Vec::new, |g| g.frames.iter().map(|f| f.frame).collect());
    if let Some((images, _)) = r.images {
        frames.extend(images.frames.iter().map(|f| f.frame));
    }
    frames.sort_unstable();
    frames.dedup();
    let mut rows: Vec<Row> = frames
        .into_iter()
        .map(|frame| {
            let graph = r
                .graph
                .and_then(|g| g.frames.iter().find(|f| f.frame == frame));
            let image = r
                .images
                .and_then(|(i, _)| i.frames.iter().find(|f| f.frame == frame));
            let failed =
                graph.is_some_and(|g| !g.ok()) || image.is_some_and(|i| !i.ok && !r.measure_only);
            let verdict = if failed {
                "fail"
            } else if r.measure_only && graph.is_none() {
                "measured"
            } else {
                "pass"
            };
            Row {
                frame,
                clip: clip_name(r.clips, frame),
                graph,
                image,
                verdict,
            }
        })
        .collect();
    rows.sort_by_key(|row| std::cmp::Reverse(row.severity()));
    rows
}

/// The document's head, the verdict banner, the files with their hashes and the versions.
fn head_and_files(o: &mut String, r: &HtmlReport<'_>) {
    let title = format!("trisort verify: {}", r.baked.path);
    let _ = write!(
        o,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>{}</h1>\n",
        escape(&title),
        escape(&title)
    );
    let _ = writeln!(
        o,
        "<p id=\"verdict\" class=\"banner {}\" data-ok=\"{}\">{}</p>",
        match (r.ok, r.measure_only) {
            (false, _) => "fail",
            (true, true) => "measured",
            (true, false) => "pass",
        },
        r.ok,
        escape(&r.verdict)
    );

    // Identity: files, hashes, versions.
    o.push_str("<h2>Files</h2>\n<table id=\"files\">\n");
    o.push_str(
        "<tr><th class=\"l\">what</th><th class=\"l\">path</th><th class=\"l\">BLAKE3</th></tr>\n",
    );
    let mut file_row = |what: &str, id: &str, f: &ReportFile| {
        let _ = writeln!(
            o,
            "<tr id=\"{id}\"><td class=\"l\">{}</td><td class=\"l\"><code>{}</code></td>\
             <td class=\"l\"><code class=\"hash\">{}</code>{}</td></tr>",
            escape(what),
            escape(&f.path),
            escape(f.blake3.as_deref().unwrap_or("")),
            if f.note.is_empty() {
                String::new()
            } else {
                format!(" {}", escape(&f.note))
            }
        );
    };
    file_row("baked file", "file-baked", &r.baked);
    if let Some(s) = &r.scene {
        file_row("scene", "file-scene", s);
    }
    for (i, rec) in r.recordings.iter().enumerate() {
        file_row("recording", &format!("file-recording-{i}"), rec);
    }
    o.push_str("</table>\n<table id=\"versions\">\n");
    let _ = writeln!(
        o,
        "<tr><th class=\"l\">verified by</th><td class=\"l\" id=\"tool-version\">trisort {}</td></tr>\n\
         <tr><th class=\"l\">baked by</th><td class=\"l\">{}</td></tr>",
        escape(r.tool_version),
        escape(r.baked_tool_version)
    );
    o.push_str("</table>\n");
}

/// The bake's settings and raster profile, and what was checked how.
fn settings_and_check(o: &mut String, r: &HtmlReport<'_>) {
    o.push_str("<h2>Bake settings</h2>\n<table id=\"settings\">\n");
    let _ = writeln!(
        o,
        "<tr><th class=\"l\">raster profile</th><td class=\"l\" id=\"raster-profile\">{}</td></tr>",
        escape(&r.raster_profile)
    );
    for (k, v) in &r.settings {
        let _ = writeln!(
            o,
            "<tr><th class=\"l\">{}</th><td class=\"l\">{}</td></tr>",
            escape(k),
            escape(v)
        );
    }
    o.push_str("</table>\n");
    o.push_str("<h2>Check</h2>\n<table id=\"check\">\n");
    let mut check_row = |k: &str, v: String| {
        let _ = writeln!(
            o,
            "<tr><th class=\"l\">{}</th><td class=\"l\">{}</td></tr>",
            escape(k),
            escape(&v)
        );
    };
    check_row(
        "graph rules",
        match r.graph {
            None => "not checked (no --recording)".into(),
            Some(g) => format!(
                "{} ({} frames, {} copies wrong; {})",
                if g.ok { "OK" } else { "FAILED" },
                g.frames.len(),
                g.bad_copies,
                if g.problems.is_empty() {
                    "no file-wide problem".to_string()
                } else {
                    g.problems.join("; ")
                }
            ),
        },
    );
    match r.images {
        None => check_row("images", "not checked (no --scene)".into()),
        Some((report, check)) => {
            check_row(
                "images",
                format!(
                    "{} mode, {}x{}, {}x MSAA, {} shading, {} tone map{}: {}",
                    check.mode,
                    check.size.0,
                    check.size.1,
                    check.samples,
                    check.shading.name(),
                    check.tone_map.name(),
                    if check.captured {
                        ", captured frames"
                    } else {
                        ""
                    },
                    if r.measure_only {
                        "measured only: NOTHING VERIFIED".to_string()
                    } else if report.at_recorded_pattern {
                        "at the recorded pattern".to_string()
                    } else {
                        format!(
                            "off the recorded pattern, max error {}/255",
                            check.max_error.unwrap_or(0)
                        )
                    }
                ),
            );
            check_row(
                "unordered (excused) pixels",
                if r.graph.is_some() {
                    "those with a sample on a cycle of the recording's E_f".into()
                } else {
                    "none (no --recording)".into()
                },
            );
        }
    }
    check_row("clip verified", r.clip.unwrap_or("all").to_string());
    o.push_str("</table>\n");
}

/// A row per clip of the file: its frames, how many were checked and failed, its worst.
fn clips_table(o: &mut String, r: &HtmlReport<'_>, rows: &[Row<'_>]) {
    o.push_str(
        "<h2>Clips</h2>\n<table id=\"clips\">\n<tr><th class=\"l\">clip</th>\
        <th>frames</th><th>fps</th><th>checked</th><th>failed</th><th>verdict</th>\
        <th>worst frame</th><th>max diff</th><th>pixels differing (sum)</th><th>holes (sum)</th></tr>\n",
    );
    for c in r.clips {
        let mine: Vec<&Row> = rows.iter().filter(|row| row.clip == c.name).collect();
        let failed = mine.iter().filter(|row| row.verdict == "fail").count();
        let verdict = if mine.is_empty() {
            "not checked"
        } else if failed > 0 {
            "fail"
        } else if mine.iter().all(|row| row.verdict == "measured") {
            "measured"
        } else {
            "pass"
        };
        let sum = |f: &dyn Fn(&FrameImageReport) -> u64| -> u64 {
            mine.iter().filter_map(|row| row.image).map(f).sum()
        };
        let _ = writeln!(
            o,
            "<tr class=\"clip {}\" data-clip=\"{}\"><td class=\"l\">{}</td><td>{}..{}</td>\
             <td>{}</td><td data-key=\"checked\">{}</td><td data-key=\"failed\">{failed}</td>\
             <td class=\"verdict\">{verdict}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            verdict.replace(' ', "-"),
            escape(&c.name),
            escape(&c.name),
            c.first,
            c.first + c.count,
            c.fps.map_or_else(|| "-".into(), |f| format!("{f}")),
            mine.len(),
            // Rows are worst first: the clip's first is its worst.
            mine.first()
                .map_or_else(|| "-".into(), |row| row.frame.to_string()),
            mine.iter()
                .filter_map(|row| row.image)
                .map(|i| i.comparison.max_channel_diff)
                .max()
                .map_or_else(|| "-".into(), |m| m.to_string()),
            sum(&|i| i.comparison.pixels_differing),
            sum(&|i| i.hole_pixels),
        );
    }
    o.push_str("</table>\n");
}

/// A row per checked frame, worst first, with its figures and thumbnails.
fn frames_table(o: &mut String, r: &HtmlReport<'_>, rows: &[Row<'_>]) {
    o.push_str(
        "<h2>Frames (worst first)</h2>\n<table id=\"frames\">\n<tr><th>frame</th>\
        <th class=\"l\">clip</th><th>verdict</th><th>pixels differing</th>\
        <th>ordered pixels differing</th><th>max diff</th><th>max diff (ordered)</th>\
        <th>unordered samples</th><th>holes</th><th>order errors</th><th>graph violations</th>\
        <th>PSNR</th><th class=\"l\">player</th><th class=\"l\">reference</th>\
        <th class=\"l\">difference</th></tr>\n",
    );
    let num = |v: Option<u64>| v.map_or_else(|| "-".to_string(), |v| v.to_string());
    for row in rows {
        let c = row.image.map(|i| &i.comparison);
        let _ = write!(
            o,
            "<tr class=\"frame\" data-frame=\"{}\" data-clip=\"{}\" data-verdict=\"{}\">\
             <td data-key=\"frame\">{}</td><td class=\"l\" data-key=\"clip\">{}</td>\
             <td class=\"verdict {}\" data-key=\"verdict\">{}</td>",
            row.frame,
            escape(row.clip),
            row.verdict,
            row.frame,
            escape(row.clip),
            row.verdict,
            row.verdict
        );
        let unordered = row
            .image
            .map(|i| i.unordered_samples)
            .or(row.graph.map(|g| g.unordered_samples));
        let cells: [(&str, String); 9] = [
            ("pixels_differing", num(c.map(|c| c.pixels_differing))),
            (
                "pixels_differing_ordered",
                num(c.map(|c| c.pixels_differing_ordered)),
            ),
            (
                "max_channel_diff",
                num(c.map(|c| c.max_channel_diff as u64)),
            ),
            (
                "max_channel_diff_ordered",
                num(c.map(|c| c.max_channel_diff_ordered as u64)),
            ),
            ("unordered_samples", num(unordered)),
            ("hole_pixels", num(row.image.map(|i| i.hole_pixels))),
            (
                "order_error_pixels",
                num(row.image.map(|i| i.order_error_pixels)),
            ),
            (
                "graph_violations",
                num(row.graph.map(|g| g.graph_violations)),
            ),
            (
                "psnr",
                c.map_or_else(|| "-".into(), |c| format!("{:.1}", c.psnr)),
            ),
        ];
        for (key, value) in cells {
            let _ = write!(o, "<td data-key=\"{key}\">{}</td>", escape(&value));
        }
        match r.thumbnails.get(&row.frame) {
            Some(t) => {
                for (what, bytes) in [
                    ("player", &t.player),
                    ("reference", &t.reference),
                    ("difference", &t.heat),
                ] {
                    let _ = write!(
                        o,
                        "<td class=\"l\"><img class=\"{what}\" alt=\"frame {} {what}\" \
                         width=\"{}\" height=\"{}\" src=\"data:image/png;base64,{}\"></td>",
                        row.frame,
                        t.width,
                        t.height,
                        base64(bytes)
                    );
                }
            }
            None => o.push_str("<td class=\"l\" colspan=\"3\">no images</td>"),
        }
        o.push_str("</tr>\n");
    }
    o.push_str("</table>\n");
}

/// What the report's figures mean, and the end of the document.
const LEGEND: &str = "<h2>Legend</h2>\n<div class=\"legend\" id=\"legend\">\n<ul>\n\
         <li><b>verdict</b>: fail when the frame's graph rules or its image check failed \
         (the image check: at the recorded pattern, a colour channel more than 1/255 off at an \
         ordered pixel, or any difference in depth mode; off it, more than --max-error); \
         <i>measured</i> when the images were only measured (--measure-only).</li>\n\
         <li><b>pixels differing</b>: pixels whose colour differs from the exact reference at \
         all; <b>ordered</b>: of those, the pixels without an unordered sample.</li>\n\
         <li><b>max diff</b>: the largest colour-channel difference, in 1/255.</li>\n\
         <li><b>unordered samples</b>: samples whose peel fragments form an edge on a cycle of \
         the recording's E_f (excused; 0 without --recording).</li>\n\
         <li><b>holes</b>: differing pixels with a hole sample, one whose nearest fragment in \
         the reference is of a triangle the file does not draw in the frame (what verify's \
         <code>hole_pixels</code> measures); <b>order errors</b>: the other differing ordered \
         pixels, drawn in the wrong order.</li>\n\
         <li><b>difference</b>: per pixel the largest colour-channel difference, black where \
         none, dark blue at 1/255 through red (about 16/255) to yellow and white (255/255), \
         logarithmic; grey where only unordered (excused) pixels differ. Thumbnails are at \
         most 256 pixels wide; the difference keeps the largest value of the pixels each \
         thumbnail pixel covers.</li>\n\
         <li>Frames are sorted worst first: failing frames first, then by ordered pixels \
         differing, largest ordered difference, graph violations and pixels differing.</li>\n\
         </ul>\n</div>\n</body>\n</html>\n";

/// Writes `html` as `dir/index.html` (creating `dir`), atomically.
pub fn write_report(dir: &Path, html: &str) -> Result<(), FramesError> {
    std::fs::create_dir_all(dir).map_err(|e| FramesError::Write {
        path: dir.to_path_buf(),
        problem: format!("creating: {e}"),
    })?;
    let path = dir.join("index.html");
    trisort_format::container::write_bytes_atomic(&path, html.as_bytes()).map_err(|e| {
        FramesError::Write {
            path,
            problem: e.to_string(),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648() {
        for (raw, enc) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(raw.as_bytes()), enc);
        }
    }

    #[test]
    fn escape_covers_markup_and_quotes() {
        assert_eq!(
            escape("<a href=\"x\">&'</a>"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;&lt;/a&gt;"
        );
    }

    #[test]
    fn heat_map_keeps_a_single_pixel_in_the_downscale() {
        let (w, h) = (8, 8);
        let reference = vec![10u8; w * h * 4];
        let mut test = reference.clone();
        test[4 * 27] = 30; // one pixel, 20/255 off
        let heat = heat_map(&test, &reference, &vec![false; w * h], (8, 8), (2, 2));
        let lit: Vec<bool> = heat.chunks(4).map(|p| p[..3] != [0, 0, 0]).collect();
        // Pixel (3, 3) lies in the top-left quarter.
        assert_eq!(lit, [true, false, false, false]);
    }
}
