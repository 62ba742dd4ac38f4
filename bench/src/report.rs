//! `trisort bench`'s table run: its bakes (made or reused) and its outputs (`bench.json`,
//! `bench.csv`, `bench.md`, SVG charts).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::json;
use trisort_bake::{recording_path, Events, Settings, Working};
use trisort_format::{Baked, FileKind, RecordSettings, Recording};
use trisort_gpu::Gpu;
use trisort_merger::MergeOptions;

use crate::methods::source_baked;
use crate::methods::BenchView;
use crate::plot::{write_svg, Chart, Series, Style};
use crate::table::{run_group, GroupInput, GroupReport, MethodKind};
use crate::BenchError;

/// What a table run measured, for [`report_json`].
pub struct TableRun<'a> {
    /// The device, described.
    pub device: String,
    /// The scene as given.
    pub scene: &'a str,
    /// Its triangles (as recorded).
    pub triangles: usize,
    /// The path as given.
    pub path: &'a str,
    /// Frames of the path.
    pub path_frames: usize,
    /// Frames measured.
    pub frames: &'a [u32],
    /// Image size.
    pub size: (u32, u32),
    /// Repeats of each measurement.
    pub repeats: u32,
    /// Seconds the run took.
    pub seconds: f64,
}

/// Bytes of the file at `path`.
fn file_len(path: &Path) -> Result<u64, BenchError> {
    std::fs::metadata(path)
        .map(|m| m.len())
        .map_err(|source| BenchError::Io {
            path: path.to_path_buf(),
            source,
        })
}

/// A bake of the path at one sample count, the `source` method's bake made from it and its
/// recording, and its costs.
pub struct BakeRun {
    /// MSAA samples.
    pub samples: u32,
    /// The baked file.
    pub baked: Baked,
    /// The `source` method's bake (per-frame lists, no merge) made from its recording.
    pub source: Baked,
    /// Seconds recording took (`None`: reused, not timed).
    pub record_seconds: Option<f64>,
    /// Seconds merging took (`None`: reused).
    pub merge_seconds: Option<f64>,
    /// Bytes of the baked file.
    pub bytes: u64,
    /// Where it is.
    pub path: PathBuf,
}

/// Bakes `working` with `settings` into `out` (or reuses the bake there made from the same
/// scene, path and settings), naming the file after its size, samples and bridge; `say`
/// tells what it does.
pub fn bake_for(
    gpu: &Gpu,
    working: &Working,
    settings: &Settings,
    out: &Path,
    events: &mut dyn Events,
    say: &dyn Fn(&str),
) -> Result<BakeRun, BenchError> {
    let record = &settings.record;
    let (size, samples) = ((record.width, record.height), record.samples);
    let suffix = if settings.merge.bridge == MergeOptions::default().bridge {
        String::new()
    } else {
        format!("-{}", settings.merge.bridge)
    };
    let path = out.join(format!(
        "bake-{}x{}-{}x{suffix}.baked",
        size.0, size.1, samples
    ));
    let rec_path = recording_path(&path);
    let (scene, timeline) = (&working.scene, &working.timeline);
    if path.exists() && rec_path.exists() {
        match reusable(&path, &rec_path, scene, timeline, record, &settings.merge) {
            Ok((baked, recording)) => {
                say(&format!("reusing {}", path.display()));
                let bytes = file_len(&path)?;
                return Ok(BakeRun {
                    samples,
                    source: source_baked(&baked, &recording)?,
                    baked,
                    record_seconds: None,
                    merge_seconds: None,
                    bytes,
                    path,
                });
            }
            Err(why) => say(&format!("{}: {why}; baking again", path.display())),
        }
    }
    say(&format!(
        "baking {} frames at {}x{} {}x",
        timeline.frames.len(),
        size.0,
        size.1,
        samples
    ));
    let environment = settings.light.load()?;
    let done = trisort_bake::bake(gpu, working, settings, environment, &path, events)?;
    let (recording, baked) = (done.recording, done.baked);
    let (record_s, merge_s, reused) = (
        done.record_seconds,
        done.merge_seconds,
        done.recording_reused,
    );
    let bytes = file_len(&path)?;
    say(&format!(
        "baked {} in {:.1} s (record {record_s:.1} s, merge {merge_s:.1} s): {} index triangles, |G| = {}",
        path.display(),
        record_s + merge_s,
        baked.stats.index_triangles,
        baked.stats.unique_visible
    ));
    Ok(BakeRun {
        samples,
        source: source_baked(&baked, &recording)?,
        baked,
        // A recording found finished beside the bake was not timed.
        record_seconds: (!reused).then_some(record_s),
        merge_seconds: Some(merge_s),
        bytes,
        path,
    })
}

