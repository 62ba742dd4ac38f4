//! `trisort demo`: bake and play the built-in procedural car with its default path.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use trisort_format::{Baked, RecordSettings, Recording};
use trisort_player::headless::{HeadlessConfig, RenderedFrame};
use trisort_reference::frames::ImageReport;
use trisort_verify::GraphReport;

use crate::cmd::play::play_frames;
use crate::common::parse_size;

/// Arguments of `demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Where to write the baked file, its recording and the PNG frames.
    #[arg(long, default_value = "demo-out")]
    out_dir: PathBuf,
    /// Triangles of the procedural car (about 10 000 to 5 000 000).
    #[arg(long)]
    triangles: Option<u32>,
    /// Also write the car as glTF binary to this file.
    #[arg(long)]
    export_scene: Option<PathBuf>,
    /// Recording and playback size.
    #[arg(long, default_value = "256x256", value_parser = parse_size)]
    size: (u32, u32),
    /// MSAA samples.
    #[arg(long, default_value_t = RecordSettings::DEFAULT_SAMPLES)]
    samples: u32,
    /// Opacity at which the car's glass is recorded and played (0: invisible, as `bake`
    /// defaults to; the demo shows its windows, and what is sorted behind them).
    #[arg(long, default_value_t = DEMO_GLASS_OPACITY)]
    glass_opacity: f32,
}

/// The demo's default glass opacity: visibly tinted glass, the seats seen through it.
pub const DEMO_GLASS_OPACITY: f32 = 0.35;

pub fn run(a: DemoArgs) -> Result<ExitCode> {
    let t0 = Instant::now();
    let settings = RecordSettings {
        glass_opacity: a.glass_opacity,
        ..RecordSettings::new(a.size, a.samples)
    };
    settings.validate()?;
    let working = demo_working(&a, &settings)?;
    let bake_settings = trisort_bake::Settings {
        fps: working.timeline.fps,
        record: settings,
        ..trisort_bake::Settings::new(format!("demo:{}", demo_triangles(&a)), "demo")
    };
    let gpu = crate::common::open_gpu()?;
    println!("device: {}", gpu.describe());
    let baked_path = a.out_dir.join("demo.baked");
    let environment = bake_settings.light.load()?;
    let done = trisort_bake::bake(
        &gpu,
        &working,
        &bake_settings,
        environment,
        &baked_path,
        &mut crate::common::Console::new(),
    )?;
    let scene = &working.scene;
    let trisort_bake::Baking {
        recording: rec,
        baked,
        record_seconds: record_s,
        merge_seconds: merge_s,
        recording_reused: reused,
        textures: _,
    } = done;
    let report = trisort_verify::check_graph(std::slice::from_ref(&rec), &baked);
    let frames_dir = a.out_dir.join("frames");
    let t_play = Instant::now();
    let played = play_frames(
        &gpu,
        &baked,
        &HeadlessConfig::recorded(&baked),
        0..baked.frames.len() as u32,
        Some(&frames_dir),
    )?;
    let play_s = t_play.elapsed().as_secs_f64();
    let t_images = Instant::now();
    let images = verify_demo_images(&gpu, &baked, &scene.geometry, &rec)?;
    let images_s = t_images.elapsed().as_secs_f64();
    print_bake_figures(&baked, &rec, &played, play_s);
    print_verdicts(&report, &images);
    let record = if reused { "record (reused)" } else { "record" };
    println!("times:                  {record} {record_s:.1} s, merge {merge_s:.2} s, play {play_s:.1} s, verify images {images_s:.1} s, total {:.1} s", t0.elapsed().as_secs_f64());
    println!(
        "wrote {} and {} PNG frames in {}",
        baked_path.display(),
        played.len(),
        frames_dir.display()
    );
    Ok(if report.ok && images.ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(crate::cmd::verify::VERIFY_FAILED)
    })
}

/// The procedural car and its default path, split as `settings` record it; writes
/// `--export-scene` and prints what the car holds.
/// The car's triangles (`--triangles`, else the default): the demo bakes `demo:N`.
fn demo_triangles(a: &DemoArgs) -> u32 {
    a.triangles
        .unwrap_or(trisort_scene::demo_car::DEFAULT_TRIANGLES)
}

