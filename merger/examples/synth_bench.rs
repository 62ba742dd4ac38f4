//! Benchmark (not a test): merges synthetic turntable recordings with every strategy, layout
//! and seeding and prints the merge figures and times.
//!
//! `cargo run --release -p trisort-merger --example synth_bench -- [objects] [frames] [degrees] [segment] [lib|all] [samples] [transparent] [sides] [size]`

use std::time::Instant;

use trisort_merger::synth::{turntable, Turntable};
use trisort_merger::{merge, Bridge, Choice, Layout, MergeOptions, Seeding, Strategy};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |k: usize, d: f64| args.get(k).and_then(|s| s.parse().ok()).unwrap_or(d);
    let p = Turntable {
        objects: arg(0, 40.0) as u32,
        sides: arg(7, 32.0) as u32,
        frames: arg(1, 24.0) as u32,
        samples: arg(5, 512.0) as u32,
        degrees: arg(2, 90.0),
        transparent: arg(6, 0.3),
        size: arg(8, 1.0),
        ..Turntable::default()
    };
    let segment = args.get(3).and_then(|s| s.parse().ok());
    // One strategy (by name), or every one (`all` or nothing).
    let only: Option<Strategy> = args
        .get(4)
        .filter(|s| !s.is_empty() && *s != "all")
        .map(|s| s.parse().unwrap_or_else(|e| panic!("{e}")));
    let fast = std::env::var("SYNTH_BENCH_FAST").is_ok();
    let t0 = Instant::now();
    let rec = turntable(&p);
    let vis: usize = rec.frames.iter().map(|f| f.visible.len()).sum();
    println!(
        "turntable {p:?}: |G| = {}, sum |V_f| = {vis}, generated in {:.2} s",
        rec.unique_visible.len(),
        t0.elapsed().as_secs_f64()
    );
    println!("seeding  bridge  strategy layout  | index/|G| draws mean  max | drawn-not-vis unordered | seconds | cell edges -> reduced");
    let strategies: Vec<Strategy> = Strategy::ALL
        .into_iter()
        .filter(|&s| only.is_none_or(|o| o == s))
        .collect();
    let seedings: &[Seeding] = if fast {
        &[Seeding::Interval]
    } else {
        &[Seeding::Interval, Seeding::Paper]
    };
    let bridges: &[Bridge] = if fast {
        &[Bridge::Hidden]
    } else {
        &[Bridge::Hidden, Bridge::Ignored]
    };
    for &seeding in seedings {
        for &bridge in bridges {
            for &strategy in &strategies {
                for layout in Layout::ALL {
                    let opts = MergeOptions {
                        strategy: Choice::Only(strategy),
                        layout: Choice::Only(layout),
                        bridge,
                        seeding,
                        segment,
                        ..MergeOptions::default()
                    };
                    let t = Instant::now();
                    let b = merge(std::slice::from_ref(&rec), &opts)
                        .expect("merge")
                        .lit(trisort_format::Environment::uniform(1.0));
                    let secs = t.elapsed().as_secs_f64();
                    let s = &b.stats;
                    println!(
                        "{:8} {:7} {:8} {:7} | {:9.3} {:10.1} {:4} | {:13.1} {:9} | {:.3} | {} -> {}",
                        seeding,
                        bridge,
                        b.merge.strategy,
                        b.merge.layout,
                        s.index_triangles as f64 / s.unique_visible as f64,
                        s.draws_per_frame_mean,
                        s.draws_per_frame_max,
                        s.drawn_not_visible_mean,
                        s.unordered_samples,
                        secs,
                        s.cell_constraint_edges,
                        s.cell_constraint_edges_reduced
                    );
                }
            }
        }
    }
}
