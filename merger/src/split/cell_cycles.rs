//! Cell cycles: cycles in a multi-frame cell's union-over-frames constraint graph (the camera
//! turned around), found by Kahn's algorithm and a walk back through the left-over vertices,
//! each broken by splitting one multi-frame copy on it.

use std::ops::Range;

use rayon::prelude::*;

use super::Context;
use crate::cells::{cell_edges, CellGraph, Copy, CopyTable, NONE};
use crate::cycles::csr;

/// Cycles in the union-over-frames constraint graphs of the multi-frame cells: one split
/// `(copy, m)` (pieces `first..=m` and `m+1..=last`) per vertex-disjoint cycle found.
pub(super) fn find_cell_cycles(
    cx: &Context<'_>,
    seg: Range<u32>,
    copies: &[Copy],
    table: &CopyTable,
) -> Vec<(u32, u32)> {
    // Tracked cells: multi-frame cells with at least two copies.
    let mut cells: Vec<(u32, u32, u32)> = copies
        .iter()
        .enumerate()
        .filter(|(_, c)| c.first < c.last)
        .map(|(k, c)| (c.first, c.last, k as u32))
        .collect();
    cells.sort_unstable();
    let mut cell_of = vec![NONE; copies.len()];
    let mut members: Vec<Vec<u32>> = Vec::new();
    for g in cells.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
        if g.len() >= 2 {
            for &(_, _, k) in g {
                cell_of[k as usize] = members.len() as u32;
            }
            members.push(g.iter().map(|x| x.2).collect());
        }
    }
    if members.is_empty() {
        return Vec::new();
    }
    let edges = cell_edges(cx.graphs, seg, table, &cell_of);
    let groups: Vec<&[crate::cells::CellEdge]> = edges.chunk_by(|a, b| a.cell == b.cell).collect();
    let per_cell: Vec<Vec<(u32, u32)>> = groups
        .par_iter()
        .map(|g| {
            let graph = CellGraph::new(g, &members[g[0].cell as usize]);
            cycle_splits(&graph, copies)
        })
        .collect();
    per_cell.into_iter().flatten().collect()
}

/// Vertex-disjoint cycles of one cell graph and the split that breaks each.
fn cycle_splits(g: &CellGraph, copies: &[Copy]) -> Vec<(u32, u32)> {
    let n = g.nodes.len();
    let (off, succ) = csr(n, g.edges.iter().copied());
    let mut indeg = vec![0u32; n];
    for &(_, b) in &g.edges {
        indeg[b as usize] += 1;
    }
    let mut stack: Vec<u32> = (0..n as u32).filter(|&v| indeg[v as usize] == 0).collect();
    let mut done = vec![false; n];
    while let Some(v) = stack.pop() {
        done[v as usize] = true;
        for &w in &succ[off[v as usize] as usize..off[v as usize + 1] as usize] {
            indeg[w as usize] -= 1;
            if indeg[w as usize] == 0 {
                stack.push(w);
            }
        }
    }
    if done.iter().all(|&d| d) {
        return Vec::new();
    }
    // Incoming edges per vertex (edge ids), to walk back through left-over vertices.
    let (in_off, in_e) = csr(
        n,
        g.edges.iter().enumerate().map(|(e, &(_, b))| (b, e as u32)),
    );
    let mut used = vec![false; n];
    let mut out = Vec::new();
    let mut on_walk = vec![NONE; n];
    for start in 0..n {
        if done[start] || used[start] {
            continue;
        }
        // Walk predecessors until a vertex repeats; record the edge taken into each vertex.
        let mut walk: Vec<(u32, u32)> = Vec::new(); // (vertex, edge into it from the next)
        let mut v = start as u32;
        let cycle_from = loop {
            if on_walk[v as usize] != NONE {
                break Some(on_walk[v as usize] as usize);
            }
            let pred = in_e[in_off[v as usize] as usize..in_off[v as usize + 1] as usize]
                .iter()
                .copied()
                .find(|&e| {
                    let a = g.edges[e as usize].0 as usize;
                    !done[a] && !used[a]
                });
            let Some(e) = pred else { break None };
            on_walk[v as usize] = walk.len() as u32;
            walk.push((v, e));
            v = g.edges[e as usize].0;
        };
        for &(w, _) in &walk {
            on_walk[w as usize] = NONE;
            used[w as usize] = true;
        }
        let Some(from) = cycle_from else { continue };
        // walk[from..] is the cycle, backwards: walk[k].1 enters walk[k].0 from walk[k+1].0.
        let cyc = &walk[from..];
        let len = cyc.len();
        // For the vertex cyc[k]: its incoming edge is cyc[k].1, its outgoing edge is the one
        // entering cyc[k-1] (cyclically).
        let mut chosen: Option<(u32, u32)> = None;
        let mut fallback: Option<(u32, u32)> = None;
        let mut longest: Option<(u32, u32, u32)> = None;
        for k in 0..len {
            let Some(copy) = g.nodes[cyc[k].0 as usize].as_copy() else {
                continue;
            };
            let c = copies[copy as usize];
            if c.first == c.last {
                continue;
            }
            let s_in = &g.frames[cyc[k].1 as usize];
            let s_out = &g.frames[cyc[(k + len - 1) % len].1 as usize];
            let (in_lo, in_hi) = (s_in[0], *s_in.last().expect("an edge has a frame"));
            let (out_lo, out_hi) = (s_out[0], *s_out.last().expect("an edge has a frame"));
            let gap = if in_hi < out_lo {
                Some((in_hi, out_lo))
            } else if out_hi < in_lo {
                Some((out_hi, in_lo))
            } else {
                None
            };
            if let Some((lo, hi)) = gap {
                chosen = Some((copy, lo + (hi - lo - 1) / 2));
                break;
            }
            if fallback.is_none() {
                let a = s_in.iter().find(|f| s_out.binary_search(f).is_err());
                let b = s_out.iter().find(|f| s_in.binary_search(f).is_err());
                if let (Some(&a), Some(&b)) = (a, b) {
                    let (lo, hi) = (a.min(b), a.max(b));
                    fallback = Some((copy, lo + (hi - lo - 1) / 2));
                }
            }
            let span = c.last - c.first;
            if longest.is_none_or(|l| span > l.2) {
                longest = Some((copy, c.first + (span - 1) / 2, span));
            }
        }
        let split = chosen.or(fallback).or(longest.map(|l| (l.0, l.1)));
        if let Some(s) = split {
            out.push(s);
        }
    }
    out
}
