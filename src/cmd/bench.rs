//! `trisort bench SCENE --path P`: frame time and accuracy of the merged player against its
//! rivals (the paper's Table 1 and more), the speed/accuracy sweep and bake-cost scaling.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::json;
use trisort_bench::methods::{source_baked, BenchView};
use trisort_bench::plot::{write_svg, Chart, Series, Style};
use trisort_bench::table::{run_group, GroupInput, GroupReport, MethodKind};
use trisort_format::{Baked, Bridge, FileKind, RecordSettings, Recording};
use trisort_gpu::Gpu;
use trisort_merger::MergeOptions;
use trisort_player::Mode;

use trisort_bake::{recording_path, Working};

use crate::cmd::merge::MergeOpts;
use crate::common::{
    default_size, load_working, option_parser, parse_range, parse_size, print_json, FrameRange,
};

/// Arguments of `bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scene (.glb/.gltf, or `demo[:TRIANGLES]`).
    scene: String,
    /// Path: TOML file, `gltf` (or `gltf:animation=NAME,camera=NAME`), `orbit:…`, `dolly:…`
    /// or `demo`.
    #[arg(long)]
    path: String,
    /// Recording and playback size, WIDTHxHEIGHT.
    #[arg(long, default_value = default_size(), value_parser = parse_size)]
    size: (u32, u32),
    /// MSAA sample counts, comma-separated; each is baked (recorded) at its own count, so every
    /// method plays at its recorded pattern. The first is the headline (`methods` in --json).
    #[arg(long, default_value = "4,1", value_delimiter = ',')]
    samples: Vec<u32>,
    /// Modes, comma-separated (blend, depth, saturate). The first is the headline.
    #[arg(long, default_value = "blend,depth,saturate", value_delimiter = ',')]
    mode: Vec<Mode>,
    /// Methods, comma-separated: default, source, merged, oit, peeling.
    #[arg(long, default_value = "default,source,merged,oit,peeling", value_delimiter = ',', value_parser = parse_method)]
    methods: Vec<MethodKind>,
    /// Frames to measure, half-open `a..b` (default: all); the bake always covers the path.
    #[arg(long, value_parser = parse_range)]
    frames: Option<FrameRange>,
    /// At most this many measured frames, evenly spaced over --frames (0: every frame).
    #[arg(long, default_value_t = 12)]
    max_frames: u32,
    /// Timed repetitions of every (frame, method); calls are interleaved.
    #[arg(long, default_value_t = 5)]
    repeats: u32,
    /// Opacity at which transmissive glass is recorded and played.
    #[arg(long, default_value_t = RecordSettings::DEFAULT_GLASS_OPACITY)]
    glass_opacity: f32,
    /// Bridge policy of the bakes (see `trisort merge --bridge`): `visible` draws exactly each
    /// frame's visible set; `hidden` shares more copies and draws more triangles.
    #[arg(long, value_parser = option_parser::<Bridge>(),
          default_value_t = MergeOptions::default().bridge)]
    bridge: Bridge,
    /// Sampling rate for `--path gltf` and generated paths (a TOML file sets its own).
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    /// Skip timing `merged` with wgpu's indirect-call validation off.
    #[arg(long)]
    no_unvalidated: bool,
    /// `--backend`/`--limits` other than auto/default: `merged` is also played on that device
    /// (gl: OpenGL/GLES through EGL; webgl2: the player's GLES 3.0 / WebGL2 path), as the
    /// method `merged_device`; baking, the reference and the rivals stay on the default device.
    #[command(flatten)]
    device: crate::cmd::play::DeviceArgs,
    /// Output folder: bench.json, bench.csv, bench.md, SVG plots, and the bakes (reused by a
    /// later run with the same scene, path and settings).
    #[arg(long, default_value = "bench-out")]
    out: PathBuf,
    /// Run the speed/accuracy sweep instead (one factor at a time around the defaults):
    /// sweep.csv, sweep.json and plots in --out.
    #[arg(long)]
    sweep: bool,
    /// With --sweep: the factors, comma-separated (default: all).
    #[arg(long, requires = "sweep")]
    sweep_factors: Option<String>,
    /// Measure bake cost against `triangles` or `frames` instead, on the procedural car at the
    /// configuration's own sizes and orbits (SCENE must be `demo`; --path is not used).
    #[arg(long, value_parser = ["triangles", "frames"])]
    scaling: Option<String>,
    /// With --scaling: the small configuration (for tests).
    #[arg(long, requires = "scaling")]
    quick: bool,
    /// Print the figures as JSON.
    #[arg(long)]
    json: bool,
}

fn parse_method(s: &str) -> Result<MethodKind, String> {
    MethodKind::parse(s).ok_or_else(|| {
        format!("unknown method `{s}` (expected default, source, merged, oit or peeling)")
    })
}

/// Says what the bench is doing (stderr, so `--json` stays clean).
fn say(msg: &str) {
    eprintln!("trisort bench: {msg}");
}

