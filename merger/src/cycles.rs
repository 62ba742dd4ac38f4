//! Cycle breaking inside one frame's graph: a minimum-weight feedback arc set, per strongly
//! connected component.
//!
//! Components are found without recursion (`scc.rs`; petgraph's `tarjan_scc`
//! recurses once per vertex and overflows a rayon worker's stack on long chains). Each
//! component that the exact reductions shrink to at most 20 vertices is solved exactly by a
//! subset programme, and one of 21 to 32 by branch and bound where it proves its order
//! optimal within its budget (`exact.rs`: every component of up to 30 edges or 20 vertices is
//! exact; real frames' cycles are tiny), the others by the weighted Eades–Lin–Smyth heuristic (`els.rs`). Afterwards every
//! removed edge whose re-insertion closes no cycle is put back (heaviest first), so the set is
//! minimal on both paths: each removed edge lies on a cycle of the frame's graph and is
//! needed, which the independent validator checks. Where the heuristic's set already has the
//! minimum weight it is the one kept, so a bake changes only where the exact solution
//! removes less weight.

mod els;
mod exact;
mod scc;

/// The result of [`feedback_arc_set`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ArcSet {
    /// One flag per edge: `true` if the edge is removed.
    pub removed: Vec<bool>,
    /// Strongly connected components (of two or more vertices) solved exactly.
    pub exact_components: u32,
    /// Strongly connected components left to the heuristic (too big to solve exactly).
    pub heuristic_components: u32,
    /// The weight removed from the heuristic components: the part of the removed weight that
    /// is not proven minimal.
    pub heuristic_weight: u64,
}

/// Finds a minimum-weight set of edges whose removal makes the graph acyclic, exactly where
/// a strongly connected component is small and by a heuristic otherwise.
///
/// `nodes` is the number of vertices; `edges` are `(from, to, weight)` with endpoints below
/// `nodes` (parallel edges and self-loops allowed; a self-loop is always removed). Only
/// edges inside a strongly connected component can be removed, and every removed edge is
/// needed: put back alone, it closes a cycle. The result is deterministic: of several
/// minimum-weight sets of a component, the heuristic's is kept if it is one of them, else the
/// one the exact programme's tie rule picks (`exact.rs`); both depend only on the edges and
/// their order.
///
/// Complexity: O(V + E) for the components; per component of E_c edges, O(E_c) for the exact
/// reductions, then either at most 2²⁰ · 20 steps for the exact programme, at most 10⁶ · 32
/// for branch and bound, or O(E_c log V)
/// for the heuristic; and O(E_c) per removed edge for the minimality pass (skipped for
/// heuristic components where that would exceed ~5·10⁷ steps).
///
/// ```
/// use trisort_merger::cycles::feedback_arc_set;
/// // A three-triangle cyclic overlap: the lightest edge goes.
/// let set = feedback_arc_set(3, &[(0, 1, 5), (1, 2, 4), (2, 0, 1)]);
/// assert_eq!(set.removed, vec![false, false, true]);
/// assert_eq!((set.exact_components, set.heuristic_components), (1, 0));
/// ```
pub fn feedback_arc_set(nodes: usize, edges: &[(u32, u32, u32)]) -> ArcSet {
    feedback_arc_set_up_to(nodes, edges, exact::MAX_VERTICES)
}

/// [`feedback_arc_set`], solving exactly the components that reduce to at most
/// `max_exact` vertices (0: none, so tests can run the heuristic on small graphs).
fn feedback_arc_set_up_to(nodes: usize, edges: &[(u32, u32, u32)], max_exact: usize) -> ArcSet {
    let mut set = ArcSet {
        removed: vec![false; edges.len()],
        exact_components: 0,
        heuristic_components: 0,
        heuristic_weight: 0,
    };
    for (k, &(a, b, _)) in edges.iter().enumerate() {
        set.removed[k] = a == b;
    }
    let (off, succ) = csr(
        nodes,
        edges.iter().filter(|e| e.0 != e.1).map(|&(a, b, _)| (a, b)),
    );
    let (component, count) = scc::strongly_connected(&off, &succ);
    let mut size = vec![0u32; count as usize];
    for &c in &component {
        size[c as usize] += 1;
    }
    // Edges of each component of two or more vertices, grouped by component.
    let mut by_component: Vec<(u32, usize)> = edges
        .iter()
        .enumerate()
        .filter(|&(_, &(a, b, _))| {
            let c = component[a as usize];
            a != b && c == component[b as usize] && size[c as usize] > 1
        })
        .map(|(k, &(a, _, _))| (component[a as usize], k))
        .collect();
    by_component.sort_unstable();
    for group in by_component.chunk_by(|x, y| x.0 == y.0) {
        let ids: Vec<usize> = group.iter().map(|&(_, k)| k).collect();
        let (cut, exact) = break_component(edges, &ids, max_exact);
        if exact {
            set.exact_components += 1;
        } else {
            set.heuristic_components += 1;
            set.heuristic_weight += cut.iter().map(|&k| edges[k].2 as u64).sum::<u64>();
        }
        for k in cut {
            set.removed[k] = true;
        }
    }
    set
}

