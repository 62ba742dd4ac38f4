//! Benchmark (not a test): merges recording files (as `trisort record` writes them) with each
//! strategy × layout separately, optionally validates, and prints the figures and times.
//!
//! `cargo run --release -p trisort-merger --example merge_file -- REC... [--strategy S|all]
//! [--layout paper|compact|all] [--bridge hidden|ignored] [--seeding interval|paper]
//! [--segment N] [--auto] [--verify]`
//!
//! `--auto` also runs the library's own `auto` (every combination at once, as the CLI does).

use std::path::PathBuf;
use std::time::Instant;

use trisort_format::{FileKind, Recording};
use trisort_merger::{
    merge, Bridge, LayoutChoice, MergeOptions, Seeding, Strategy, StrategyChoice,
};

fn strategy_choice(s: Strategy) -> StrategyChoice {
    match s {
        Strategy::Lib => StrategyChoice::Lib,
        Strategy::Lbi => StrategyChoice::Lbi,
        Strategy::Ilb => StrategyChoice::Ilb,
        Strategy::Ibl => StrategyChoice::Ibl,
        Strategy::Bli => StrategyChoice::Bli,
        Strategy::Bil => StrategyChoice::Bil,
    }
}

fn main() {
    let mut files = Vec::new();
    let mut strategies: Vec<Strategy> = Strategy::ALL.to_vec();
    let mut layouts = vec![LayoutChoice::Paper, LayoutChoice::Compact];
    let mut base = MergeOptions::default();
    let (mut auto, mut verify) = (false, false);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().expect("option needs a value");
        match a.as_str() {
            "--strategy" => {
                let v = value();
                if v != "all" {
                    strategies = vec![Strategy::from_name(&v).expect("strategy name")];
                }
            }
            "--layout" => {
                layouts = match value().as_str() {
                    "paper" => vec![LayoutChoice::Paper],
                    "compact" => vec![LayoutChoice::Compact],
                    _ => vec![LayoutChoice::Paper, LayoutChoice::Compact],
                }
            }
            "--bridge" => {
                base.bridge = match value().as_str() {
                    "ignored" => Bridge::Ignored,
                    "visible" => Bridge::Visible,
                    _ => Bridge::Hidden,
                }
            }
            "--seeding" => {
                base.seeding = match value().as_str() {
                    "paper" => Seeding::Paper,
                    _ => Seeding::Interval,
                }
            }
            "--segment" => base.segment = Some(value().parse().expect("segment")),
            "--auto" => auto = true,
            "--verify" => verify = true,
            _ => files.push(PathBuf::from(a)),
        }
    }
    let t0 = Instant::now();
    let recs: Vec<Recording> = files
        .iter()
        .map(|f| trisort_format::read_file(FileKind::Recording, f).expect("read recording"))
        .collect();
    println!(
        "read {} recording(s) in {:.2} s",
        recs.len(),
        t0.elapsed().as_secs_f64()
    );
    println!("seeding  bridge  strategy layout  | index/|G| index  draws mean  max | drawn-not-vis unordered | seconds | valid");
    let mut runs: Vec<MergeOptions> = Vec::new();
    for &s in &strategies {
        for &l in &layouts {
            runs.push(MergeOptions {
                strategy: strategy_choice(s),
                layout: l,
                ..base
            });
        }
    }
    if auto {
        runs.push(MergeOptions {
            strategy: StrategyChoice::Auto,
            layout: LayoutChoice::Auto,
            ..base
        });
    }
    for opts in runs {
        let t = Instant::now();
        let b = merge(&recs, &opts).expect("merge");
        let secs = t.elapsed().as_secs_f64();
        let valid = if verify {
            let r = trisort_verify::check_graph(&recs, &b);
            if r.ok {
                "ok".to_string()
            } else {
                format!("FAIL {:?}", r.problems.first())
            }
        } else {
            "-".to_string()
        };
        let s = &b.stats;
        println!(
            "{:8} {:7} {:8} {:7} | {:9.3} {:6} {:10.1} {:4} | {:13.1} {:9} | {:7.2} | {}{}",
            b.merge.seeding,
            b.merge.bridge,
            b.merge.strategy,
            b.merge.layout,
            s.index_triangles as f64 / s.unique_visible as f64,
            s.index_triangles,
            s.draws_per_frame_mean,
            s.draws_per_frame_max,
            s.drawn_not_visible_mean,
            s.unordered_samples,
            secs,
            valid,
            if opts.strategy == StrategyChoice::Auto {
                " (auto)"
            } else {
                ""
            }
        );
    }
}