/// Frames measured: `max` evenly spaced frames of `range` (all when `max` is 0).
fn measured_frames(range: std::ops::Range<u32>, max: u32) -> Vec<u32> {
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

/// A bake of the path at one sample count, the `source` method's bake made from it and its
/// recording, and its costs.
struct BakeRun {
    samples: u32,
    baked: Baked,
    source: Baked,
    record_seconds: Option<f64>,
    merge_seconds: Option<f64>,
    bytes: u64,
    path: PathBuf,
}

/// Bakes (or reuses the bake in `out` made from the same scene, path and settings).
fn bake_for(gpu: &Gpu, working: &Working, a: &BenchArgs, samples: u32) -> Result<BakeRun> {
    let merge = MergeOpts {
        bridge: a.bridge,
        ..MergeOpts::defaults()
    };
    let suffix = if a.bridge == MergeOptions::default().bridge {
        String::new()
    } else {
        format!("-{}", a.bridge)
    };
    let path = a.out.join(format!(
        "bake-{}x{}-{}x{suffix}.baked",
        a.size.0, a.size.1, samples
    ));
    let rec_path = recording_path(&path);
    let settings = RecordSettings {
        glass_opacity: a.glass_opacity,
        ..RecordSettings::new(a.size, samples)
    };
    let (scene, timeline) = (&working.scene, &working.timeline);
    if path.exists() && rec_path.exists() {
        match reusable(&path, &rec_path, scene, timeline, &settings, &merge) {
            Ok((baked, recording)) => {
                say(&format!("reusing {}", path.display()));
                let bytes = std::fs::metadata(&path)?.len();
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
        a.size.0,
        a.size.1,
        samples
    ));
    let bake_settings = trisort_bake::Settings {
        fps: a.fps,
        record: settings,
        merge: merge.options(),
        light: merge.light(),
        ..trisort_bake::Settings::new(&a.scene, &a.path)
    };
    let environment = bake_settings.light.load()?;
    let done = trisort_bake::bake(
        gpu,
        working,
        &bake_settings,
        environment,
        &path,
        &mut crate::common::Console::new(),
    )?;
    let (recording, baked) = (done.recording, done.baked);
    let (record_s, merge_s, reused) = (
        done.record_seconds,
        done.merge_seconds,
        done.recording_reused,
    );
    let bytes = std::fs::metadata(&path)?.len();
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
    merge: &MergeOpts,
) -> Result<(Baked, Recording)> {
    let baked: Baked = trisort_format::read_file(FileKind::Baked, path)?;
    let recording: Recording = trisort_format::read_file(FileKind::Recording, rec_path)?;
    let options = merge.options();
    if baked.scene_hash == scene.hash()
        && baked.path_hash == timeline.hash()
        && baked.settings == *settings
        && baked.merge.bridge == options.bridge
        && baked.merge.segment == options.segment
        && recording.content_hash() == *baked.recording_hashes.first().unwrap_or(&[0; 32])
    {
        Ok((baked, recording))
    } else {
        bail!("made from other inputs")
    }
}

pub fn run(a: BenchArgs) -> Result<ExitCode> {
    if let Some(axis) = &a.scaling {
        return run_scaling(&a, axis);
    }
    if a.samples.is_empty() || a.samples.iter().any(|&s| s != 1 && s != 4) {
        bail!("--samples takes 1 and/or 4");
    }
    if a.mode.is_empty() || a.methods.is_empty() {
        bail!("--mode and --methods need at least one entry");
    }
    if a.repeats == 0 {
        bail!("--repeats must be at least 1");
    }
    let t0 = Instant::now();
    // Every bake and rival below sees the scene as the default settings record it.
    let working = load_working(&a.scene, &a.path, a.fps, &RecordSettings::default())?;
    let (scene, timeline) = (&working.scene, &working.timeline);
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let gpu = crate::common::open_gpu()?;
    let n = timeline.frames.len() as u32;
    let range = match a.frames {
        Some(r) => r.resolve(n)?,
        None => 0..n,
    };
    let frames = measured_frames(range, a.max_frames);
    if a.sweep {
        return run_sweep(&a, &gpu, scene, timeline, frames);
    }
    let unvalidated = if a.no_unvalidated || !a.methods.contains(&MethodKind::Merged) {
        None
    } else {
        Some(
            Gpu::with_flags(trisort_player::instance_flags(false))
                .context("opening a second device with indirect validation off")?,
        )
    };
    let other = if a.device.options() == trisort_gpu::GpuOptions::default()
        || !a.methods.contains(&MethodKind::Merged)
    {
        None
    } else {
        let g = crate::common::open_gpu_with(a.device.options()).with_context(|| {
            format!(
                "opening the --backend {} --limits {} device",
                a.device.backend, a.device.limits
            )
        })?;
        say(&format!("merged_device plays on {}", g.describe()));
        Some(g)
    };
    say(&format!(
        "{} on {}: {} frames measured of {}, {} repeats",
        a.scene,
        gpu.describe(),
        frames.len(),
        n,
        a.repeats
    ));

    let mut bakes = Vec::new();
    for &s in &a.samples {
        bakes.push(bake_for(&gpu, &working, &a, s)?);
    }
    let mut groups: Vec<GroupReport> = Vec::new();
    for b in &bakes {
        for &mode in &a.mode {
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
                methods: &a.methods,
                frames: &frames,
                repeats: a.repeats,
                unvalidated: unvalidated.as_ref(),
                other_device: other.as_ref(),
            };
            let label = format!("{}x {}", b.samples, mode.name());
            groups.push(run_group(&gpu, &input, &|m| {
                say(&format!("[{label}] {m}"))
            })?);
        }
    }

    let value = report_json(&a, &gpu, scene, timeline, &frames, &bakes, &groups, t0);
    write_outputs(&a.out, &value, &groups, &bakes)?;
    let md = markdown(&value, &groups, &bakes);
    trisort_format::container::write_bytes_atomic(&a.out.join("bench.md"), md.as_bytes())?;
    if a.json {
        print_json(&value);
    } else {
        print!("{md}");
        println!("wrote {}", a.out.display());
    }
    Ok(ExitCode::SUCCESS)
}

#[allow(clippy::too_many_arguments)]
fn report_json(
    a: &BenchArgs,
    gpu: &Gpu,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    frames: &[u32],
    bakes: &[BakeRun],
    groups: &[GroupReport],
    t0: Instant,
) -> serde_json::Value {
    let head = &groups[0];
    let mut methods = serde_json::Map::new();
    for r in &head.rows {
        methods.insert(
            r.method.clone(),
            json!({
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
            }),
        );
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
        "device": gpu.describe(),
        "scene": a.scene,
        "triangles": scene.geometry.triangles.len(),
        "path": a.path,
        "path_frames": timeline.frames.len(),
        "frames": frames,
        "size": [a.size.0, a.size.1],
        "repeats": a.repeats,
        "timing": if groups.iter().flat_map(|g| &g.rows).all(|r| r.gpu_ms.is_some()) {
            "gpu timestamps"
        } else {
            "wall clock"
        },
        "methods": methods,
        "bakes": bake_json,
        "goals": goals,
        "groups": groups,
        "seconds": t0.elapsed().as_secs_f64(),
    })
}

