//! The validator's own graph algorithms (it shares no code with the merger): a compressed
//! adjacency list over a frame's edges, strongly connected components by an iterative Tarjan
//! (no recursion: a 40,000-vertex chain must not overflow the stack), reachability by
//! breadth-first search, and the least weight of a feedback arc set of a small component
//! ([`least_cut`]).

use trisort_format::Edge;

/// A directed graph over the endpoints of an edge list, compressed to `0..len()`; its
/// adjacency lists hold edge ids (indices into the list it was built from).
pub(crate) struct Csr {
    /// The original id of each compressed vertex, ascending.
    verts: Vec<usize>,
    /// Per vertex: its out-edges in `out[off[v]..off[v + 1]]`.
    off: Vec<usize>,
    out: Vec<u32>,
    /// Per edge: its compressed endpoints.
    ends: Vec<(u32, u32)>,
}

impl Csr {
    /// The graph of `edges` (`(from, to)` in any ids; parallel edges allowed).
    pub fn new(edges: &[(usize, usize)]) -> Csr {
        let mut verts: Vec<usize> = edges.iter().flat_map(|&(a, b)| [a, b]).collect();
        verts.sort_unstable();
        verts.dedup();
        let local = |t: usize| verts.binary_search(&t).expect("an endpoint") as u32;
        let ends: Vec<(u32, u32)> = edges.iter().map(|&(a, b)| (local(a), local(b))).collect();
        let n = verts.len();
        let mut off = vec![0usize; n + 1];
        for &(a, _) in &ends {
            off[a as usize + 1] += 1;
        }
        for v in 0..n {
            off[v + 1] += off[v];
        }
        let mut fill = off.clone();
        let mut out = vec![0u32; ends.len()];
        for (k, &(a, _)) in ends.iter().enumerate() {
            out[fill[a as usize]] = k as u32;
            fill[a as usize] += 1;
        }
        Csr {
            verts,
            off,
            out,
            ends,
        }
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.verts.len()
    }

    /// The original id of compressed vertex `v`.
    pub fn id(&self, v: u32) -> usize {
        self.verts[v as usize]
    }

    /// Compressed endpoints of edge `k`.
    pub fn ends(&self, k: usize) -> (u32, u32) {
        self.ends[k]
    }

    /// Edge ids leaving compressed vertex `v`.
    pub fn out(&self, v: u32) -> &[u32] {
        &self.out[self.off[v as usize]..self.off[v as usize + 1]]
    }

    /// The strongly connected component of every compressed vertex (numbers in no particular
    /// order). Iterative Tarjan, O(V + E).
    pub fn components(&self) -> Vec<u32> {
        let mut t = Tarjan::new(self.len());
        for root in 0..self.len() as u32 {
            if t.index[root as usize] != UNSEEN {
                continue;
            }
            t.visit(root, self);
            while let Some(top) = t.calls.last_mut() {
                let v = top.0 as usize;
                if top.1 < self.off[v + 1] {
                    let w = self.ends[self.out[top.1] as usize].1;
                    top.1 += 1;
                    if t.index[w as usize] == UNSEEN {
                        t.visit(w, self);
                    } else if t.on_stack[w as usize] {
                        t.low[v] = t.low[v].min(t.index[w as usize]);
                    }
                } else {
                    t.finish(v);
                }
            }
        }
        t.component
    }
}

const UNSEEN: u32 = u32::MAX;

/// The state of [`Csr::components`].
struct Tarjan {
    index: Vec<u32>,
    low: Vec<u32>,
    on_stack: Vec<bool>,
    component: Vec<u32>,
    stack: Vec<u32>,
    /// The explicit call stack: (vertex, position of its next out-edge in `Csr::out`).
    calls: Vec<(u32, usize)>,
    next_index: u32,
    next_component: u32,
}

impl Tarjan {
    fn new(n: usize) -> Tarjan {
        Tarjan {
            index: vec![UNSEEN; n],
            low: vec![0; n],
            on_stack: vec![false; n],
            component: vec![UNSEEN; n],
            stack: Vec::new(),
            calls: Vec::new(),
            next_index: 0,
            next_component: 0,
        }
    }

    /// Enters `v`: numbers it and pushes it on both stacks.
    fn visit(&mut self, v: u32, graph: &Csr) {
        self.index[v as usize] = self.next_index;
        self.low[v as usize] = self.next_index;
        self.next_index += 1;
        self.stack.push(v);
        self.on_stack[v as usize] = true;
        self.calls.push((v, graph.off[v as usize]));
    }

