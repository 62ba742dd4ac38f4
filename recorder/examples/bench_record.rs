//! Recorder benchmark (numbers for BENCHMARKS.md, not a test).
//!
//! ```sh
//! cargo run --release -p trisort-recorder --example bench_record -- SCENE PATH SIZE SAMPLES STRIDE
//! ```
//!
//! Records every STRIDE-th frame of the path (a sample of its frames: G then comes from those
//! frames only), and prints seconds per frame of each phase, peel passes per frame, peak
//! memory, and a peel pass's cost relative to a plain pass over the same triangles, measured
//! in the same run.

use std::time::Instant;

use trisort_format::{Phase, RecordSettings};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Gpu;
use trisort_recorder::{bench::pass_cost, record, RecordJob};

fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 6 {
        eprintln!("usage: bench_record SCENE PATH SIZE SAMPLES STRIDE");
        std::process::exit(2);
    }
    let scene = trisort_scene::load(std::path::Path::new(&args[1])).expect("scene");
    let timeline = trisort_paths::load(&args[2], &scene, &Default::default()).expect("path");
    let size: u32 = args[3].parse().expect("size");
    let samples: u32 = args[4].parse().expect("samples");
    let stride: usize = args[5].parse().expect("stride");
    let frames: Vec<_> = timeline.frames.iter().step_by(stride).cloned().collect();
    let gpu = Gpu::new().expect("gpu");
    let settings = RecordSettings {
        width: size,
        height: size,
        samples,
        ..Default::default()
    };
    let job = RecordJob {
        geometry: &scene.geometry,
        frames: &frames,
        scene_hash: scene.hash(),
        path_hash: [0; 32],
        settings,
        range: None,
        phase: Phase::Graphs,
        known_visible: None,
    };
    let mut last = Instant::now();
    let (mut p1, mut p2) = (vec![], vec![]);
    let t0 = Instant::now();
    let rec = record(&gpu, &job, None, |p| {
        let dt = last.elapsed().as_secs_f64();
        last = Instant::now();
        if p.phase == 1 {
            p1.push(dt)
        } else {
            p2.push(dt)
        }
    })
    .expect("record");
    let total = t0.elapsed().as_secs_f64();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let max = |v: &[f64]| v.iter().cloned().fold(0.0, f64::max);
    let l1: Vec<f64> = rec.frames.iter().map(|f| f.layers[0] as f64).collect();
    let l2: Vec<f64> = rec.frames.iter().map(|f| f.layers[1] as f64).collect();
    let vis: Vec<f64> = rec.frames.iter().map(|f| f.visible.len() as f64).collect();
    println!("device: {}", gpu.describe());
    println!("scene: {} ({} triangles), path {} ({} frames, every {stride}th: {} recorded), {size}x{size} at {samples}x", scene.name, scene.geometry.triangles.len(), args[2], timeline.frames.len(), frames.len());
    println!("| phase | s/frame mean | s/frame max | peel passes/frame mean | max |");
    println!("|---|---|---|---|---|");
    println!(
        "| 1 visibility (all triangles, until saturated) | {:.3} | {:.3} | {:.1} | {} |",
        mean(&p1),
        max(&p1),
        mean(&l1),
        max(&l1)
    );
    println!(
        "| 2 graphs (G only, complete) | {:.3} | {:.3} | {:.1} | {} |",
        mean(&p2),
        max(&p2),
        mean(&l2),
        max(&l2)
    );
    println!(
        "total {:.1} s; |G| = {} ({:.1} % of the scene); |V_f| mean {:.0}; peak RSS {:.0} MiB",
        total,
        rec.unique_visible.len(),
        100.0 * rec.unique_visible.len() as f64 / scene.geometry.triangles.len() as f64,
        mean(&vis),
        peak_rss_mib()
    );
    let view = View {
        width: size,
        height: size,
        samples,
        glass_opacity: 0.0,
    };
    for f in [0u32, (frames.len() / 2) as u32] {
        let c = pass_cost(&gpu, &scene.geometry, &frames, view, f, 5).expect("pass cost");
        println!(
            "frame {f}: peel layer {:.1} ms (render {:.1} ms + gather/readback), plain pass {:.1} ms: render ratio {:.2}x, with readback {:.2}x",
            c.peel_ms, c.peel_render_ms, c.plain_ms, c.peel_render_ms / c.plain_ms, c.peel_ms / c.plain_ms
        );
    }
}
