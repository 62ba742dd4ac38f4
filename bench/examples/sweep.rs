//! The speed/accuracy sweep without the CLI:
//!
//! ```text
//! cargo run --release -p trisort-bench --example sweep -- SCENE PATH SIZE FRAMES OUT [FACTORS]
//! ```
//!
//! `SCENE`: a glTF file or `demo[:TRIANGLES]`; `PATH`: a path spec (`demo`, `orbit:…`, a TOML
//! file, `gltf`); `SIZE`: playback `WxH` or `WxHxS` with S samples (default 4); `FRAMES`:
//! frames to compare, `a..b` (half-open), `a,b,c` or `all`; `OUT`: output folder; `FACTORS`:
//! comma-separated factor names (default all). Prints the table as it ends.

use std::process::ExitCode;

use trisort_bench::sweep::{run, Factor, SweepConfig};

fn usage() -> ExitCode {
    eprintln!("usage: sweep SCENE PATH WxH[xS] FRAMES OUT [FACTORS]");
    ExitCode::from(2)
}

fn parse_frames(s: &str) -> Option<Vec<u32>> {
    if s == "all" {
        return Some(Vec::new());
    }
    if let Some((a, b)) = s.split_once("..") {
        let (a, b): (u32, u32) = (a.parse().ok()?, b.parse().ok()?);
        return Some((a..b).collect());
    }
    s.split(',').map(|x| x.trim().parse().ok()).collect()
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 5 || args.len() > 6 {
        return usage();
    }
    // The scene as the default settings record it (crossing triangles split), as `trisort
    // bench --sweep` sees it.
    let settings = trisort_format::RecordSettings::default();
    let paths = [args[1].clone()];
    let working = match trisort_bake::Working::load(&args[0], &paths, 30.0, None, &settings) {
        Ok(w) => w,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let dims: Vec<u32> = match args[2].split('x').map(str::parse).collect() {
        Ok(d) => d,
        Err(_) => return usage(),
    };
    let (size, samples) = match dims[..] {
        [w, h] => ((w, h), 4),
        [w, h, s] => ((w, h), s),
        _ => return usage(),
    };
    let Some(frames) = parse_frames(&args[3]) else {
        return usage();
    };
    let factors = match Factor::parse_list(args.get(5).map_or("all", |s| s.as_str())) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("{e}");
            return usage();
        }
    };
    let config = SweepConfig {
        frames,
        factors,
        ..SweepConfig::new(size, samples)
    };
    let gpu = match trisort_gpu::Gpu::new() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let t = std::time::Instant::now();
    let report = match run(
        &gpu,
        &working,
        &config,
        std::path::Path::new(&args[4]),
        &|s| eprintln!("{s}"),
    ) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("sweep failed: {e}");
            return ExitCode::FAILURE;
        }
    };
    println!(
        "{} triangles, {} frames, playback {}x{} {}x, frames compared {:?}, on {}; default merge {}; sweep took {:.0} s",
        report.scene_triangles,
        report.path_frames,
        size.0,
        size.1,
        samples,
        report.frames,
        report.device,
        report.default_merge,
        t.elapsed().as_secs_f64()
    );
    println!(
        "| factor | value | record s | merge s | bake s | baked KiB | index tris | |G| | unordered | draws mean | draws max | play ms mean | play ms max | wall ms | px differing | max diff | FLIP |"
    );
    println!("|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|");
    for p in &report.points {
        println!(
            "| {} | {}{} | {:.2} | {:.2} | {:.2} | {:.0} | {} | {} | {} | {:.1} | {} | {:.2} | {:.2} | {:.1} | {} ({:.3} %) | {} | {:.4} |",
            p.factor,
            p.value,
            if p.is_default { " *" } else { "" },
            p.record_seconds,
            p.merge_seconds,
            p.bake_seconds,
            p.baked_bytes as f64 / 1024.0,
            p.index_triangles,
            p.unique_visible,
            p.unordered_samples,
            p.draws_per_frame_mean,
            p.draws_per_frame_max,
            p.play_ms_mean,
            p.play_ms_max,
            p.wall_ms_mean,
            p.pixels_differing,
            p.pixels_differing_fraction * 100.0,
            p.max_channel_diff,
            p.flip_mean
        );
    }
    ExitCode::SUCCESS
}
