//! `trisort bench SCENE --path P`: frame time and accuracy of the merged player against its
//! rivals (the paper's Table 1 and more), the speed/accuracy sweep and bake-cost scaling.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::json;
use trisort_bench::report::{
    bake_for, markdown, measured_frames, report_json, run_groups, write_outputs, BakeRun, Devices,
    Table, TableRun,
};
use trisort_bench::table::{GroupReport, MethodKind};
use trisort_format::{Bridge, RecordSettings};
use trisort_gpu::Gpu;
use trisort_merger::MergeOptions;
use trisort_player::Mode;

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
    /// Methods, comma-separated: default, source, merged, oit, peeling, presorted (paper 000;
    /// not by default: it presorts the scene first, and needs every camera outside the
    /// scene's bounding polyhedron), occlusion-query (paper 004, blend mode only; not by
    /// default: it sorts every frame of the path from frame 0 with GPU readbacks).
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
    /// The `presorted` methods play this file (`trisort presort` of the same scene) instead of
    /// presorting the scene first, which can take long on a large one.
    #[arg(long, value_name = "FILE")]
    presorted: Option<PathBuf>,
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

/// `--presorted FILE`, read and checked against the bench's scene (the one its reference
/// renders): triangle for triangle, vertex for vertex.
fn presorted_for(
    path: &std::path::Path,
    geometry: &trisort_format::Geometry,
) -> Result<trisort_format::Presorted> {
    let file: trisort_format::Presorted =
        trisort_format::read_file(trisort_format::FileKind::Presorted, path)?;
    file.check_structure()
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    if let Some(why) = trisort_bench::methods::presorted_mismatch(&file, geometry) {
        anyhow::bail!("{}: --presorted: {why}", path.display());
    }
    Ok(file)
}

/// Says what the bench is doing (stderr, so `--json` stays clean).
fn say(msg: &str) {
    eprintln!("trisort bench: {msg}");
}

pub fn run(a: BenchArgs) -> Result<ExitCode> {
    if let Some(axis) = &a.scaling {
        return run_scaling(&a, axis);
    }
    check_table_args(&a)?;
    let t0 = Instant::now();
    // Every bake and rival below sees the scene as the default settings record it.
    let working = load_working(&trisort_bake::Settings {
        fps: a.fps,
        ..trisort_bake::Settings::new(&a.scene, a.path.as_str())
    })?;
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
        return run_sweep(&a, &gpu, &working, frames);
    }
    let unvalidated = unvalidated_device(&a)?;
    let other = other_device(&a)?;
    say(&format!(
        "{} on {}: {} frames measured of {}, {} repeats",
        a.scene,
        gpu.describe(),
        frames.len(),
        n,
        a.repeats
    ));
    let presorted = a
        .presorted
        .as_deref()
        .map(|p| presorted_for(p, &scene.geometry))
        .transpose()?;
    let bakes = bake_samples(&a, &gpu, &working)?;
    let devices = Devices {
        gpu: &gpu,
        unvalidated: unvalidated.as_ref(),
        other: other.as_ref(),
    };
    let table = Table {
        size: a.size,
        glass_opacity: a.glass_opacity,
        modes: &a.mode,
        methods: &a.methods,
        frames: &frames,
        repeats: a.repeats,
        presorted: presorted.as_ref(),
    };
    let groups = run_groups(&table, &devices, &working, &bakes, &say)?;

    let run = TableRun {
        device: gpu.describe(),
        scene: &a.scene,
        triangles: scene.geometry.triangles.len(),
        path: &a.path,
        path_frames: timeline.frames.len(),
        frames: &frames,
        size: a.size,
        repeats: a.repeats,
        seconds: t0.elapsed().as_secs_f64(),
    };
    write_table_report(&a, &run, &bakes, &groups)?;
    Ok(ExitCode::SUCCESS)
}