    /// Leaves `v` (the top call) once its edges are done: passes its low link to its caller
    /// and pops its component if it is the component's root.
    fn finish(&mut self, v: usize) {
        self.calls.pop();
        if let Some(&(parent, _)) = self.calls.last() {
            self.low[parent as usize] = self.low[parent as usize].min(self.low[v]);
        }
        if self.low[v] == self.index[v] {
            while let Some(w) = self.stack.pop() {
                self.on_stack[w as usize] = false;
                self.component[w as usize] = self.next_component;
                if w as usize == v {
                    break;
                }
            }
            self.next_component += 1;
        }
    }
}

/// Breadth-first search from compressed vertex `from` for `to`, through the edges `usable`
/// accepts and only vertices of `from`'s component; `seen` (one stamp per vertex, reused
/// across searches) is stamped with `stamp`. Every path between two vertices of one strongly
/// connected component stays inside it, so the restriction loses nothing and keeps each search
/// within one component.
pub(crate) struct Search<'a> {
    /// The graph.
    pub graph: &'a Csr,
    /// Its components ([`Csr::components`]).
    pub component: &'a [u32],
    /// Per vertex: the stamp of the last search that reached it.
    pub seen: Vec<u32>,
    /// The queue, reused.
    pub queue: Vec<u32>,
}

impl Search<'_> {
    /// Whether `to` is reachable from `from` through edges `usable` accepts (`stamp` must
    /// differ from every earlier call's).
    pub fn reaches(
        &mut self,
        from: u32,
        to: u32,
        stamp: u32,
        usable: &dyn Fn(usize) -> bool,
    ) -> bool {
        let c = self.component[from as usize];
        if c != self.component[to as usize] {
            return false;
        }
        self.queue.clear();
        self.queue.push(from);
        self.seen[from as usize] = stamp;
        let mut head = 0;
        while head < self.queue.len() {
            let v = self.queue[head];
            head += 1;
            if v == to {
                return true;
            }
            for &k in self.graph.out(v) {
                let w = self.graph.ends(k as usize).1;
                if usable(k as usize)
                    && self.seen[w as usize] != stamp
                    && self.component[w as usize] == c
                {
                    self.seen[w as usize] = stamp;
                    self.queue.push(w);
                }
            }
        }
        false
    }
}

/// The edges of `edges` that lie on a cycle: both ends in one strongly connected component of
/// the graph they form (in their order). Ids are any triangle ids (scene or G-local); O(E log E).
///
/// These are the only edges a merger may leave unordered (rule 3 of [`crate::check_graph`]:
/// a removed edge must lie on a cycle), so a sample whose
/// consecutive peel fragments are one of them is the only kind an image check may excuse.
pub fn cycle_edges(edges: &[Edge]) -> Vec<Edge> {
    let pairs: Vec<(usize, usize)> = edges
        .iter()
        .map(|e| (e.from as usize, e.to as usize))
        .collect();
    let graph = Csr::new(&pairs);
    let component = graph.components();
    edges
        .iter()
        .enumerate()
        .filter(|&(k, _)| {
            let (a, b) = graph.ends(k);
            a != b && component[a as usize] == component[b as usize]
        })
        .map(|(_, e)| *e)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edge(from: u32, to: u32) -> Edge {
        Edge {
            from,
            to,
            weight: 1,
        }
    }

    #[test]
    fn cycle_edges_are_those_inside_a_component() {
        // 1 → 2 → 3 → 1 is a cycle, 3 → 4 leaves it, 4 ⇄ 5 is a second one, 6 → 7 stands alone.
        let edges = [
            edge(1, 2),
            edge(2, 3),
            edge(3, 1),
            edge(3, 4),
            edge(4, 5),
            edge(5, 4),
            edge(6, 7),
        ];
        let on = cycle_edges(&edges);
        assert_eq!(
            on,
            vec![edge(1, 2), edge(2, 3), edge(3, 1), edge(4, 5), edge(5, 4)]
        );
        assert!(cycle_edges(&[edge(0, 1), edge(1, 2)]).is_empty());
        assert!(cycle_edges(&[]).is_empty());
    }

    /// A chain far longer than any recursion could follow, closed into one cycle.
    #[test]
    fn a_long_chain_needs_no_recursion() {
        let n = 200_000u32;
        let mut edges: Vec<Edge> = (0..n - 1).map(|k| edge(k, k + 1)).collect();
        assert!(cycle_edges(&edges).is_empty());
        edges.push(edge(n - 1, 0));
        assert_eq!(cycle_edges(&edges).len(), n as usize);
    }

    #[test]
    fn search_stays_in_the_component_and_skips_unusable_edges() {
        // 0 → 1 → 2 → 0 and 2 → 3 → 0: one component of four; edge ids in list order.
        let pairs = [(0, 1), (1, 2), (2, 0), (2, 3), (3, 0)];
        let g = Csr::new(&pairs);
        let component = g.components();
        assert!(component.iter().all(|&c| c == component[0]));
        let mut s = Search {
            graph: &g,
            component: &component,
            seen: vec![u32::MAX; g.len()],
            queue: Vec::new(),
        };
        assert!(s.reaches(1, 0, 0, &|_| true));
        // Without 2 → 0 the way back goes through 3.
        assert!(s.reaches(1, 0, 1, &|k| k != 2));
        // Without 2 → 0 and 3 → 0 there is none.
        assert!(!s.reaches(1, 0, 2, &|k| k != 2 && k != 4));
    }
}