fn write_outputs(
    out: &Path,
    value: &serde_json::Value,
    groups: &[GroupReport],
    bakes: &[BakeRun],
) -> Result<()> {
    let write = |name: &str, bytes: &[u8]| -> Result<()> {
        trisort_format::container::write_bytes_atomic(&out.join(name), bytes)?;
        Ok(())
    };
    write(
        "bench.json",
        serde_json::to_string_pretty(value)?.as_bytes(),
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
fn markdown(value: &serde_json::Value, groups: &[GroupReport], bakes: &[BakeRun]) -> String {
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

/// `--scaling triangles|frames`: bake cost against scene size or path length.
fn run_scaling(a: &BenchArgs, axis: &str) -> Result<ExitCode> {
    use trisort_bench::scaling;
    if a.scene != "demo" {
        bail!(
            "--scaling measures the built-in procedural car at its own sizes and paths: give `demo` as the scene, not `{}`",
            a.scene
        );
    }
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let gpu = crate::common::open_gpu()?;
    let config = if a.quick {
        scaling::ScalingConfig::quick()
    } else {
        scaling::ScalingConfig::full()
    };
    let progress = |m: &str| say(m);
    let rows = match axis {
        "triangles" => scaling::triangles(&gpu, &config, &progress)?,
        _ => scaling::frames(&gpu, &config, &progress)?,
    };
    scaling::write_outputs(&rows, &a.out, axis)?;
    if a.json {
        print_json(&json!({
            "device": gpu.describe(),
            "axis": axis,
            "rows": rows,
            "growth": scaling::growth(&rows),
        }));
    } else {
        print!("{}", scaling::to_csv(&rows));
        println!("wrote {}", a.out.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// `--sweep`: one factor at a time around the defaults, at the first `--samples` count, over
/// the measured frames.
fn run_sweep(
    a: &BenchArgs,
    gpu: &Gpu,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    frames: Vec<u32>,
) -> Result<ExitCode> {
    use trisort_bench::sweep;
    let mut config = sweep::SweepConfig::new(a.size, a.samples[0]);
    config.glass_opacity = a.glass_opacity;
    config.frames = frames;
    if let Some(list) = &a.sweep_factors {
        config.factors = sweep::Factor::parse_list(list)?;
    }
    let report = sweep::run(gpu, scene, timeline, &config, &a.out, &|m| say(m))?;
    if a.json {
        print_json(&serde_json::to_value(&report)?);
    } else {
        print!("{}", sweep::to_csv(&report.points));
        println!("wrote {}", a.out.display());
    }
    Ok(ExitCode::SUCCESS)
}