/// The bake at `path` and its recording at `rec_path` when they were made from `scene`,
/// `timeline`, `settings` and `merge`'s bridge and segments; otherwise why not (another
/// trisort's file version, other inputs).
fn reusable(
    path: &Path,
    rec_path: &Path,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    settings: &RecordSettings,
    options: &MergeOptions,
) -> Result<(Baked, Recording), String> {
    let read_err = |e: trisort_format::FormatError| e.to_string();
    let baked: Baked = trisort_format::read_file(FileKind::Baked, path).map_err(read_err)?;
    let recording: Recording =
        trisort_format::read_file(FileKind::Recording, rec_path).map_err(read_err)?;
    if baked.scene_hash == scene.hash()
        && baked.path_hash == timeline.hash()
        && baked.settings == *settings
        && baked.merge.bridge == options.bridge
        && baked.merge.segment == options.segment
        && recording.content_hash() == *baked.recording_hashes.first().unwrap_or(&[0; 32])
    {
        Ok((baked, recording))
    } else {
        Err("made from other inputs".into())
    }
}

/// `bench.json`: the run's inputs, every bake's figures, the head group's methods, the
/// ratios the goals are stated in, and every group.
pub fn report_json(
    run: &TableRun<'_>,
    bakes: &[BakeRun],
    groups: &[GroupReport],
) -> serde_json::Value {
    let head = &groups[0];
    let mut methods = serde_json::Map::new();
    for r in &head.rows {
        let mut entry = json!({
            "ms_per_frame": r.ms_per_frame,
            "ms_p95": r.ms_p95,
            "ms_max": r.ms_max,
            "triangles_per_frame": r.triangles_per_frame,
            "draws_per_frame_mean": r.draws_per_frame_mean,
            "overdraw": r.overdraw,
            "fragments_shaded_per_frame": r.fragments_shaded_per_frame,
            "frames_exact": r.error.frames_exact,
            "pixels_differing_fraction": r.error.pixels_differing_fraction,
            "max_channel_diff": r.error.max_channel_diff,
            "flip_mean": r.error.flip_mean,
        });
        if let Some(q) = &r.occlusion_queries {
            entry["occlusion_queries"] = json!(q);
        }
        methods.insert(r.method.clone(), entry);
    }
    let bake_json: Vec<serde_json::Value> = bakes
        .iter()
        .map(|b| {
            let s = &b.baked.stats;
            json!({
                "samples": b.samples,
                "file": b.path.display().to_string(),
                "record_seconds": b.record_seconds,
                "merge_seconds": b.merge_seconds,
                "record_seconds_per_frame": b.record_seconds.map(|x| x / b.baked.frames.len().max(1) as f64),
                "baked_bytes": b.bytes,
                "index_triangles": s.index_triangles,
                "unique_visible": s.unique_visible,
                "source_triangles": s.source_triangles,
                "index_over_g": s.index_triangles as f64 / s.unique_visible.max(1) as f64,
                "draws_per_frame_mean": s.draws_per_frame_mean,
                "draws_per_frame_max": s.draws_per_frame_max,
                "strategy": b.baked.merge.strategy,
                "bridge": b.baked.merge.bridge,
                "segment": b.baked.merge.segment,
                "layout": b.baked.merge.layout,
                "draws_along_path": b.baked.frames.iter().map(|w| w.count).collect::<Vec<_>>(),
            })
        })
        .collect();
    let ratio = |g: &GroupReport, x: &str, y: &str| -> Option<f64> {
        Some(g.row(x)?.ms_per_frame / g.row(y)?.ms_per_frame)
    };
    let goals: Vec<serde_json::Value> = groups
        .iter()
        .map(|g| {
            json!({
                "samples": g.samples,
                "mode": g.mode,
                "merged_over_source": ratio(g, "merged", "source"),
                "merged_unvalidated_over_source": ratio(g, "merged_unvalidated", "source"),
                "default_over_merged": ratio(g, "default", "merged"),
                "oit_over_merged": ratio(g, "oit", "merged"),
                "peeling_over_merged": ratio(g, "peeling", "merged"),
            })
        })
        .collect();
    json!({
        "device": run.device,
        "scene": run.scene,
        "triangles": run.triangles,
        "path": run.path,
        "path_frames": run.path_frames,
        "frames": run.frames,
        "size": [run.size.0, run.size.1],
        "repeats": run.repeats,
        "timing": if groups.iter().flat_map(|g| &g.rows).all(|r| r.gpu_ms.is_some()) {
            "gpu timestamps"
        } else {
            "wall clock"
        },
        "methods": methods,
        "bakes": bake_json,
        "goals": goals,
        "groups": groups,
        "seconds": run.seconds,
    })
}

