//! Serialization of one cell: Kahn's algorithm by levels over the cell's (transitively
//! reduced) constraint graph, front to back (paper §5, Figure 8: a breadth-first traversal
//! from the roots), and inside a level the vertex-cache order of meshoptimizer
//! (`meshopt_optimizeVertexCache`, Forsyth's algorithm), since a level's triangles are
//! mutually unordered.

use std::collections::HashMap;

use crate::cells::{CellGraph, Copy};
use crate::cycles::csr;
use crate::reduction::transitive_reduction;

/// A serialized cell.
pub(crate) struct SerializedCell {
    /// Copy ids, front to back.
    pub order: Vec<u32>,
    /// Edges of the constraint graph.
    pub edges: u64,
    /// Edges after transitive reduction (equal to `edges` where the graph was too large).
    pub reduced_edges: u64,
}

/// Serializes one cell whose constraint graph `g` is acyclic. `triangles[t]` are the vertex
/// indices of G-local triangle t. Vertices of `g` that are not copies (undrawn triangles)
/// take part in the levels but are not emitted.
pub(crate) fn serialize_cell(
    g: &CellGraph,
    copies: &[Copy],
    triangles: &[[u32; 3]],
) -> SerializedCell {
    let n = g.nodes.len();
    let reduced = transitive_reduction(n, &g.edges);
    let edges: &[(u32, u32)] = reduced.as_deref().unwrap_or(&g.edges);
    let (off, succ) = csr(n, edges.iter().copied());
    let mut indeg = vec![0u32; n];
    for &(_, b) in edges {
        indeg[b as usize] += 1;
    }
    let mut level: Vec<u32> = (0..n as u32).filter(|&v| indeg[v as usize] == 0).collect();
    let mut order = Vec::new();
    let mut seen = 0;
    while !level.is_empty() {
        seen += level.len();
        let mut level_copies: Vec<u32> = level
            .iter()
            .filter_map(|&v| g.nodes[v as usize].as_copy())
            .collect();
        level_copies.sort_by_key(|&k| (copies[k as usize].t, k));
        order.extend(vertex_cache_order(&level_copies, copies, triangles));
        let mut next = Vec::new();
        for &v in &level {
            for &w in &succ[off[v as usize] as usize..off[v as usize + 1] as usize] {
                indeg[w as usize] -= 1;
                if indeg[w as usize] == 0 {
                    next.push(w);
                }
            }
        }
        next.sort_unstable();
        level = next;
    }
    assert_eq!(seen, n, "a final cell graph is acyclic");
    SerializedCell {
        order,
        edges: g.edges.len() as u64,
        reduced_edges: reduced.map_or(g.edges.len(), |r| r.len()) as u64,
    }
}

/// Reorders mutually unordered copies for the post-transform vertex cache.
fn vertex_cache_order(level: &[u32], copies: &[Copy], triangles: &[[u32; 3]]) -> Vec<u32> {
    if level.len() < 3 {
        return level.to_vec();
    }
    let mut local: HashMap<u32, u32> = HashMap::new();
    let mut indices = Vec::with_capacity(level.len() * 3);
    for &k in level {
        for v in triangles[copies[k as usize].t as usize] {
            let next = local.len() as u32;
            indices.push(*local.entry(v).or_insert(next));
        }
    }
    let optimized = meshopt::optimize_vertex_cache(&indices, local.len());
    // Map the reordered triangles back to copies (identical triangles are interchangeable).
    let mut by_tri: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
    for (p, tri) in indices.chunks_exact(3).enumerate().rev() {
        by_tri
            .entry([tri[0], tri[1], tri[2]])
            .or_default()
            .push(level[p]);
    }
    let mut out = Vec::with_capacity(level.len());
    for tri in optimized.chunks_exact(3) {
        match by_tri
            .get_mut(&[tri[0], tri[1], tri[2]])
            .and_then(|v| v.pop())
        {
            Some(k) => out.push(k),
            None => return level.to_vec(),
        }
    }
    if out.len() == level.len() {
        out
    } else {
        level.to_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The vertex-cache order of a level is a permutation of it that meshoptimizer actually
    /// produced (no fallback), here on a strip given in scrambled order.
    #[test]
    fn vertex_cache_order_is_a_permutation() {
        let triangles: Vec<[u32; 3]> = (0..40).map(|k| [k, k + 1, k + 2]).collect();
        let copies: Vec<Copy> = (0..40)
            .map(|t| Copy {
                t,
                first: 0,
                last: 0,
            })
            .collect();
        let level: Vec<u32> = (0..40).map(|k| (k * 17) % 40).collect();
        let out = vertex_cache_order(&level, &copies, &triangles);
        let mut sorted = out.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..40).collect::<Vec<u32>>());
        assert_ne!(out, level, "meshoptimizer reorders a scrambled strip");
    }

    /// Kahn levels put a vertex after all its predecessors, undrawn vertices included.
    #[test]
    fn levels_respect_edges_through_undrawn_vertices() {
        use crate::cells::{CellEdge, NodeRef};
        let triangles: Vec<[u32; 3]> = (0..3).map(|k| [k, k + 1, k + 2]).collect();
        let copies: Vec<Copy> = (0..3)
            .map(|t| Copy {
                t,
                first: 0,
                last: 1,
            })
            .collect();
        // 2 → (undrawn 7 at frame 0) → 0, and 0 → 1.
        let e = |from, to| CellEdge {
            cell: 0,
            from,
            to,
            frame: 0,
        };
        let edges = [
            e(NodeRef::copy(2), NodeRef::undrawn(7, 0)),
            e(NodeRef::undrawn(7, 0), NodeRef::copy(0)),
            e(NodeRef::copy(0), NodeRef::copy(1)),
        ];
        let g = CellGraph::new(&edges, &[0, 1, 2]);
        let s = serialize_cell(&g, &copies, &triangles);
        assert_eq!(s.order, vec![2, 0, 1]);
        assert_eq!((s.edges, s.reduced_edges), (3, 3));
    }
}
