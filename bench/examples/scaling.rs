//! The BENCHMARKS scaling run:
//!
//! ```sh
//! cargo run --release -p trisort-bench --example scaling -- triangles|frames|quick OUTDIR [WxH]
//! ```
//!
//! `triangles` and `frames` run [`ScalingConfig::full`]'s triangle or frame axis and write
//! `OUTDIR/scaling-triangles.*` or `OUTDIR/scaling-frames.*`; `quick` runs both axes of
//! [`ScalingConfig::quick`]. `WxH` overrides the recording size (128x128 in `full`); the
//! outputs are then named `scaling-AXIS-WxH.*`. The table is printed to stdout, progress to
//! stderr.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use trisort_bench::scaling::{self, growth, ScalingConfig, ScalingRow};
use trisort_gpu::Gpu;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (axis, out, size) = match args.as_slice() {
        [axis, out] => (axis, out, None),
        [axis, out, size] => {
            let parsed = size
                .split_once('x')
                .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)));
            match parsed {
                Some(s) => (axis, out, Some(s)),
                None => {
                    eprintln!("scaling: bad size {size:?}: expected WIDTHxHEIGHT");
                    return ExitCode::from(2);
                }
            }
        }
        _ => {
            eprintln!("usage: scaling triangles|frames|quick OUTDIR [WIDTHxHEIGHT]");
            return ExitCode::from(2);
        }
    };
    let full = ScalingConfig {
        size: size.unwrap_or(ScalingConfig::full().size),
        ..ScalingConfig::full()
    };
    let quick = ScalingConfig {
        size: size.unwrap_or(ScalingConfig::quick().size),
        ..ScalingConfig::quick()
    };
    let name = match size {
        Some((w, h)) => format!("{axis}-{w}x{h}"),
        None => axis.clone(),
    };
    let gpu = match Gpu::new() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("scaling: {e}");
            return ExitCode::FAILURE;
        }
    };
    eprintln!("device: {}", gpu.describe());
    let t0 = Instant::now();
    let progress = |s: &str| eprintln!("[{:7.1} s] {s}", t0.elapsed().as_secs_f64());
    let result = match axis.as_str() {
        "triangles" => scaling::triangles(&gpu, &full, &progress),
        "frames" => scaling::frames(&gpu, &full, &progress),
        "quick" => scaling::triangles(&gpu, &quick, &progress).and_then(|mut rows| {
            rows.extend(scaling::frames(&gpu, &quick, &progress)?);
            Ok(rows)
        }),
        other => {
            eprintln!("scaling: unknown axis {other:?} (triangles, frames or quick)");
            return ExitCode::from(2);
        }
    };
    let rows = match result {
        Ok(r) => r,
        Err(e) => {
            eprintln!("scaling: {e}");
            return ExitCode::FAILURE;
        }
    };
    if let Err(e) = scaling::write_outputs(&rows, &PathBuf::from(out), &name) {
        eprintln!("scaling: {e}");
        return ExitCode::FAILURE;
    }
    print_table(&rows);
    eprintln!("total {:.1} s", t0.elapsed().as_secs_f64());
    ExitCode::SUCCESS
}

fn print_table(rows: &[ScalingRow]) {
    println!(
        "| axis | triangles | frames | \\|G\\| | record s (CPU s) | record s/frame | merge s (CPU s) | index/\\|G\\| | draws mean / max | layers | peak RSS MiB |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let cpu = |c: Option<f64>| c.map_or(String::new(), |c| format!(" ({c:.1})"));
    let num = |x: f64, d: usize| {
        if x.is_finite() {
            format!("{x:.d$}")
        } else {
            "—".into()
        }
    };
    for r in rows {
        println!(
            "| {} | {} | {} | {} | {}{} | {} | {}{} | {:.2} | {:.1} / {} | {:.1} | {} |",
            r.axis,
            r.triangles,
            r.frames,
            r.unique_visible,
            num(r.record_seconds, 2),
            cpu(r.record_cpu_seconds),
            num(r.record_seconds_per_frame, 3),
            num(r.merge_seconds, 2),
            cpu(r.merge_cpu_seconds),
            r.index_ratio(),
            r.draws_per_frame_mean,
            r.draws_per_frame_max,
            r.layers_mean,
            r.peak_rss_mib.map_or("—".into(), |m| format!("{m:.0}")),
        );
    }
    println!();
    println!("| axis | x | y | growth exponent (all points) | upper half | points |");
    println!("|---|---|---|---|---|---|");
    for g in growth(rows) {
        println!(
            "| {} | {} | {} | {:.2} | {} | {} |",
            g.axis,
            g.x,
            g.y,
            g.exponent,
            g.exponent_upper.map_or("—".into(), |e| format!("{e:.2}")),
            g.points
        );
    }
}