/// Writes `bench.json` (`value`), `bench.csv` (a row per method and group), an SVG of ms
/// per frame along the path per group and one of draws per frame per bake into `out`.
pub fn write_outputs(
    out: &Path,
    value: &serde_json::Value,
    groups: &[GroupReport],
    bakes: &[BakeRun],
) -> Result<(), BenchError> {
    let write = |name: &str, bytes: &[u8]| -> Result<(), BenchError> {
        let path = out.join(name);
        trisort_format::container::write_bytes_atomic(&path, bytes)
            .map_err(|e| BenchError::Invalid(format!("writing {}: {e}", path.display())))
    };
    write(
        "bench.json",
        serde_json::to_string_pretty(value)
            .expect("JSON values serialize")
            .as_bytes(),
    )?;
    let mut csv = String::from(
        "samples,mode,method,ms_per_frame,ms_p95,ms_max,gpu_ms_mean,wall_ms_mean,triangles_per_frame,draws_per_frame_mean,draws_per_frame_max,fragment_invocations_per_frame,fragments_shaded_per_frame,pixels_covered_per_frame,overdraw,frames_exact,frames,pixels_differing_fraction,pixels_differing_ordered_fraction,max_channel_diff,flip_mean,psnr_min\n",
    );
    for g in groups {
        for r in &g.rows {
            let _ = writeln!(
                csv,
                "{},{},{},{:.4},{:.4},{:.4},{},{:.4},{:.1},{:.2},{},{},{:.0},{:.0},{:.3},{},{},{:.6},{:.6},{},{:.5},{:.2}",
                r.samples,
                r.mode,
                r.method,
                r.ms_per_frame,
                r.ms_p95,
                r.ms_max,
                r.gpu_ms.map(|s| format!("{:.4}", s.mean)).unwrap_or_default(),
                r.wall_ms.mean,
                r.triangles_per_frame,
                r.draws_per_frame_mean,
                r.draws_per_frame_max,
                r.fragment_invocations_per_frame
                    .map(|x| format!("{x:.0}"))
                    .unwrap_or_default(),
                r.fragments_shaded_per_frame,
                r.pixels_covered_per_frame,
                r.overdraw,
                r.error.frames_exact,
                r.error.frames,
                r.error.pixels_differing_fraction,
                r.error.pixels_differing_ordered_fraction,
                r.error.max_channel_diff,
                r.error.flip_mean,
                r.error.psnr_min,
            );
        }
    }
    write("bench.csv", csv.as_bytes())?;
    for g in groups {
        let chart = Chart {
            title: format!("ms per frame, {}x MSAA, {} mode", g.samples, g.mode),
            x_label: "frame".into(),
            y_label: "ms per frame".into(),
            log_x: false,
            log_y: true,
            series: g
                .rows
                .iter()
                .map(|r| Series {
                    name: r.method.clone(),
                    points: r
                        .ms_along_path
                        .iter()
                        .map(|&(f, ms)| (f as f64, ms))
                        .collect(),
                })
                .collect(),
        };
        write_svg(
            &out.join(format!("bench-ms-per-frame-{}x-{}.svg", g.samples, g.mode)),
            &chart,
            Style::Lines,
        )?;
    }
    let draws = Chart {
        title: "merged: draws per frame along the path".into(),
        x_label: "frame".into(),
        y_label: "draws (multi-draw commands)".into(),
        log_x: false,
        log_y: false,
        series: bakes
            .iter()
            .map(|b| Series {
                name: format!("{}x bake", b.samples),
                points: b
                    .baked
                    .frames
                    .iter()
                    .enumerate()
                    .map(|(f, w)| (f as f64, w.count as f64))
                    .collect(),
            })
            .collect(),
    };
    write_svg(
        &out.join("bench-draws-along-path.svg"),
        &draws,
        Style::Lines,
    )?;
    Ok(())
}

