//! Recorder benchmark (numbers for BENCHMARKS.md, not a test).
//!
//! ```sh
//! cargo run --release -p trisort-recorder --example bench_record -- SCENE PATH SIZE SAMPLES STRIDE [compare|costs|record|peel]
//! ```
//!
//! Records every STRIDE-th frame of the path (a sample of its frames: G then comes from those
//! frames only), and prints seconds per frame of each phase, peel passes per frame, bytes
//! read back per frame, peak memory, and a peel pass's cost relative to a plain pass over the
//! same triangles, measured in the same run. With `compare`, first the same by depth peeling
//! (`Internals::peel`: one pass per layer, the recorder until 2026-12-02), then as shipped (one
//! capture pass a frame where the device can), in one process, and checks that both
//! recordings are identical. With `costs`, only the pass costs (no recording); with `record`
//! or `peel`, one recording as shipped or by peeling and its peak memory (no pass costs).

use std::time::Instant;

use trisort_format::Recording;
use trisort_format::{Phase, RecordSettings};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Gpu;
use trisort_recorder::{
    bench::pass_cost, capture_counters, readback_counters, record, Internals, RecordJob,
};

fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// CPU seconds (user + system, every thread: llvmpipe renders on worker threads) of this
/// process so far; less sensitive than wall time to other processes sharing the cores.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // After the command name (which may hold spaces): utime and stime are the 12th and 13th
    // fields, in clock ticks (100 a second on Linux).
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|v| v.parse().unwrap_or(f64::NAN))
        .collect();
    if f.len() < 13 {
        return f64::NAN;
    }
    (f[11] + f[12]) / 100.0
}

/// Passes drawn (peel layers and capture passes) and bytes read back by this process so far.
fn counters() -> (u64, u64) {
    let (layers, bytes) = readback_counters();
    let c = capture_counters();
    (layers + c[0], bytes + c[3])
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let compare = args.len() == 7 && args[6] == "compare";
    let mode = args.get(6).map_or("", |m| m.as_str());
    let only_costs = mode == "costs";
    if args.len() > 7 || !["", "compare", "costs", "record", "peel"].contains(&mode) {
        eprintln!("usage: bench_record SCENE PATH SIZE SAMPLES STRIDE [compare|costs|record|peel]");
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
        internals: Default::default(),
    };
    println!("device: {}", gpu.describe());
    println!("scene: {} ({} triangles), path {} ({} frames, every {stride}th: {} recorded), {size}x{size} at {samples}x", scene.name, scene.geometry.triangles.len(), args[2], timeline.frames.len(), frames.len());
    let view = View {
        width: size,
        height: size,
        samples,
        glass_opacity: 0.0,
    };
    let peel = Internals {
        peel: true,
        ..Internals::default()
    };
    let run = |internals: Internals| {
        let job = RecordJob {
            internals,
            ..job.clone()
        };
        let mut last = (Instant::now(), counters(), cpu_seconds());
        // Per frame of each phase: wall seconds, layers peeled (including the last, empty,
        // one), bytes read back, CPU seconds.
        let (mut p1, mut p2) = (vec![], vec![]);
        let t0 = Instant::now();
        let rec = record(&gpu, &job, None, |p| {
            let now = (Instant::now(), counters(), cpu_seconds());
            let d = (
                (now.0 - last.0).as_secs_f64(),
                (now.1 .0 - last.1 .0) as f64,
                (now.1 .1 - last.1 .1) as f64,
                now.2 - last.2,
            );
            last = now;
            if p.phase == 1 {
                p1.push(d)
            } else {
                p2.push(d)
            }
        })
        .expect("record");
        let total = t0.elapsed().as_secs_f64();
        report(&rec, &p1, &p2, total, scene.geometry.triangles.len());
        rec
    };
    if only_costs {
        // Only the pass costs below.
    } else if mode == "record" || mode == "peel" {
        // One recording (as shipped, or by peeling), no pass costs: the peak memory is the
        // recording's.
        if mode == "peel" {
            run(peel);
        } else {
            run(Internals::default());
        }
        println!("peak RSS {:.0} MiB", peak_rss_mib());
        return;
    } else if compare {
        println!("\nbefore: depth peeling, one pass a layer");
        let before = run(peel);
        println!("\nafter: one capture pass a frame");
        let after = run(Internals::default());
        let bytes = |r: &Recording| postcard::to_stdvec(r).expect("serialises");
        let same = bytes(&before) == bytes(&after);
        println!("\nrecordings identical: {same}");
        if !same {
            std::process::exit(1);
        }
    } else {
        run(Internals::default());
    }
    println!("\npass costs (medians of 5 interleaved repeats):");
    for f in [0u32, (frames.len() / 2) as u32] {
        let c = pass_cost(&gpu, &scene.geometry, &frames, view, f, 5).expect("pass cost");
        println!(
            "frame {f}: peel layer {:.1} ms (render {:.1} ms + gather/readback), plain pass {:.1} ms: render ratio {:.2}x, with readback {:.2}x",
            c.peel_ms, c.peel_render_ms, c.plain_ms, c.peel_render_ms / c.plain_ms, c.peel_ms / c.plain_ms
        );
        match (c.capture_render_ms, c.capture_ms) {
            (Some(render), Some(all)) => println!(
                "frame {f}: capture pass {render:.1} ms ({:.2}x plain), with readback and sorting {all:.1} ms ({:.2}x plain)",
                render / c.plain_ms,
                all / c.plain_ms
            ),
            _ => println!("frame {f}: this device cannot capture"),
        }
    }
    println!("peak RSS {:.0} MiB", peak_rss_mib());
}

/// One frame: wall seconds, layers peeled, bytes read back, CPU seconds.
type FrameCost = (f64, f64, f64, f64);

/// Prints the per-phase table: `p1`, `p2` hold one [`FrameCost`] per frame.
fn report(rec: &Recording, p1: &[FrameCost], p2: &[FrameCost], total: f64, tris: usize) {
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let max = |v: &[f64]| v.iter().cloned().fold(0.0, f64::max);
    let col = |v: &[FrameCost], k: usize| -> Vec<f64> {
        v.iter().map(|d| [d.0, d.1, d.2, d.3][k]).collect()
    };
    let l1: Vec<f64> = rec.frames.iter().map(|f| f.layers[0] as f64).collect();
    let l2: Vec<f64> = rec.frames.iter().map(|f| f.layers[1] as f64).collect();
    let vis: Vec<f64> = rec.frames.iter().map(|f| f.visible.len() as f64).collect();
    println!("| phase | s/frame mean | s/frame max | CPU s/frame mean | peel passes/frame mean | max | layers read back/frame | MiB read back/frame |");
    println!("|---|---|---|---|---|---|---|---|");
    for (name, p, l) in [
        ("1 visibility (all triangles, until saturated)", p1, &l1),
        ("2 graphs (G only, complete)", p2, &l2),
    ] {
        println!(
            "| {name} | {:.3} | {:.3} | {:.3} | {:.1} | {} | {:.1} | {:.1} |",
            mean(&col(p, 0)),
            max(&col(p, 0)),
            mean(&col(p, 3)),
            mean(l),
            max(l),
            mean(&col(p, 1)),
            mean(&col(p, 2)) / (1 << 20) as f64
        );
    }
    println!(
        "total {:.1} s; |G| = {} ({:.1} % of the scene); |V_f| mean {:.0}",
        total,
        rec.unique_visible.len(),
        100.0 * rec.unique_visible.len() as f64 / tris as f64,
        mean(&vis),
    );
}
