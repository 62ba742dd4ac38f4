//! Which edges of a directed graph lie on a cycle: those whose two ends are distinct and in one
//! strongly connected component. The recorder needs only this much graph theory (to keep the
//! grown peel's edges from closing cycles); it takes the components from petgraph rather than
//! from the validator, which checks what the recorder and merger produce.

use std::collections::{HashMap, HashSet};

use petgraph::algo::kosaraju_scc;
use petgraph::graphmap::DiGraphMap;

/// The edges of `edges` (`(from, to)`, any ids) on a cycle of the graph they form: both ends
/// distinct and in one strongly connected component. O(V + E); Kosaraju's algorithm runs
/// without recursion, so a chain of any length is fine.
pub(crate) fn on_cycle(edges: &[(u32, u32)]) -> HashSet<(u32, u32)> {
    let graph: DiGraphMap<u32, ()> = DiGraphMap::from_edges(edges);
    let component: HashMap<u32, usize> = kosaraju_scc(&graph)
        .into_iter()
        .enumerate()
        .flat_map(|(c, members)| members.into_iter().map(move |v| (v, c)))
        .collect();
    edges
        .iter()
        .filter(|&&(a, b)| a != b && component[&a] == component[&b])
        .copied()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_inside_a_component_are_on_a_cycle() {
        // 1 → 2 → 3 → 1 is a cycle, 3 → 4 leaves it, 4 ⇄ 5 is a second one, 6 → 7 stands alone.
        let edges = [
            (1, 2),
            (2, 3),
            (3, 1),
            (3, 4),
            (4, 5),
            (5, 4),
            (6, 7),
            (8, 8),
        ];
        let want: HashSet<(u32, u32)> = [(1, 2), (2, 3), (3, 1), (4, 5), (5, 4)].into();
        assert_eq!(on_cycle(&edges), want);
        assert!(on_cycle(&[(0, 1), (1, 2)]).is_empty());
        assert!(on_cycle(&[]).is_empty());
    }

    /// A chain far longer than any recursion could follow, closed into one cycle.
    #[test]
    fn a_long_chain_needs_no_recursion() {
        let n = 200_000u32;
        let mut edges: Vec<(u32, u32)> = (0..n - 1).map(|k| (k, k + 1)).collect();
        assert!(on_cycle(&edges).is_empty());
        edges.push((n - 1, 0));
        assert_eq!(on_cycle(&edges).len(), n as usize);
    }

    /// The validator's cycle test (a dev-dependency only) agrees on pseudo-random graphs.
    #[test]
    fn agrees_with_the_validator() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |m: u64| {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((seed >> 33) % m) as u32
        };
        for round in 0..200u64 {
            let vertices = 2 + round % 30;
            let edges: Vec<(u32, u32)> = (0..next(3 * vertices) + 1)
                .map(|_| (next(vertices), next(vertices)))
                .collect();
            let listed: Vec<trisort_format::Edge> = edges
                .iter()
                .map(|&(from, to)| trisort_format::Edge {
                    from,
                    to,
                    weight: 1,
                })
                .collect();
            let want: HashSet<(u32, u32)> = trisort_verify::cycle_edges(&listed)
                .into_iter()
                .map(|e| (e.from, e.to))
                .collect();
            assert_eq!(on_cycle(&edges), want, "edges {edges:?}");
        }
    }
}