/// Refuses table arguments no run could use: samples other than 1 and 4, empty mode or
/// method lists, no repeats.
fn check_table_args(a: &BenchArgs) -> Result<()> {
    if a.samples.is_empty() || a.samples.iter().any(|&s| s != 1 && s != 4) {
        bail!("--samples takes 1 and/or 4");
    }
    if a.mode.is_empty() || a.methods.is_empty() {
        bail!("--mode and --methods need at least one entry");
    }
    if a.repeats == 0 {
        bail!("--repeats must be at least 1");
    }
    Ok(())
}

/// The second device `merged` is also timed on, with wgpu's indirect-call validation off
/// (none with --no-unvalidated or without `merged`).
fn unvalidated_device(a: &BenchArgs) -> Result<Option<Gpu>> {
    if a.no_unvalidated || !a.methods.contains(&MethodKind::Merged) {
        return Ok(None);
    }
    Ok(Some(
        Gpu::with_flags(trisort_player::instance_flags(false))
            .context("opening a second device with indirect validation off")?,
    ))
}

/// The `--backend`/`--limits` device `merged_device` plays on (none at the defaults or
/// without `merged`).
fn other_device(a: &BenchArgs) -> Result<Option<Gpu>> {
    if a.device.options() == trisort_gpu::GpuOptions::default()
        || !a.methods.contains(&MethodKind::Merged)
    {
        return Ok(None);
    }
    let g = crate::common::open_gpu_with(a.device.options()).with_context(|| {
        format!(
            "opening the --backend {} --limits {} device",
            a.device.backend, a.device.limits
        )
    })?;
    say(&format!("merged_device plays on {}", g.describe()));
    Ok(Some(g))
}

/// One bake per `--samples` count, each recorded at its own count (reused when found in
/// --out).
fn bake_samples(a: &BenchArgs, gpu: &Gpu, working: &trisort_bake::Working) -> Result<Vec<BakeRun>> {
    let mut bakes = Vec::new();
    for &s in &a.samples {
        let settings = trisort_bake::Settings {
            fps: a.fps,
            record: RecordSettings {
                glass_opacity: a.glass_opacity,
                ..RecordSettings::new(a.size, s)
            },
            merge: MergeOptions {
                bridge: a.bridge,
                ..MergeOptions::default()
            },
            ..trisort_bake::Settings::new(&a.scene, a.path.as_str())
        };
        let mut console = crate::common::Console::new();
        bakes.push(bake_for(
            gpu,
            working,
            &settings,
            &a.out,
            &mut console,
            &say,
        )?);
    }
    Ok(bakes)
}

/// Writes bench.json, bench.csv, the plots and bench.md to --out, and prints the JSON or
/// the Markdown table.
fn write_table_report(
    a: &BenchArgs,
    run: &TableRun<'_>,
    bakes: &[BakeRun],
    groups: &[GroupReport],
) -> Result<()> {
    let value = report_json(run, bakes, groups);
    write_outputs(&a.out, &value, groups, bakes)?;
    let md = markdown(&value, groups, bakes);
    trisort_format::container::write_bytes_atomic(&a.out.join("bench.md"), md.as_bytes())?;
    if a.json {
        print_json(&value);
    } else {
        print!("{md}");
        println!("wrote {}", a.out.display());
    }
    Ok(())
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
    working: &trisort_bake::Working,
    frames: Vec<u32>,
) -> Result<ExitCode> {
    use trisort_bench::sweep;
    let mut config = sweep::SweepConfig::new(a.size, a.samples[0]);
    config.glass_opacity = a.glass_opacity;
    config.frames = frames;
    if let Some(list) = &a.sweep_factors {
        config.factors = sweep::Factor::parse_list(list)?;
    }
    let report = sweep::run(gpu, working, &config, &a.out, &|m| say(m))?;
    if a.json {
        print_json(&serde_json::to_value(&report)?);
    } else {
        print!("{}", sweep::to_csv(&report.points));
        println!("wrote {}", a.out.display());
    }
    Ok(ExitCode::SUCCESS)
}