/// The human summary (also written as bench.md): one Markdown table per group.
pub fn markdown(value: &serde_json::Value, groups: &[GroupReport], bakes: &[BakeRun]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "device: {}; timing: {}; frames {}",
        value["device"].as_str().unwrap_or(""),
        value["timing"].as_str().unwrap_or(""),
        value["frames"]
    );
    for b in bakes {
        let st = &b.baked.stats;
        let _ = writeln!(
            s,
            "bake {}x: index {} triangles = {:.3} × |G| ({}), draws/frame mean {:.1} max {}, {} bytes{}",
            b.samples,
            st.index_triangles,
            st.index_triangles as f64 / st.unique_visible.max(1) as f64,
            st.unique_visible,
            st.draws_per_frame_mean,
            st.draws_per_frame_max,
            b.bytes,
            match (b.record_seconds, b.merge_seconds) {
                (Some(r), Some(m)) => format!(", record {r:.1} s, merge {m:.1} s"),
                _ => " (reused)".into(),
            }
        );
    }
    for g in groups {
        let _ = writeln!(s, "\n{}x MSAA, {} mode", g.samples, g.mode);
        let _ = writeln!(s, "| method | ms/frame | p95 | max | × merged | triangles | draws | overdraw | exact frames | px differing | max diff | FLIP |");
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|");
        let merged = g.row("merged").map(|r| r.ms_per_frame);
        for r in &g.rows {
            let _ = writeln!(
                s,
                "| {} | {:.3} | {:.3} | {:.3} | {} | {:.0} | {:.1} | {:.2} | {}/{} | {:.3} % | {} | {:.4} |",
                r.method,
                r.ms_per_frame,
                r.ms_p95,
                r.ms_max,
                merged
                    .map(|m| format!("{:.2}", r.ms_per_frame / m))
                    .unwrap_or_default(),
                r.triangles_per_frame,
                r.draws_per_frame_mean,
                r.overdraw,
                r.error.frames_exact,
                r.error.frames,
                100.0 * r.error.pixels_differing_fraction,
                r.error.max_channel_diff,
                r.error.flip_mean,
            );
        }
        for k in &g.skipped {
            let _ = writeln!(s, "- {} left out: {}", k.method, k.why);
        }
        for r in g.rows.iter().filter(|r| !r.variant.is_empty()) {
            let _ = writeln!(s, "- {}: {}", r.method, r.variant);
        }
        if let Some(x) = g.merged_over_source() {
            let _ = writeln!(s, "merged / source = {x:.2} (goal ≤ 1.2; paper 1.35–2.7)");
        }
    }
    s
}

/// What a table run measures: the playback size and glass, the modes and methods, the
/// frames and how often each is repeated.
pub struct Table<'a> {
    /// Playback size.
    pub size: (u32, u32),
    /// Glass opacity of playback.
    pub glass_opacity: f32,
    /// The modes, one group per bake and mode.
    pub modes: &'a [trisort_player::Mode],
    /// The methods compared in every group.
    pub methods: &'a [MethodKind],
    /// The frames measured.
    pub frames: &'a [u32],
    /// Repeats of each measurement.
    pub repeats: u32,
    /// The file the `presorted` methods play (`None`: they presort the scene).
    pub presorted: Option<&'a trisort_format::Presorted>,
}

/// Frames measured: `max` evenly spaced frames of `range` (all when `max` is 0).
pub fn measured_frames(range: std::ops::Range<u32>, max: u32) -> Vec<u32> {
    let n = range.end - range.start;
    if max == 0 || n <= max {
        return range.collect();
    }
    let mut v: Vec<u32> = (0..max)
        .map(|k| range.start + ((k as u64 * (n - 1) as u64) / (max - 1).max(1) as u64) as u32)
        .collect();
    v.dedup();
    v
}

/// The devices the table times on: the default one, and the optional extra ones.
pub struct Devices<'a> {
    /// The device every method plays on.
    pub gpu: &'a Gpu,
    /// `merged` again with wgpu's indirect-call validation off.
    pub unvalidated: Option<&'a Gpu>,
    /// `merged_device`: `merged` on another backend or with other limits.
    pub other: Option<&'a Gpu>,
}

/// Times every method on every (bake, mode) pair: one group each, in that order.
pub fn run_groups(
    a: &Table<'_>,
    devices: &Devices<'_>,
    working: &Working,
    bakes: &[BakeRun],
    say: &dyn Fn(&str),
) -> Result<Vec<GroupReport>, BenchError> {
    let frames = a.frames;
    let (scene, timeline) = (&working.scene, &working.timeline);
    let mut groups: Vec<GroupReport> = Vec::new();
    for b in bakes {
        for &mode in a.modes {
            say(&format!("{} samples, {} mode", b.samples, mode.name()));
            let input = GroupInput {
                geometry: &scene.geometry,
                frame_states: &timeline.frames,
                baked: &b.baked,
                source: &b.source,
                view: BenchView {
                    size: a.size,
                    samples: b.samples,
                    glass_opacity: a.glass_opacity,
                },
                mode,
                methods: a.methods,
                frames,
                repeats: a.repeats,
                unvalidated: devices.unvalidated,
                other_device: devices.other,
                presorted: a.presorted,
            };
            let label = format!("{}x {}", b.samples, mode.name());
            groups.push(run_group(devices.gpu, &input, &|m| {
                say(&format!("[{label}] {m}"))
            })?);
        }
    }
    Ok(groups)
}