/// The most vertices a component may have for [`least_cut`] (2²⁰ subsets of 8 bytes).
pub(crate) const LEAST_CUT_VERTICES: usize = 20;

/// The least total weight of edges whose removal leaves the graph of `n` vertices (at most
/// [`LEAST_CUT_VERTICES`]) and `edges` `(from, to, weight)` acyclic: the least weight of the
/// edges pointing backwards in some vertex order. Over vertex sets S placed first,
/// best(S) = min over v ∈ S of best(S \ v) + w(v → S \ v) (v placed last of S, its edges into
/// the earlier ones pointing back). O(2ⁿ · n) with each vertex's out-weights summed over the
/// low and high halves of S separately.
pub(crate) fn least_cut(n: usize, edges: &[(u32, u32, u64)]) -> u64 {
    assert!(
        n <= LEAST_CUT_VERTICES,
        "{n} vertices: too many for least_cut"
    );
    let half = n / 2;
    // into[v] = (sums over subsets of the low half, sums over subsets of the high half).
    let mut into: Vec<(Vec<u64>, Vec<u64>)> = (0..n)
        .map(|_| (vec![0u64; 1 << half], vec![0u64; 1 << (n - half)]))
        .collect();
    for &(a, b, w) in edges {
        let (lo, hi) = &mut into[a as usize];
        let b = b as usize;
        if b < half {
            for (s, x) in lo.iter_mut().enumerate() {
                if s >> b & 1 == 1 {
                    *x += w;
                }
            }
        } else {
            for (s, x) in hi.iter_mut().enumerate() {
                if s >> (b - half) & 1 == 1 {
                    *x += w;
                }
            }
        }
    }
    let low_mask = (1usize << half) - 1;
    let mut best = vec![u64::MAX; 1 << n];
    best[0] = 0;
    for set in 1usize..1 << n {
        let mut left = set;
        let mut b = u64::MAX;
        while left != 0 {
            let v = left.trailing_zeros() as usize;
            left &= left - 1;
            let before = set & !(1 << v);
            let (lo, hi) = &into[v];
            b = b.min(best[before] + lo[before & low_mask] + hi[before >> half]);
        }
        best[set] = b;
    }
    best[(1 << n) - 1]
}

#[cfg(test)]
mod least_cut_tests {
    use super::*;

    #[test]
    fn least_cut_of_small_graphs() {
        // A triangle: the lightest edge.
        assert_eq!(least_cut(3, &[(0, 1, 5), (1, 2, 4), (2, 0, 1)]), 1);
        // Two 2-cycles sharing a vertex: the lighter of each.
        assert_eq!(
            least_cut(3, &[(0, 1, 2), (1, 0, 3), (1, 2, 7), (2, 1, 6)]),
            8
        );
        // Acyclic: nothing.
        assert_eq!(least_cut(4, &[(0, 1, 1), (1, 2, 1), (0, 3, 1)]), 0);
        // The complete digraph on 6 vertices, weight 1: one edge of each of the 15 pairs.
        let all: Vec<(u32, u32, u64)> = (0..6u32)
            .flat_map(|a| (0..6u32).filter(move |&b| b != a).map(move |b| (a, b, 1)))
            .collect();
        assert_eq!(least_cut(6, &all), 15);
        // A tournament-like case: 0→1→2→3→0 plus 0→2 and 1→3 heavier: the back edge 3→0.
        assert_eq!(
            least_cut(
                4,
                &[
                    (0, 1, 3),
                    (1, 2, 3),
                    (2, 3, 3),
                    (3, 0, 2),
                    (0, 2, 9),
                    (1, 3, 9)
                ]
            ),
            2
        );
    }
}
