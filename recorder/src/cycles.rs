//! Which edges of a directed graph lie on a cycle: those whose two ends are distinct and in one
//! strongly connected component. The recorder needs only this much graph theory (to keep the
//! grown peel's edges from closing cycles), so it has its own small iterative Tarjan rather
//! than depending on the validator, which checks what the recorder and merger produce.

use std::collections::{HashMap, HashSet};

/// The edges of `edges` (`(from, to)`, any ids) on a cycle of the graph they form: both ends
/// distinct and in one strongly connected component. O(V + E) with hashing; no recursion, so
/// a chain of any length is fine.
pub(crate) fn on_cycle(edges: &[(u32, u32)]) -> HashSet<(u32, u32)> {
    let mut local: HashMap<u32, usize> = HashMap::new();
    let mut ends = Vec::with_capacity(edges.len());
    for &(a, b) in edges {
        let mut id = |v: u32| {
            let next = local.len();
            *local.entry(v).or_insert(next)
        };
        let a = id(a);
        let b = id(b);
        ends.push((a, b));
    }
    let component = components(local.len(), &ends);
    edges
        .iter()
        .zip(&ends)
        .filter(|(_, &(a, b))| a != b && component[a] == component[b])
        .map(|(&e, _)| e)
        .collect()
}

/// The strongly connected component of each of `n` vertices (numbers in no particular order)
/// of the graph with edges `ends`: Tarjan's algorithm with an explicit call stack.
fn components(n: usize, ends: &[(usize, usize)]) -> Vec<usize> {
    // Adjacency lists, compressed: vertex v's successors are `out[off[v]..off[v + 1]]`.
    let mut off = vec![0usize; n + 1];
    for &(a, _) in ends {
        off[a + 1] += 1;
    }
    for v in 0..n {
        off[v + 1] += off[v];
    }
    let mut fill = off.clone();
    let mut out = vec![0usize; ends.len()];
    for &(a, b) in ends {
        out[fill[a]] = b;
        fill[a] += 1;
    }
    let mut t = Tarjan {
        index: vec![UNSEEN; n],
        low: vec![0; n],
        on_stack: vec![false; n],
        component: vec![UNSEEN; n],
        stack: Vec::new(),
        calls: Vec::new(),
        next_index: 0,
        next_component: 0,
    };
    for root in 0..n {
        if t.index[root] != UNSEEN {
            continue;
        }
        t.enter(root, off[root]);
        while let Some(top) = t.calls.last_mut() {
            let v = top.0;
            if top.1 < off[v + 1] {
                let w = out[top.1];
                top.1 += 1;
                if t.index[w] == UNSEEN {
                    t.enter(w, off[w]);
                } else if t.on_stack[w] {
                    t.low[v] = t.low[v].min(t.index[w]);
                }
            } else {
                t.finish(v);
            }
        }
    }
    t.component
}

const UNSEEN: usize = usize::MAX;

/// The state of [`components`].
struct Tarjan {
    index: Vec<usize>,
    low: Vec<usize>,
    on_stack: Vec<bool>,
    component: Vec<usize>,
    stack: Vec<usize>,
    /// The explicit call stack: (vertex, position of its next out-edge).
    calls: Vec<(usize, usize)>,
    next_index: usize,
    next_component: usize,
}

impl Tarjan {
    /// Enters `v`, whose out-edges start at `first`: numbers it and pushes it on both stacks.
    fn enter(&mut self, v: usize, first: usize) {
        self.index[v] = self.next_index;
        self.low[v] = self.next_index;
        self.next_index += 1;
        self.stack.push(v);
        self.on_stack[v] = true;
        self.calls.push((v, first));
    }

    /// Leaves `v` (the top call) once its edges are done: passes its low link to its caller
    /// and pops its component if it is the component's root.
    fn finish(&mut self, v: usize) {
        self.calls.pop();
        if let Some(&(parent, _)) = self.calls.last() {
            self.low[parent] = self.low[parent].min(self.low[v]);
        }
        if self.low[v] == self.index[v] {
            while let Some(w) = self.stack.pop() {
                self.on_stack[w] = false;
                self.component[w] = self.next_component;
                if w == v {
                    break;
                }
            }
            self.next_component += 1;
        }
    }
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
