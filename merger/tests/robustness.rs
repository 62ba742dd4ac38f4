//! Regression tests for the merger's robustness on long chains: results only, never times (the
//! times are in `merger/BENCHMARKS.md` § Robustness).

use crate::merge;
use trisort_merger::cycles::feedback_arc_set;
use trisort_merger::synth::hidden_chain;
use trisort_merger::{Choice, Layout, MergeOptions, Strategy};
use trisort_verify::check_graph;

/// Copies joined back across a chain of 32,768 hidden triangles (8 pairs of swapping
/// triangles in front of it): each join's search visits the chain once per frame (it kept the
/// visited vertices in a `Vec` and took 3.3 s here, 0.9 s at half the length), and the bake
/// passes the validator. The chain is also a 32,768-vertex path for the cycle search, which
/// overflowed a rayon worker's stack when it recursed.
#[test]
fn rejoin_search_through_a_long_hidden_chain() {
    let (chain, pairs) = (32_768, 8);
    let rec = hidden_chain(chain, pairs);
    let opts = MergeOptions {
        strategy: Choice::Only(Strategy::Ibl),
        layout: Choice::Only(Layout::Compact),
        ..MergeOptions::default()
    };
    let baked = merge(std::slice::from_ref(&rec), &opts).expect("merge");
    let report = check_graph(std::slice::from_ref(&rec), &baked);
    assert!(report.ok, "{:?}", report.problems);
    // The chain is visible in one frame: one copy each; the pairs at most one per frame.
    let s = &baked.stats;
    assert!(
        s.index_triangles <= chain as u64 + 2 * pairs as u64 * 4,
        "{s:?}"
    );
}

/// A 50,000-vertex cycle is one strongly connected component: finding it recursively
/// (petgraph's `tarjan_scc`) overflows a rayon worker's 2 MiB stack; the iterative search
/// does not, and the lightest edge goes.
#[test]
fn a_fifty_thousand_vertex_cycle_fits_a_rayon_stack() {
    let n = 50_000u32;
    let lightest = 12_345;
    let edges: Vec<(u32, u32, u32)> = (0..n)
        .map(|v| (v, (v + 1) % n, if v == lightest { 1 } else { 2 + v % 7 }))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .stack_size(2 << 20)
        .build()
        .expect("a rayon pool");
    let removed = pool
        .install(|| feedback_arc_set(n as usize, &edges))
        .removed;
    let cut: Vec<usize> = (0..edges.len()).filter(|&k| removed[k]).collect();
    assert_eq!(cut, vec![lightest as usize]);
}
