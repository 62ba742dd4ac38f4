//! Cells: copies of triangles, the cell (i, j) each lives in, its place in the layout, and the
//! per-cell constraint graph (the union over the cell's frames of what rule 3 demands of the
//! cell's copies).

use rayon::prelude::*;

use crate::graph::FrameGraph;
use crate::strategy::{cell_key, Layout, Strategy};

/// A copy of G-local triangle `t`, drawn in frames `first..=last` (cell (first, last)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) struct Copy {
    /// G-local triangle.
    pub t: u32,
    /// First frame (row i), global.
    pub first: u32,
    /// Last frame (column j), global.
    pub last: u32,
}

/// The layout order of the cells of one segment (frames `start..start + len`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CellOrder {
    pub strategy: Strategy,
    pub layout: Layout,
    pub start: u32,
    pub len: u32,
}

impl CellOrder {
    /// Sort key of cell (first, last) (global frames).
    pub fn key(&self, first: u32, last: u32) -> u64 {
        cell_key(
            self.strategy,
            self.layout,
            self.len,
            first - self.start,
            last - self.start,
        )
    }
}

/// Marks "no copy" / "no cell".
pub(crate) const NONE: u32 = u32::MAX;

/// Which copy is drawn at every vertex of every frame graph of a segment: a dense table
/// (one entry per vertex of each frame's graph), updated in place as copies are split, so
/// that a round of the splitter reads it in O(1) per vertex and rewrites only what changed.
pub(crate) struct CopyTable {
    /// First frame of the segment.
    start: u32,
    /// Per frame of the segment (relative), the offset of its vertices in `at`.
    frame_off: Vec<usize>,
    /// Copy drawn at (frame, local vertex), or [`NONE`].
    at: Vec<u32>,
    /// Per G-local triangle, the range of `slots` holding its vertices.
    tri_off: Vec<u32>,
    /// `(frame, index into at)` of every vertex, grouped by triangle, by frame.
    slots: Vec<(u32, u32)>,
}

impl CopyTable {
    /// Indexes the vertices of the frames `seg` (triangles below `triangles`) and marks
    /// where each of `copies` is drawn. O(Σ vertices + Σ copy spans).
    pub fn new(
        graphs: &[FrameGraph],
        seg: std::ops::Range<u32>,
        triangles: usize,
        copies: &[Copy],
    ) -> CopyTable {
        let frames = &graphs[seg.start as usize..seg.end as usize];
        let mut frame_off = Vec::with_capacity(frames.len() + 1);
        let mut total = 0usize;
        let mut count = vec![0u32; triangles + 1];
        for fg in frames {
            frame_off.push(total);
            total += fg.nodes.len();
            for &t in &fg.nodes {
                count[t as usize + 1] += 1;
            }
        }
        frame_off.push(total);
        for k in 1..count.len() {
            count[k] += count[k - 1];
        }
        let tri_off = count.clone();
        let mut slots = vec![(0u32, 0u32); total];
        for (r, fg) in frames.iter().enumerate() {
            for (v, &t) in fg.nodes.iter().enumerate() {
                let p = &mut count[t as usize];
                let at = u32::try_from(frame_off[r] + v)
                    .expect("vertex-frames per segment are checked by `limits::check_segments`");
                slots[*p as usize] = (seg.start + r as u32, at);
                *p += 1;
            }
        }
        let mut table = CopyTable {
            start: seg.start,
            frame_off,
            at: vec![NONE; total],
            tri_off,
            slots,
        };
        for (k, c) in copies.iter().enumerate() {
            table.set(c.t, c.first, c.last, k as u32);
        }
        table
    }

    /// Marks `copy` (or [`NONE`]) as drawn at every vertex of triangle `t` in frames
    /// `first..=last`. O(log + frames of t in the range).
    pub fn set(&mut self, t: u32, first: u32, last: u32, copy: u32) {
        let all =
            &self.slots[self.tri_off[t as usize] as usize..self.tri_off[t as usize + 1] as usize];
        let a = all.partition_point(|&(f, _)| f < first);
        for &(f, i) in &all[a..] {
            if f > last {
                break;
            }
            self.at[i as usize] = copy;
        }
    }

    /// The copy drawn at each vertex of frame `f`'s graph ([`NONE`] where none is).
    pub fn frame(&self, f: u32) -> &[u32] {
        let r = (f - self.start) as usize;
        &self.at[self.frame_off[r]..self.frame_off[r + 1]]
    }
}

/// A vertex of a cell's constraint graph: a copy, or a triangle not drawn at one frame
/// (reachability passes through undrawn triangles: rule 3 orders drawn a before drawn b
/// wherever b is reachable from a in E_f through any triangles, drawn or not).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) struct NodeRef(u64);

impl NodeRef {
    const VIRTUAL: u64 = 1 << 63;

    /// A copy.
    pub fn copy(k: u32) -> NodeRef {
        NodeRef(k as u64)
    }

    /// Triangle `t`, undrawn at frame `f`.
    pub fn undrawn(t: u32, f: u32) -> NodeRef {
        NodeRef(Self::VIRTUAL | (f as u64) << 32 | t as u64)
    }

    /// The copy, if this is one.
    pub fn as_copy(self) -> Option<u32> {
        (self.0 & Self::VIRTUAL == 0).then_some(self.0 as u32)
    }
}

/// An edge of a cell's constraint graph, demanded at `frame`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) struct CellEdge {
    pub cell: u32,
    pub from: NodeRef,
    pub to: NodeRef,
    pub frame: u32,
}