fn demo_working(a: &DemoArgs, settings: &RecordSettings) -> Result<trisort_bake::Working> {
    let mut scene = trisort_scene::demo_car::demo_car(demo_triangles(a));
    let path = trisort_paths::demo_default(&scene);
    std::fs::create_dir_all(&a.out_dir)?;
    if let Some(p) = &a.export_scene {
        trisort_scene::export::export_glb(&scene, p)?;
        println!("wrote {}", p.display());
    }
    println!(
        "demo car: {} triangles, {} nodes, {} materials, glass at opacity {}; path: {} frames (orbit, driver door opens and closes)",
        scene.stats.triangles,
        scene.geometry.nodes.len(),
        scene.geometry.materials.len(),
        a.glass_opacity,
        path.frames.len()
    );
    let t_split = Instant::now();
    let split =
        trisort_bake::working_scene(&mut scene, "demo", &path.frames, "the demo path", settings)?;
    let working = trisort_bake::Working::whole(scene, path, split, t_split.elapsed().as_secs_f64());
    if let Some(line) = working.split_summary() {
        eprintln!("trisort: {line}");
    }
    Ok(working)
}

/// Every frame the demo played, checked in blend mode against the exact reference.
fn verify_demo_images(
    gpu: &trisort_gpu::Gpu,
    baked: &Baked,
    geometry: &trisort_format::Geometry,
    rec: &Recording,
) -> Result<ImageReport> {
    let what = trisort_reference::frames::FramesToVerify {
        baked,
        geometry,
        check: trisort_reference::ImageCheck::recorded(baked, trisort_player::Mode::Blend),
        recordings: std::slice::from_ref(rec),
        frames: 0..baked.frames.len() as u32,
        source: trisort_reference::frames::Frames::Play,
    };
    Ok(trisort_reference::frames::verify_images(gpu, what, |_| {
        Ok(())
    })?)
}

/// The bake's figures: frames, raster profile, |G|, index size, draws and time per frame.
fn print_bake_figures(baked: &Baked, rec: &Recording, played: &[RenderedFrame], play_s: f64) {
    let s = &baked.stats;
    let gpu_ms: Vec<f64> = played.iter().filter_map(|f| f.gpu_ms).collect();
    println!("frames:                 {}", baked.frames.len());
    println!(
        "raster profile:         {}",
        trisort_bake::figures::profile_summary(&baked.settings)
    );
    println!(
        "|G| (visible at least once): {} of {} triangles",
        s.unique_visible, rec.scene_triangles
    );
    println!("Σ|V_f| (per-frame lists):    {}", s.source_triangles);
    println!(
        "index triangles:        {} ({:.2} × |G|), strategy {} / layout {}",
        s.index_triangles,
        s.index_triangles as f64 / s.unique_visible.max(1) as f64,
        baked.merge.strategy,
        baked.merge.layout
    );
    println!(
        "draws per frame:        {:.1} mean, {} max (one multi-draw-indirect call per frame)",
        s.draws_per_frame_mean, s.draws_per_frame_max
    );
    println!(
        "drawn but not visible:  {:.0} triangles per frame",
        s.drawn_not_visible_mean
    );
    println!("unordered samples:      {}", s.unordered_samples);
    if gpu_ms.is_empty() {
        println!(
            "ms per frame:           {:.2} wall (no GPU timestamps on this adapter)",
            1000.0 * play_s / played.len().max(1) as f64
        );
    } else {
        println!(
            "ms per frame:           {:.3} GPU mean, {:.3} max",
            gpu_ms.iter().sum::<f64>() / gpu_ms.len() as f64,
            gpu_ms.iter().cloned().fold(0.0, f64::max)
        );
    }
}

/// The two checks' verdicts: the graph rules and the images against the exact reference.
fn print_verdicts(report: &GraphReport, images: &ImageReport) {
    println!(
        "graph rules (verify):   {}",
        if report.ok {
            "all frames OK".to_string()
        } else {
            format!("FAILED: {:?}", report.problems)
        }
    );
    let worst = |f: fn(&trisort_reference::FrameImageReport) -> u8| {
        images.frames.iter().map(f).max().unwrap_or(0)
    };
    println!(
        "images (verify, blend): {}: {} frames against the exact reference, max channel diff {}/255 ({}/255 on ordered pixels), {} unordered samples",
        if images.ok { "all frames OK" } else { "FAILED" },
        images.frames.len(),
        worst(|f| f.comparison.max_channel_diff),
        worst(|f| f.comparison.max_channel_diff_ordered),
        images.frames.iter().map(|f| f.unordered_samples).sum::<u64>()
    );
}