/// Breaks the cycles of one strongly connected component given by its edge ids: exactly if
/// it reduces to at most `max_exact` vertices, else by the heuristic, either way keeping
/// only needed edges. Returns the ids of the edges to remove (ascending) and whether the
/// result is exact (of minimum weight).
fn break_component(
    edges: &[(u32, u32, u32)],
    ids: &[usize],
    max_exact: usize,
) -> (Vec<usize>, bool) {
    // Local vertex numbering.
    let mut verts: Vec<u32> = ids.iter().flat_map(|&k| [edges[k].0, edges[k].1]).collect();
    verts.sort_unstable();
    verts.dedup();
    let local = |v: u32| verts.binary_search(&v).expect("endpoint of the component") as u32;
    let n = verts.len();
    let le: Vec<(u32, u32, u64)> = ids
        .iter()
        .map(|&k| (local(edges[k].0), local(edges[k].1), edges[k].2 as u64))
        .collect();
    // The heuristic's set, made minimal (skipped where that would take over ~5·10⁷ steps).
    let mut heuristic = els::backward_edges(n, &le);
    let minimal = (heuristic.len() as u64).saturating_mul(le.len() as u64) <= 50_000_000;
    if minimal {
        put_back_harmless(n, &le, &mut heuristic, true);
    }
    let (cut, exact) = match exact::solve(n, &le, max_exact) {
        // Of two minimum-weight sets, the heuristic's is kept: bakes change only where the
        // exact solution removes less.
        Some(cut) if minimal && weight(&le, &heuristic) == weight(&le, &cut) => (heuristic, true),
        Some(mut cut) => {
            // An optimum is minimal but for edges of weight 0 (it never holds a positive
            // edge it could do without): only those are tried.
            let zeros = cut.iter().filter(|&&e| le[e].2 == 0).count() as u64;
            if zeros.saturating_mul(le.len() as u64) <= 50_000_000 {
                put_back_harmless(n, &le, &mut cut, false);
            }
            (cut, true)
        }
        None => (heuristic, false),
    };
    let mut out: Vec<usize> = cut.into_iter().map(|e| ids[e]).collect();
    out.sort_unstable();
    (out, exact)
}

/// The total weight of the edges `cut` of `le`.
fn weight(le: &[(u32, u32, u64)], cut: &[usize]) -> u64 {
    cut.iter().map(|&e| le[e].2).sum()
}

/// Minimality: puts back every edge of `cut` whose re-insertion closes no cycle with the
/// edges kept, heaviest first (only the edges of weight 0 unless `all`), and leaves in `cut`
/// the edges still removed.
fn put_back_harmless(n: usize, le: &[(u32, u32, u64)], cut: &mut Vec<usize>, all: bool) {
    let (out_off, out_e) = csr(n, le.iter().enumerate().map(|(e, x)| (x.0, e as u32)));
    cut.sort_by_key(|&e| (std::cmp::Reverse(le[e].2), e));
    let mut kept = vec![true; le.len()];
    for &e in cut.iter() {
        kept[e] = false;
    }
    let mut mark = vec![u32::MAX; n];
    let mut stack = Vec::new();
    for (round, &e) in cut.iter().enumerate() {
        let (a, b, w) = le[e];
        if !all && w > 0 {
            continue;
        }
        // Does b reach a through kept edges? Then a → b would close a cycle.
        stack.clear();
        stack.push(b);
        mark[b as usize] = round as u32;
        let mut closes = false;
        while let Some(v) = stack.pop() {
            if v == a {
                closes = true;
                break;
            }
            for &o in &out_e[out_off[v as usize] as usize..out_off[v as usize + 1] as usize] {
                let t = le[o as usize].1;
                if kept[o as usize] && mark[t as usize] != round as u32 {
                    mark[t as usize] = round as u32;
                    stack.push(t);
                }
            }
        }
        if !closes {
            kept[e] = true;
        }
    }
    cut.retain(|&e| !kept[e]);
}