/// For every frame of `frames`, the constraint edges inside every tracked cell: for drawn
/// a, b in the same cell with b reachable from a in E_f* through undrawn triangles, the path
/// (through undrawn vertices, one per triangle and frame; undrawn vertices that lead back to
/// no copy of the cell are left out). `cell_of[k]` is copy k's tracked cell or [`NONE`]. Paths through drawn triangles of other cells are not followed: when no
/// inter-cell conflict is left they cannot return to the cell (its key would have to both
/// rise and fall). Sorted by cell, deterministic.
pub(crate) fn cell_edges(
    graphs: &[FrameGraph],
    frames: std::ops::Range<u32>,
    table: &CopyTable,
    cell_of: &[u32],
) -> Vec<CellEdge> {
    let per_frame: Vec<Vec<CellEdge>> = frames
        .into_par_iter()
        .map(|f| {
            let fg = &graphs[f as usize];
            let n = fg.nodes.len();
            let cop = table.frame(f);
            let cell = |v: usize| {
                if cop[v] == NONE {
                    NONE
                } else {
                    cell_of[cop[v] as usize]
                }
            };
            let mut groups: Vec<(u32, u32)> = (0..n)
                .filter(|&v| cell(v) != NONE)
                .map(|v| (cell(v), v as u32))
                .collect();
            groups.sort_unstable();
            let mut out = Vec::new();
            // Per vertex: the last cell whose search reached it (undrawn), and the last cell
            // it leads back to (undrawn vertices on a path between two of the cell's copies).
            let mut stamp = vec![NONE; n];
            let mut useful = vec![NONE; n];
            let mut pos = vec![0u32; n];
            for (p, &v) in fg.topo.iter().enumerate() {
                pos[v as usize] = p as u32;
            }
            let mut stack: Vec<u32> = Vec::new();
            let mut reached: Vec<u32> = Vec::new();
            let mut pairs: Vec<(u32, u32)> = Vec::new();
            for group in groups.chunk_by(|a, b| a.0 == b.0) {
                let c = group[0].0;
                reached.clear();
                pairs.clear();
                let mut visit = |v: u32, stack: &mut Vec<u32>| {
                    for &w in fg.successors(v) {
                        let wu = w as usize;
                        if cop[wu] != NONE {
                            if cell(wu) == c {
                                pairs.push((v, w));
                            }
                        } else {
                            pairs.push((v, w));
                            if stamp[wu] != c {
                                stamp[wu] = c;
                                stack.push(w);
                                reached.push(w);
                            }
                        }
                    }
                };
                for &(_, v) in group {
                    visit(v, &mut stack);
                }
                while let Some(h) = stack.pop() {
                    visit(h, &mut stack);
                }
                // Keep only undrawn vertices that lead back to the cell: the others end
                // outside it and constrain nothing in it (latest in topological order first).
                reached.sort_unstable_by_key(|&h| std::cmp::Reverse(pos[h as usize]));
                for &h in &reached {
                    let back = fg.successors(h).iter().any(|&w| {
                        let wu = w as usize;
                        if cop[wu] != NONE {
                            cell(wu) == c
                        } else {
                            useful[wu] == c
                        }
                    });
                    if back {
                        useful[h as usize] = c;
                    }
                }
                let node = |v: u32| {
                    if cop[v as usize] != NONE {
                        NodeRef::copy(cop[v as usize])
                    } else {
                        NodeRef::undrawn(fg.nodes[v as usize], f)
                    }
                };
                for &(v, w) in &pairs {
                    if cop[w as usize] != NONE || useful[w as usize] == c {
                        out.push(CellEdge {
                            cell: c,
                            from: node(v),
                            to: node(w),
                            frame: f,
                        });
                    }
                }
            }
            out
        })
        .collect();
    let mut all: Vec<CellEdge> = per_frame.into_iter().flatten().collect();
    all.par_sort_unstable();
    all
}

/// One cell's constraint graph in compressed form.
pub(crate) struct CellGraph {
    /// Vertices, sorted (copies first: plain copy ids sort before undrawn vertices).
    pub nodes: Vec<NodeRef>,
    /// Deduplicated edges `(from, to)` over local indices, sorted.
    pub edges: Vec<(u32, u32)>,
    /// For each edge, the frames that demand it (ascending).
    pub frames: Vec<Vec<u32>>,
}

impl CellGraph {
    /// Builds the graph of one cell from its edges (all with the same `cell`) and its copies.
    pub fn new(edges: &[CellEdge], copies: &[u32]) -> CellGraph {
        let mut nodes: Vec<NodeRef> = copies.iter().map(|&k| NodeRef::copy(k)).collect();
        nodes.extend(edges.iter().flat_map(|e| [e.from, e.to]));
        nodes.sort_unstable();
        nodes.dedup();
        let li = |r: NodeRef| nodes.binary_search(&r).expect("endpoint is a node") as u32;
        let mut triples: Vec<(u32, u32, u32)> = edges
            .iter()
            .map(|e| (li(e.from), li(e.to), e.frame))
            .collect();
        triples.sort_unstable();
        triples.dedup();
        let mut out_edges = Vec::new();
        let mut frames: Vec<Vec<u32>> = Vec::new();
        for g in triples.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
            out_edges.push((g[0].0, g[0].1));
            frames.push(g.iter().map(|x| x.2).collect());
        }
        CellGraph {
            nodes,
            edges: out_edges,
            frames,
        }
    }
}
