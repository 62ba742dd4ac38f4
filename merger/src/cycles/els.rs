//! The weighted Eades–Lin–Smyth heuristic for components too big to solve exactly.
//!
//! P. Eades, X. Lin, W. F. Smyth, "A fast and effective heuristic for the feedback arc set
//! problem", Information Processing Letters 47 (1993). The greedy order peels sinks to the
//! back and sources to the front, and otherwise moves the vertex with the largest
//! (outgoing − incoming) *weight* to the front; the edges that point backwards in that order
//! form the arc set. petgraph's `greedy_feedback_arc_set` ignores weights, so this one is
//! written here.

use std::collections::BTreeSet;

use super::csr;

/// The ids (positions in `le`) of the edges that point backwards in the greedy order of a
/// component of `n` local vertices, ascending. O(E log V).
pub(crate) fn backward_edges(n: usize, le: &[(u32, u32, u64)]) -> Vec<usize> {
    let order = Els::new(n, le).order();
    let mut pos = vec![0u32; n];
    for (p, &v) in order.iter().enumerate() {
        pos[v as usize] = p as u32;
    }
    (0..le.len())
        .filter(|&e| pos[le[e].0 as usize] > pos[le[e].1 as usize])
        .collect()
}

/// Edge sides: an edge leaves its source by the `OUT` side and enters its target by the `IN`
/// side; the per-side arrays of [`Els`] are indexed by them.
const OUT: usize = 0;
const IN: usize = 1;

/// The state of the greedy Eades–Lin–Smyth order on one component (local vertex ids).
struct Els<'a> {
    /// Edges `(from, to, weight)`.
    le: &'a [(u32, u32, u64)],
    /// Per side, the [`csr`] lists of edge ids: `OUT` by source, `IN` by target.
    adj: [(Vec<u32>, Vec<u32>); 2],
    alive: Vec<bool>,
    /// Per side, live edges and their total weight at each vertex.
    degree: [Vec<u32>; 2],
    weight: [Vec<i64>; 2],
    /// Candidates by δ = w_out − w_in, largest last (ties: smallest vertex).
    by_delta: BTreeSet<(i64, std::cmp::Reverse<u32>)>,
    /// Per side, vertices whose degree on that side fell to 0: `OUT` sinks, `IN` sources.
    empty: [Vec<u32>; 2],
}

impl<'a> Els<'a> {
    fn new(n: usize, le: &'a [(u32, u32, u64)]) -> Els<'a> {
        let adj = [
            csr(n, le.iter().enumerate().map(|(e, x)| (x.0, e as u32))),
            csr(n, le.iter().enumerate().map(|(e, x)| (x.1, e as u32))),
        ];
        let mut degree = [vec![0u32; n], vec![0u32; n]];
        let mut weight = [vec![0i64; n], vec![0i64; n]];
        for &(a, b, w) in le {
            for (side, v) in [(OUT, a), (IN, b)] {
                degree[side][v as usize] += 1;
                weight[side][v as usize] += w as i64;
            }
        }
        let mut els = Els {
            le,
            adj,
            alive: vec![true; n],
            degree,
            weight,
            by_delta: BTreeSet::new(),
            empty: [Vec::new(), Vec::new()],
        };
        els.by_delta = (0..n as u32).map(|v| els.key(v)).collect();
        els
    }

    fn key(&self, v: u32) -> (i64, std::cmp::Reverse<u32>) {
        let v = v as usize;
        (
            self.weight[OUT][v] - self.weight[IN][v],
            std::cmp::Reverse(v as u32),
        )
    }

    /// Removes v from the graph, updating its live neighbours' degrees, weights and queues.
    fn remove(&mut self, v: u32) {
        self.alive[v as usize] = false;
        self.by_delta.remove(&self.key(v));
        // v's out-edges change their targets' IN side, its in-edges their sources' OUT side.
        for side in [OUT, IN] {
            let (off, list) = &self.adj[side];
            let edges = &list[off[v as usize] as usize..off[v as usize + 1] as usize];
            for &e in edges {
                let (a, b, w) = self.le[e as usize];
                let (u, other) = if side == OUT { (b, IN) } else { (a, OUT) };
                if self.alive[u as usize] {
                    self.by_delta.remove(&self.key(u));
                    self.degree[other][u as usize] -= 1;
                    self.weight[other][u as usize] -= w as i64;
                    self.by_delta.insert(self.key(u));
                    if self.degree[other][u as usize] == 0 {
                        self.empty[other].push(u);
                    }
                }
            }
        }
    }

    /// The greedy order: sinks peeled to the back, sources to the front, otherwise the
    /// vertex with the largest δ to the front.
    fn order(mut self) -> Vec<u32> {
        let n = self.alive.len();
        let mut front: Vec<u32> = Vec::with_capacity(n);
        let mut back: Vec<u32> = Vec::new();
        let mut left = n;
        while left > 0 {
            let (v, to_back) = if let Some(v) = self.empty[OUT].pop() {
                (v, true)
            } else if let Some(v) = self.empty[IN].pop() {
                (v, false)
            } else {
                let &(_, std::cmp::Reverse(v)) =
                    self.by_delta.iter().next_back().expect("a live vertex");
                (v, false)
            };
            if !self.alive[v as usize] {
                continue;
            }
            if to_back {
                back.push(v)
            } else {
                front.push(v)
            }
            left -= 1;
            self.remove(v);
        }
        back.reverse();
        front.extend(back);
        front
    }
}
