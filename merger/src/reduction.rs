//! Transitive reduction of a directed acyclic graph (Aho, Garey, Ullman, "The transitive
//! reduction of a directed graph", SIAM J. Comput. 1(2), 1972).
//!
//! The merger applies it only to *final* cell graphs, whose vertex set no longer changes:
//! reducing earlier and then dropping a middle triangle (as the paper's violator removal does,
//! Figure 12) would lose the constraint it carried. Kahn levels, and so the serialized order,
//! are the same with and without it; what it gains is edges, which the merge statistics report.

/// Largest graph reduced (vertices); the reachability bitsets take V²/8 bytes.
pub const MAX_VERTICES: usize = 4096;

/// The transitive reduction of a DAG given as sorted, deduplicated `(from, to)` pairs over
/// `nodes` vertices: the subset of edges not implied by a longer path. Returns `None` for a
/// graph with more than [`MAX_VERTICES`] vertices, or one with a cycle. O(V·E / 64) time,
/// O(V² / 8) memory.
///
/// ```
/// use trisort_merger::reduction::transitive_reduction;
/// let r = transitive_reduction(3, &[(0, 1), (0, 2), (1, 2)]).unwrap();
/// assert_eq!(r, vec![(0, 1), (1, 2)]);
/// ```
pub fn transitive_reduction(nodes: usize, edges: &[(u32, u32)]) -> Option<Vec<(u32, u32)>> {
    if nodes > MAX_VERTICES {
        return None;
    }
    let (off, succ) = crate::cycles::csr(nodes, edges.iter().copied());
    let topo = crate::cycles::topological_order(&off, &succ)?;
    let mut pos = vec![0u32; nodes];
    for (p, &v) in topo.iter().enumerate() {
        pos[v as usize] = p as u32;
    }
    let words = nodes.div_ceil(64);
    let mut reach = vec![0u64; nodes * words];
    let mut keep = vec![false; edges.len()];
    // Edge ids per source, so the kept flags can be set.
    let (eoff, eids) = crate::cycles::csr(
        nodes,
        edges.iter().enumerate().map(|(e, &(a, _))| (a, e as u32)),
    );
    for &v in topo.iter().rev() {
        let v = v as usize;
        let mut out: Vec<u32> = eids[eoff[v] as usize..eoff[v + 1] as usize].to_vec();
        out.sort_by_key(|&e| pos[edges[e as usize].1 as usize]);
        let mut mine = vec![0u64; words];
        for e in out {
            let w = edges[e as usize].1 as usize;
            if mine[w / 64] >> (w % 64) & 1 == 1 {
                continue;
            }
            keep[e as usize] = true;
            mine[w / 64] |= 1 << (w % 64);
            for (m, r) in mine.iter_mut().zip(&reach[w * words..(w + 1) * words]) {
                *m |= r;
            }
        }
        reach[v * words..(v + 1) * words].copy_from_slice(&mine);
    }
    Some(
        edges
            .iter()
            .zip(&keep)
            .filter(|(_, &k)| k)
            .map(|(&e, _)| e)
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Reachability of every pair, by DFS.
    fn closure(n: usize, edges: &[(u32, u32)]) -> Vec<Vec<bool>> {
        (0..n)
            .map(|s| {
                let mut row = vec![false; n];
                let mut stack = vec![s];
                while let Some(v) = stack.pop() {
                    for &(a, b) in edges {
                        if a as usize == v && !row[b as usize] {
                            row[b as usize] = true;
                            stack.push(b as usize);
                        }
                    }
                }
                row
            })
            .collect()
    }

    proptest! {
        /// The reduction has the same reachability, and no kept edge is implied by the rest.
        #[test]
        fn reduction_keeps_reachability_and_is_minimal(
            n in 1usize..10,
            raw in proptest::collection::vec((0u32..10, 0u32..10), 0..30),
        ) {
            // A DAG: edges go from lower to higher vertex.
            let mut edges: Vec<(u32, u32)> = raw
                .into_iter()
                .map(|(a, b)| (a % n as u32, b % n as u32))
                .filter(|&(a, b)| a < b)
                .collect();
            edges.sort_unstable();
            edges.dedup();
            let red = transitive_reduction(n, &edges).unwrap();
            prop_assert_eq!(closure(n, &red), closure(n, &edges));
            for k in 0..red.len() {
                let mut rest = red.clone();
                let (a, b) = rest.remove(k);
                prop_assert!(!closure(n, &rest)[a as usize][b as usize]);
            }
        }
    }
}
