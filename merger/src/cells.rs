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

/// Finds the copy of a triangle drawn at a frame.
pub(crate) struct CopyLookup {
    /// `(t, first, copy)` sorted.
    entries: Vec<(u32, u32, u32)>,
}

impl CopyLookup {
    /// Indexes `copies`. O(C log C).
    pub fn new(copies: &[Copy]) -> CopyLookup {
        let mut entries: Vec<(u32, u32, u32)> = copies
            .iter()
            .enumerate()
            .map(|(k, c)| (c.t, c.first, k as u32))
            .collect();
        entries.sort_unstable();
        CopyLookup { entries }
    }

    /// The copy of `t` that spans frame `f`, or [`NONE`]. O(log C).
    pub fn at(&self, copies: &[Copy], t: u32, f: u32) -> u32 {
        let p = self.entries.partition_point(|&(a, b, _)| (a, b) <= (t, f));
        if p == 0 {
            return NONE;
        }
        let (a, _, k) = self.entries[p - 1];
        if a == t && copies[k as usize].last >= f {
            k
        } else {
            NONE
        }
    }
}

/// A vertex of a cell's constraint graph: a copy, or a triangle not drawn at one frame
/// (reachability passes through undrawn triangles, DESIGN rule 3).
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
/// (through undrawn vertices, one per triangle and frame). `cell_of[k]` is copy k's tracked
/// cell or [`NONE`]. Paths through drawn triangles of other cells are not followed: when no
/// inter-cell conflict is left they cannot return to the cell (its key would have to both
/// rise and fall). Sorted by cell, deterministic.
pub(crate) fn cell_edges(
    graphs: &[FrameGraph],
    frames: std::ops::Range<u32>,
    copies: &[Copy],
    lookup: &CopyLookup,
    cell_of: &[u32],
) -> Vec<CellEdge> {
    let per_frame: Vec<Vec<CellEdge>> = frames
        .into_par_iter()
        .map(|f| {
            let fg = &graphs[f as usize];
            let n = fg.nodes.len();
            let cop: Vec<u32> = fg.nodes.iter().map(|&t| lookup.at(copies, t, f)).collect();
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
            let mut stamp = vec![NONE; n];
            let mut stack: Vec<u32> = Vec::new();
            for group in groups.chunk_by(|a, b| a.0 == b.0) {
                let c = group[0].0;
                let mut visit =
                    |from: NodeRef, v: u32, stack: &mut Vec<u32>, out: &mut Vec<CellEdge>| {
                        for &w in fg.successors(v) {
                            let wu = w as usize;
                            if cop[wu] != NONE {
                                if cell(wu) == c {
                                    out.push(CellEdge {
                                        cell: c,
                                        from,
                                        to: NodeRef::copy(cop[wu]),
                                        frame: f,
                                    });
                                }
                            } else {
                                out.push(CellEdge {
                                    cell: c,
                                    from,
                                    to: NodeRef::undrawn(fg.nodes[wu], f),
                                    frame: f,
                                });
                                if stamp[wu] != c {
                                    stamp[wu] = c;
                                    stack.push(w);
                                }
                            }
                        }
                    };
                for &(_, v) in group {
                    visit(NodeRef::copy(cop[v as usize]), v, &mut stack, &mut out);
                }
                while let Some(h) = stack.pop() {
                    visit(
                        NodeRef::undrawn(fg.nodes[h as usize], f),
                        h,
                        &mut stack,
                        &mut out,
                    );
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