/// Compressed adjacency: `(offsets, items)` with the items of key k at
/// `items[offsets[k]..offsets[k + 1]]`, in input order.
pub(crate) fn csr(
    n: usize,
    pairs: impl Iterator<Item = (u32, u32)> + Clone,
) -> (Vec<u32>, Vec<u32>) {
    let mut off = vec![0u32; n + 1];
    for (k, _) in pairs.clone() {
        off[k as usize + 1] += 1;
    }
    for k in 0..n {
        off[k + 1] += off[k];
    }
    let mut fill = off.clone();
    let mut items = vec![0u32; off[n] as usize];
    for (k, v) in pairs {
        items[fill[k as usize] as usize] = v;
        fill[k as usize] += 1;
    }
    (off, items)
}

/// A topological order of a graph given in [`csr`] form (Kahn's algorithm, smallest ready
/// vertex first), or `None` if it has a cycle. O(V log V + E).
pub(crate) fn topological_order(off: &[u32], succ: &[u32]) -> Option<Vec<u32>> {
    let n = off.len() - 1;
    let mut indeg = vec![0u32; n];
    for &t in succ {
        indeg[t as usize] += 1;
    }
    let mut ready: std::collections::BinaryHeap<std::cmp::Reverse<u32>> = (0..n as u32)
        .filter(|&v| indeg[v as usize] == 0)
        .map(std::cmp::Reverse)
        .collect();
    let mut order = Vec::with_capacity(n);
    while let Some(std::cmp::Reverse(v)) = ready.pop() {
        order.push(v);
        for &t in &succ[off[v as usize] as usize..off[v as usize + 1] as usize] {
            indeg[t as usize] -= 1;
            if indeg[t as usize] == 0 {
                ready.push(std::cmp::Reverse(t));
            }
        }
    }
    (order.len() == n).then_some(order)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Random weighted digraphs on at most `n` vertices (parallel edges and self-loops too).
    fn graphs(
        n: usize,
        m: usize,
        weights: std::ops::Range<u32>,
    ) -> impl Strategy<Value = (usize, Vec<(u32, u32, u32)>)> {
        (
            1..=n,
            proptest::collection::vec((0..n as u32, 0..n as u32, weights), 0..=m),
        )
            .prop_map(|(n, raw)| {
                let edges = raw
                    .into_iter()
                    .map(|(a, b, w)| (a % n as u32, b % n as u32, w))
                    .collect();
                (n, edges)
            })
    }

    /// Whether the edges not removed (plus edge `back`, if any) form an acyclic graph.
    fn acyclic(n: usize, edges: &[(u32, u32, u32)], removed: &[bool], back: Option<usize>) -> bool {
        let pairs = (0..edges.len())
            .filter(|&k| !removed[k] || Some(k) == back)
            .map(|k| (edges[k].0, edges[k].1));
        let (o, s) = csr(n, pairs);
        topological_order(&o, &s).is_some()
    }

    /// The result is acyclic and minimal (each removed edge, put back alone, closes a cycle).
    fn check_acyclic_and_minimal(n: usize, edges: &[(u32, u32, u32)], set: &ArcSet) {
        assert!(acyclic(n, edges, &set.removed, None), "a cycle is left");
        for k in (0..edges.len()).filter(|&k| set.removed[k]) {
            assert!(
                !acyclic(n, edges, &set.removed, Some(k)),
                "edge {k} was removed needlessly"
            );
        }
    }

    /// The least weight of any edge subset whose removal leaves `edges` acyclic, by trying
    /// them all (vertices at most 32, edges at most ~16).
    fn brute_force(n: usize, edges: &[(u32, u32, u32)]) -> u64 {
        let m = edges.len();
        (0u32..1 << m)
            .filter(|&cut| {
                let mut succ = vec![0u32; n];
                for (k, &(a, b, _)) in edges.iter().enumerate() {
                    if cut & (1 << k) == 0 {
                        succ[a as usize] |= 1 << b;
                    }
                }
                // Peel vertices with no successor left; a cycle stops the peel.
                let mut left = if n == 32 { u32::MAX } else { (1u32 << n) - 1 };
                while left != 0 {
                    let Some(v) = (0..n).find(|&v| left & 1 << v != 0 && succ[v] & left == 0)
                    else {
                        return false;
                    };
                    left &= !(1 << v);
                }
                true
            })
            .map(|cut| {
                (0..m)
                    .filter(|&k| cut & 1 << k != 0)
                    .map(|k| edges[k].2 as u64)
                    .sum()
            })
            .min()
            .expect("removing every edge leaves no cycle")
    }

    fn weight(edges: &[(u32, u32, u32)], set: &ArcSet) -> u64 {
        (0..edges.len())
            .filter(|&k| set.removed[k])
            .map(|k| edges[k].2 as u64)
            .sum()
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

        /// Small graphs are solved exactly: the removed weight is the least of all edge
        /// subsets, the rest is acyclic, the removal minimal (weights of 0 included), and the
        /// same input gives the same result.
        #[test]
        fn exact_weight_equals_brute_force((n, edges) in graphs(7, 14, 0..20)) {
            let set = feedback_arc_set(n, &edges);
            prop_assert_eq!(weight(&edges, &set), brute_force(n, &edges));
            check_acyclic_and_minimal(n, &edges, &set);
            prop_assert_eq!(set.heuristic_components, 0);
            prop_assert_eq!(set.heuristic_weight, 0);
            prop_assert_eq!(&feedback_arc_set(n, &edges), &set);
            // Where the heuristic is optimal its set is kept.
            let els = feedback_arc_set_up_to(n, &edges, 0);
            if weight(&edges, &els) == weight(&edges, &set) {
                prop_assert_eq!(els.removed, set.removed);
            }
        }

        /// The heuristic alone (on the same small graphs) also leaves an acyclic graph with a
        /// minimal removal, never beats the optimum, and is deterministic.
        #[test]
        fn heuristic_is_acyclic_and_minimal((n, edges) in graphs(7, 14, 1..20)) {
            let set = feedback_arc_set_up_to(n, &edges, 0);
            check_acyclic_and_minimal(n, &edges, &set);
            prop_assert!(weight(&edges, &set) >= brute_force(n, &edges));
            prop_assert_eq!(set.exact_components, 0);
            let loops: u64 = edges.iter().filter(|e| e.0 == e.1).map(|e| e.2 as u64).sum();
            prop_assert_eq!(set.heuristic_weight, weight(&edges, &set) - loops);
            prop_assert_eq!(feedback_arc_set_up_to(n, &edges, 0), set);
        }
    }

    proptest! {
        /// Bigger graphs, where components are solved exactly or not by their size: acyclic,
        /// minimal, and never heavier than the heuristic alone on an exact component.
        #[test]
        fn mixed_graphs_are_acyclic_and_minimal((n, edges) in graphs(40, 90, 1..20)) {
            let set = feedback_arc_set(n, &edges);
            check_acyclic_and_minimal(n, &edges, &set);
            if set.heuristic_components == 0 {
                let els = feedback_arc_set_up_to(n, &edges, 0);
                prop_assert!(weight(&edges, &set) <= weight(&edges, &els));
            }
        }
    }

    #[test]
    fn heavier_direction_wins_a_two_cycle() {
        assert_eq!(
            feedback_arc_set(2, &[(0, 1, 3), (1, 0, 7)]).removed,
            vec![true, false]
        );
    }

    /// The heuristic misses the optimum even on a three-cycle 0 → 1 → 2 → 0 of weights 6, 2,
    /// 3: vertex 0 has the largest out − in weight, so ELS puts it first and removes 2 → 0
    /// (weight 3); the exact solution removes the lightest edge, 1 → 2.
    #[test]
    fn exact_beats_the_heuristic_where_it_errs() {
        let edges = [(0, 1, 6), (1, 2, 2), (2, 0, 3)];
        let els = feedback_arc_set_up_to(3, &edges, 0);
        assert_eq!(els.removed, vec![false, false, true]);
        assert_eq!((els.heuristic_components, els.heuristic_weight), (1, 3));
        let exact = feedback_arc_set(3, &edges);
        assert_eq!(exact.removed, vec![false, true, false]);
        assert_eq!((exact.exact_components, exact.heuristic_weight), (1, 0));
    }
}
