//! Benchmark (not a test): the merger on long chains and the cost of exact cycle breaking.
//!
//! `cargo run --release -p trisort-merger --example robustness_bench -- [PAIRS [N ...]]`
//!
//! 1. Merges `synth::hidden_chain(N, PAIRS)` (default 8 pairs; N = 4,096 … 32,768) with IBL
//!    compact and prints the time.
//! 2. Times `cycles::feedback_arc_set` on single strongly connected components: the
//!    20-edge component that keeps the most vertices after the exact reductions (13), random
//!    components of 20 and 24 edges (on ≤ 10 and ≤ 16 vertices), 30 edges on ≤ 20 (the subset
//!    programme's range), and 40, 48 and 64 edges on ≤ 24, 28 and 32 vertices (branch and
//!    bound's), with how many were solved exactly; the complete digraphs on 16, 20,
//!    21, 24 and 32 vertices, and a 50,000-vertex cycle.

use std::time::Instant;

use trisort_merger::cycles::feedback_arc_set;
use trisort_merger::synth::hidden_chain;
use trisort_merger::{merge, Choice, Layout, MergeOptions, Strategy};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let pairs: u32 = args.first().map_or(8, |s| s.parse().expect("pairs"));
    let mut sizes: Vec<u32> = args[1.min(args.len())..]
        .iter()
        .map(|s| s.parse().expect("a chain length"))
        .collect();
    if sizes.is_empty() {
        sizes = vec![4_096, 8_192, 16_384, 32_768];
    }
    let opts = MergeOptions {
        strategy: Choice::Only(Strategy::Ibl),
        layout: Choice::Only(Layout::Compact),
        ..MergeOptions::default()
    };
    for n in sizes {
        let rec = hidden_chain(n, pairs);
        let t = Instant::now();
        let baked = merge(std::slice::from_ref(&rec), &opts)
            .expect("merge")
            .lit(trisort_format::Environment::uniform(1.0));
        println!(
            "hidden chain {n}, {pairs} pairs: {:.3} s, {} index triangles",
            t.elapsed().as_secs_f64(),
            baked.stats.index_triangles
        );
    }
    cycle_breaking();
}

/// Times one call of `feedback_arc_set` (the best of 5) and prints it with the counts.
fn time(what: &str, n: usize, edges: &[(u32, u32, u32)]) {
    let mut best = f64::MAX;
    let mut set = None;
    for _ in 0..5 {
        let t = Instant::now();
        set = Some(feedback_arc_set(n, edges));
        best = best.min(t.elapsed().as_secs_f64());
    }
    let set = set.expect("timed");
    let weight: u64 = (0..edges.len())
        .filter(|&k| set.removed[k])
        .map(|k| edges[k].2 as u64)
        .sum();
    println!(
        "{what}: {:.3} ms, exact {}, heuristic {}, removed weight {weight}",
        best * 1e3,
        set.exact_components,
        set.heuristic_components
    );
}

fn cycle_breaking() {
    // A 13-cycle with 7 chords touching every vertex: no vertex has one edge in and one out,
    // so nothing contracts; 20 edges keep at most 13 vertices (n′ ≤ 2m/3).
    let mut worst: Vec<(u32, u32, u32)> = (0..13).map(|v| (v, (v + 1) % 13, 1 + v % 5)).collect();
    worst.extend(
        [(0, 6), (1, 7), (2, 8), (3, 9), (4, 10), (5, 11), (12, 3)].map(|(a, b)| (a, b, 3)),
    );
    time("20 edges, 13 vertices left", 13, &worst);
    for (m, n) in [
        (20usize, 10usize),
        (24, 16),
        (30, 20),
        (40, 24),
        (48, 28),
        (64, 32),
    ] {
        let (graphs, exact, total, max) = random_components(m, n, 1000);
        println!(
            "{graphs} random strongly connected components of {m} edges on ≤ {n} vertices: \
             {exact} exact, {:.3} ms mean, {:.3} ms max",
            total / graphs as f64 * 1e3,
            max * 1e3
        );
    }
    for n in [16u32, 20, 21, 24, 32] {
        let complete: Vec<(u32, u32, u32)> = (0..n)
            .flat_map(|a| {
                (0..n)
                    .filter(move |&b| b != a)
                    .map(move |b| (a, b, 1 + (a * 7 + b) % 9))
            })
            .collect();
        time(
            &format!("complete digraph on {n} vertices"),
            n as usize,
            &complete,
        );
    }
    let n = 50_000u32;
    let cycle: Vec<(u32, u32, u32)> = (0..n).map(|v| (v, (v + 1) % n, 2 + v % 7)).collect();
    time("cycle of 50,000 vertices", n as usize, &cycle);
}

/// Random strongly connected graphs of `m` edges on up to `n` vertices (a ring through the
/// vertices used plus random edges): (count, solved exactly, total seconds, max seconds).
fn random_components(m: usize, n: usize, count: usize) -> (usize, usize, f64, f64) {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = |k: usize| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % k as u64) as u32
    };
    let (mut total, mut max, mut exact) = (0.0f64, 0.0f64, 0);
    for _ in 0..count {
        let verts = 3 + next(n - 2) as usize;
        let mut edges: Vec<(u32, u32, u32)> = (0..verts as u32)
            .map(|v| (v, (v + 1) % verts as u32, 1 + next(9)))
            .collect();
        while edges.len() < m {
            let (a, b) = (next(verts), next(verts));
            if a != b {
                edges.push((a, b, 1 + next(9)));
            }
        }
        let t = Instant::now();
        let set = feedback_arc_set(verts, &edges);
        let s = t.elapsed().as_secs_f64();
        if m <= 30 {
            assert_eq!(set.heuristic_components, 0, "{m} edges are solved exactly");
        }
        exact += (set.heuristic_components == 0) as usize;
        total += s;
        max = max.max(s);
    }
    (count, exact, total, max)
}
