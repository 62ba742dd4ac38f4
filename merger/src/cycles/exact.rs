//! The exact minimum-weight feedback arc set of one small strongly connected component.
//!
//! A minimum-weight feedback arc set is the set of backward edges of a best vertex order: the
//! edges left by any feedback arc set have a topological order, and the edges pointing
//! backwards in any order form one. Two exact reductions shrink the component first:
//! 1. *parallel edges* become one edge of their total weight (in any order either all of them
//!    point backwards or none does);
//! 2. *chains*: a vertex v with one incoming edge u → v and one outgoing edge v → w is
//!    removed. Whatever the order of the other vertices, v costs nothing if u comes before w
//!    (put it between them) and min(w(u → v), w(v → w)) otherwise (put it before u or after
//!    w), which is what an edge u → w of that weight costs; if u = w the two edges form a
//!    cycle of their own and the lighter one is removed outright. Repeated until no such
//!    vertex is left (a cycle of 50,000 vertices shrinks to one vertex).
//!
//! After them every vertex has at least three edges, so a component of n vertices and m edges
//! shrinks to n′ ≤ min(n, 2m/3, 2(m − n)) vertices (the reductions never raise m − n). Up to
//! [`MAX_PROGRAMME`] vertices a dynamic programme over vertex subsets finds the best order of
//! what is left: with cost(S) the least backward weight of an order of S placed first,
//! cost(S) = min over v ∈ S of cost(S \ v) + w(v → S \ v) (v last among S), O(2ⁿ′ · n′) with
//! per-vertex tables of subset sums. From there up to [`MAX_VERTICES`] vertices a branch and
//! bound builds the order from the front: each placed prefix S costs the weight
//! of its backward edges, the rest R at least its edges into S plus Σ over pairs
//! {u, v} ⊂ R of min(w(u → v), w(v → u)) (one edge of every pair points backwards in any
//! order; the bound never falls as the prefix grows), a prefix
//! reached again at no lower cost is not expanded twice, and the cheapest next vertex is
//! tried first, so the first leaf is the greedy order. It proves its order optimal unless it
//! expands more than [`BRANCH_BUDGET`] prefixes; then, as for bigger components, the
//! heuristic decides.
//!
//! Ties: for every subset S the smallest vertex (in the component's ascending vertex order)
//! that reaches cost(S) is put last, and a chain is cut at its incoming edge when both weigh
//! the same; branch and bound keeps the first optimum it meets in its fixed search order. So
//! the result depends only on the component's edges, in their order.

use std::collections::HashMap;

/// The most vertices the subset programme takes: at most 2²⁰ · 20 ≈ 2·10⁷ steps and 9 MB
/// (`BENCHMARKS.md` § Exact cycle cuts measures it). This covers every component of up to
/// 20 vertices, up to 30 edges (n′ ≤ 2m/3), or with at most 10 more edges than vertices.
pub(crate) const MAX_PROGRAMME: usize = 20;

/// The most vertices a reduced component may keep to be solved exactly: above
/// [`MAX_PROGRAMME`] by branch and bound, within [`BRANCH_BUDGET`].
pub(crate) const MAX_VERTICES: usize = 32;

/// The prefixes branch and bound may expand before it gives the component to the heuristic
/// (each costs O(n′) and one map entry: at most about 40 MB).
pub(crate) const BRANCH_BUDGET: u64 = 1_000_000;

/// The edges `(from, to, weight)` of one component over local vertices.
type Edges = [(u32, u32, u64)];

/// The ids (positions in `le`) of a minimum-weight set of edges whose removal leaves the
/// component acyclic, ascending; `None` if after the reductions more than `max_vertices`
/// vertices are left, or branch and bound runs out of its budget. `n` vertices, `le` without
/// self-loops. Linear time for the reductions, then O(2ⁿ′ · n′) with n′ ≤ [`MAX_PROGRAMME`],
/// or at most [`BRANCH_BUDGET`] · n′ steps above.
pub(crate) fn solve(n: usize, le: &Edges, max_vertices: usize) -> Option<Vec<usize>> {
    let mut r = Reduced::new(n, le);
    r.contract_chains();
    let verts: Vec<u32> = (0..n as u32).filter(|&v| r.alive[v as usize]).collect();
    if verts.len() > max_vertices {
        return None;
    }
    let local = |v: u32| verts.binary_search(&v).expect("a live vertex") as u32;
    let live: Vec<&Bundle> = r.bundles.iter().filter(|b| b.alive).collect();
    let edges: Vec<(u32, u32, u64)> = live
        .iter()
        .map(|b| (local(b.from), local(b.to), b.weight))
        .collect();
    let order = if verts.len() <= MAX_PROGRAMME {
        best_order(verts.len(), &edges)
    } else {
        branch_and_bound(verts.len(), &edges, BRANCH_BUDGET)?
    };
    let mut pos = vec![0u32; verts.len()];
    for (p, &v) in order.iter().enumerate() {
        pos[v as usize] = p as u32;
    }
    let mut cut = std::mem::take(&mut r.forced);
    for (b, &(a, z, _)) in live.iter().zip(&edges) {
        if pos[a as usize] > pos[z as usize] {
            cut.extend_from_slice(&b.cut);
        }
    }
    cut.sort_unstable();
    Some(cut.into_iter().map(|e| e as usize).collect())
}

/// A vertex order of least backward weight (positions → vertices) of a graph of `n` vertices
/// (at most 24), by the dynamic programme over subsets; ties as the module says.
/// O(2ⁿ · n) time and 9 · 2ⁿ bytes.
pub(crate) fn best_order(n: usize, edges: &Edges) -> Vec<u32> {
    assert!(
        n <= 24,
        "{n} vertices are too many for the subset programme"
    );
    let mut w = vec![0u64; n * n];
    for &(a, b, x) in edges {
        w[a as usize * n + b as usize] += x;
    }
    // w(v → S) = low[v][S's low bits] + high[v][S's high bits].
    let low_bits = n.min(8);
    let tables: Vec<(Vec<u64>, Vec<u64>)> = (0..n)
        .map(|v| {
            let row = &w[v * n..(v + 1) * n];
            (subset_sums(&row[..low_bits]), subset_sums(&row[low_bits..]))
        })
        .collect();
    let low_mask = (1usize << low_bits) - 1;
    let out_weight = |v: usize, s: usize| tables[v].0[s & low_mask] + tables[v].1[s >> low_bits];
    let full = 1usize << n;
    let mut cost = vec![u64::MAX; full];
    let mut last = vec![0u8; full];
    cost[0] = 0;
    for s in 1..full {
        let mut rest = s;
        while rest != 0 {
            let v = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            let before = s & !(1 << v);
            let c = cost[before] + out_weight(v, before);
            if c < cost[s] {
                cost[s] = c;
                last[s] = v as u8;
            }
        }
    }
    let mut order = vec![0u32; n];
    let mut s = full - 1;
    for p in (0..n).rev() {
        order[p] = last[s] as u32;
        s &= !(1 << last[s]);
    }
    order
}

/// A vertex order of least backward weight of a graph of `n` vertices (at most 64) by branch
/// and bound (module documentation), or `None` when that takes more than `budget` prefixes.
pub(crate) fn branch_and_bound(n: usize, edges: &Edges, budget: u64) -> Option<Vec<u32>> {
    assert!(n <= 64, "{n} vertices are too many for a 64-bit vertex set");
    let mut w = vec![0u64; n * n];
    for &(a, b, x) in edges {
        w[a as usize * n + b as usize] += x;
    }
    let pair = |u: usize, v: usize| w[u * n + v].min(w[v * n + u]);
    let full: u64 = if n == 64 { u64::MAX } else { (1u64 << n) - 1 };
    let bound: u64 = (0..n)
        .flat_map(|u| (u + 1..n).map(move |v| (u, v)))
        .map(|(u, v)| pair(u, v))
        .sum();
    let mut search = Branch {
        n,
        w: &w,
        full,
        best: u64::MAX,
        best_order: Vec::new(),
        seen: HashMap::new(),
        order: Vec::with_capacity(n),
        left: budget,
    };
    search.place(0, 0, bound).then_some(search.best_order)
}

/// Branch and bound's state: the graph as a weight matrix, the best order found so far, the
/// least cost each prefix set was reached at, and the budget left.
struct Branch<'a> {
    n: usize,
    w: &'a [u64],
    full: u64,
    best: u64,
    best_order: Vec<u32>,
    seen: HashMap<u64, u64>,
    order: Vec<u32>,
    left: u64,
}

impl Branch<'_> {
    /// Extends the prefix `placed` (cost `cost`, what is still to come bounded below by
    /// `bound`: the rest's pairs, and the rest's edges into the prefix); false when the budget
    /// ran out.
    fn place(&mut self, placed: u64, cost: u64, bound: u64) -> bool {
        if placed == self.full {
            if cost < self.best {
                self.best = cost;
                self.best_order = self.order.clone();
            }
            return true;
        }
        if cost + bound >= self.best {
            return true;
        }
        match self.seen.get(&placed) {
            Some(&c) if c <= cost => return true,
            _ => {}
        }
        if self.left == 0 {
            return false;
        }
        self.left -= 1;
        self.seen.insert(placed, cost);
        let n = self.n;
        let rest = self.full & !placed;
        // Each candidate with the weight of its edges back into the prefix, and the bound's
        // share of its pairs with the rest; cheapest first, then by vertex.
        let mut next: Vec<(u64, u32, u64)> = Vec::with_capacity(rest.count_ones() as usize);
        let mut r = rest;
        while r != 0 {
            let v = r.trailing_zeros() as usize;
            r &= r - 1;
            let (mut back, mut share, mut behind) = (0u64, 0u64, 0u64);
            for u in 0..n {
                let bit = 1u64 << u;
                if placed & bit != 0 {
                    back += self.w[v * n + u];
                } else if u != v {
                    share += self.w[v * n + u].min(self.w[u * n + v]);
                    behind += self.w[u * n + v];
                }
            }
            // The rest's bound loses v's pairs and its edges into the prefix (now cost), and
            // gains the rest's edges into v (backward whatever comes next).
            next.push((back, v as u32, bound - share - back + behind));
        }
        next.sort_unstable();
        for (back, v, rest_bound) in next {
            self.order.push(v);
            let done = self.place(placed | 1u64 << v, cost + back, rest_bound);
            self.order.pop();
            if !done {
                return false;
            }
        }
        true
    }
}

/// The sums of every subset of `w`: entry S is Σ `w[k]` over the bits k of S.
fn subset_sums(w: &[u64]) -> Vec<u64> {
    let mut sums = vec![0u64; 1 << w.len()];
    for s in 1..sums.len() {
        sums[s] = sums[s & (s - 1)] + w[s.trailing_zeros() as usize];
    }
    sums
}

/// An edge of the reduced component: the original edges it stands for and the ones to remove
/// if it is removed (`cut`: all of a parallel bundle, the lightest link of a chain).
struct Bundle {
    from: u32,
    to: u32,
    weight: u64,
    cut: Vec<u32>,
    alive: bool,
}

/// The component under reduction (see the module documentation).
struct Reduced {
    bundles: Vec<Bundle>,
    /// The live bundle from a to b, if any.
    pair: HashMap<(u32, u32), u32>,
    /// Bundle ids leaving / entering each vertex; dead ones stay until the vertex goes.
    out: Vec<Vec<u32>>,
    inn: Vec<Vec<u32>>,
    /// Live bundles leaving / entering each vertex.
    out_degree: Vec<u32>,
    in_degree: Vec<u32>,
    alive: Vec<bool>,
    /// Original edges removed outright (the lighter edge of each two-vertex cycle left).
    forced: Vec<u32>,
}

impl Reduced {
    fn new(n: usize, le: &Edges) -> Reduced {
        let mut r = Reduced {
            bundles: Vec::with_capacity(le.len()),
            pair: HashMap::with_capacity(le.len()),
            out: vec![Vec::new(); n],
            inn: vec![Vec::new(); n],
            out_degree: vec![0; n],
            in_degree: vec![0; n],
            alive: vec![true; n],
            forced: Vec::new(),
        };
        for (e, &(a, b, w)) in le.iter().enumerate() {
            debug_assert_ne!(a, b, "self-loops are removed before");
            r.add(a, b, w, vec![e as u32]);
        }
        r
    }

    /// Adds an edge a → b, into the live bundle from a to b if there is one.
    fn add(&mut self, a: u32, b: u32, weight: u64, cut: Vec<u32>) {
        if let Some(&k) = self.pair.get(&(a, b)) {
            let bundle = &mut self.bundles[k as usize];
            bundle.weight += weight;
            bundle.cut.extend(cut);
            return;
        }
        let k = self.bundles.len() as u32;
        self.bundles.push(Bundle {
            from: a,
            to: b,
            weight,
            cut,
            alive: true,
        });
        self.pair.insert((a, b), k);
        self.out[a as usize].push(k);
        self.inn[b as usize].push(k);
        self.out_degree[a as usize] += 1;
        self.in_degree[b as usize] += 1;
    }

    /// Removes bundle k and returns its weight and cut.
    fn kill(&mut self, k: u32) -> (u64, Vec<u32>) {
        let b = &mut self.bundles[k as usize];
        b.alive = false;
        self.pair.remove(&(b.from, b.to));
        self.out_degree[b.from as usize] -= 1;
        self.in_degree[b.to as usize] -= 1;
        (b.weight, std::mem::take(&mut b.cut))
    }

    /// The one live bundle in `list`.
    fn live(&self, list: &[u32]) -> u32 {
        *list
            .iter()
            .find(|&&k| self.bundles[k as usize].alive)
            .expect("a live bundle")
    }

    /// Contracts every vertex with one incoming and one outgoing bundle, until none is left.
    /// Each vertex goes at most once and its lists are scanned then, so this takes time
    /// linear in the edges (plus hashing).
    fn contract_chains(&mut self) {
        let mut work: Vec<u32> = (0..self.alive.len() as u32).rev().collect();
        while let Some(v) = work.pop() {
            let vi = v as usize;
            if !self.alive[vi] || self.in_degree[vi] != 1 || self.out_degree[vi] != 1 {
                continue;
            }
            let (into, from) = (self.live(&self.inn[vi]), self.live(&self.out[vi]));
            let (u, w) = (
                self.bundles[into as usize].from,
                self.bundles[from as usize].to,
            );
            let (w_in, cut_in) = self.kill(into);
            let (w_out, cut_out) = self.kill(from);
            self.alive[vi] = false;
            self.inn[vi] = Vec::new();
            self.out[vi] = Vec::new();
            let (weight, cut) = if w_in <= w_out {
                (w_in, cut_in)
            } else {
                (w_out, cut_out)
            };
            if u == w {
                self.forced.extend(cut);
            } else {
                self.add(u, w, weight, cut);
                work.push(w);
            }
            work.push(u);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The weight of the backward edges of `order`.
    fn backward(edges: &Edges, order: &[u32]) -> u64 {
        let mut pos = vec![0usize; order.len()];
        for (p, &v) in order.iter().enumerate() {
            pos[v as usize] = p;
        }
        edges
            .iter()
            .filter(|e| pos[e.0 as usize] > pos[e.1 as usize])
            .map(|e| e.2)
            .sum()
    }

    /// Every order of `n` vertices (Heap's algorithm), for brute force.
    fn all_orders(n: usize) -> Vec<Vec<u32>> {
        fn heap(k: usize, a: &mut Vec<u32>, out: &mut Vec<Vec<u32>>) {
            if k <= 1 {
                out.push(a.clone());
                return;
            }
            for i in 0..k {
                heap(k - 1, a, out);
                let j = if k.is_multiple_of(2) { i } else { 0 };
                a.swap(j, k - 1);
            }
        }
        let mut out = Vec::new();
        heap(n, &mut (0..n as u32).collect(), &mut out);
        out
    }

    fn graph(n: usize, raw: Vec<(u32, u32, u64)>) -> Vec<(u32, u32, u64)> {
        raw.into_iter()
            .map(|(a, b, w)| (a % n as u32, b % n as u32, w))
            .filter(|e| e.0 != e.1)
            .collect()
    }

    proptest! {
        /// The programme's order is as good as the best of all n! orders.
        #[test]
        fn best_order_matches_every_order(
            n in 1usize..7,
            raw in proptest::collection::vec((0u32..7, 0u32..7, 0u64..20), 0..20),
        ) {
            let edges = graph(n, raw);
            let best = all_orders(n).iter().map(|o| backward(&edges, o)).min().unwrap();
            prop_assert_eq!(backward(&edges, &best_order(n, &edges)), best);
        }

        /// The reductions change no optimum: on graphs big enough to have chains, the reduced
        /// solution weighs what the programme finds on the whole graph.
        #[test]
        fn reductions_keep_the_optimum(
            n in 2usize..13,
            raw in proptest::collection::vec((0u32..13, 0u32..13, 1u64..20), 0..26),
            ring in any::<bool>(),
        ) {
            let mut edges = graph(n, raw);
            if ring {
                // A ring through every vertex: one strongly connected component.
                edges.extend((0..n as u32).map(|v| (v, (v + 1) % n as u32, 1 + v as u64 % 3)));
            }
            let best = backward(&edges, &best_order(n, &edges));
            let cut = solve(n, &edges, MAX_VERTICES).expect("n ≤ 16");
            prop_assert_eq!(cut.iter().map(|&e| edges[e].2).sum::<u64>(), best);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]
        /// Branch and bound finds an order as good as the subset programme's, on graphs dense
        /// and sparse, with a ring through every vertex or without.
        #[test]
        fn branch_and_bound_matches_the_programme(
            n in 2usize..15,
            raw in proptest::collection::vec((0u32..15, 0u32..15, 0u64..20), 0..60),
            ring in any::<bool>(),
        ) {
            let mut edges = graph(n, raw);
            if ring {
                edges.extend((0..n as u32).map(|v| (v, (v + 1) % n as u32, 1 + v as u64 % 3)));
            }
            let best = backward(&edges, &best_order(n, &edges));
            let order = branch_and_bound(n, &edges, u64::MAX).expect("no budget");
            let mut sorted = order.clone();
            sorted.sort_unstable();
            prop_assert_eq!(sorted, (0..n as u32).collect::<Vec<_>>());
            prop_assert_eq!(backward(&edges, &order), best);
        }
    }

    #[test]
    fn branch_and_bound_gives_up_past_its_budget() {
        // The complete digraph on 12 vertices, every weight 1: every order costs 66, which
        // the bound proves once the first leaf is reached, after 12 prefixes.
        let edges: Vec<(u32, u32, u64)> = (0..12u32)
            .flat_map(|a| (0..12u32).filter(move |&b| b != a).map(move |b| (a, b, 1)))
            .collect();
        assert_eq!(branch_and_bound(12, &edges, 11), None);
        let order = branch_and_bound(12, &edges, 12).expect("within the budget");
        assert_eq!(backward(&edges, &order), 66);
    }

    #[test]
    fn a_long_cycle_reduces_to_its_lightest_edge() {
        let n = 1000u32;
        let edges: Vec<(u32, u32, u64)> = (0..n)
            .map(|v| (v, (v + 1) % n, if v == 700 { 2 } else { 5 }))
            .collect();
        assert_eq!(solve(n as usize, &edges, 1), Some(vec![700]));
    }

    #[test]
    fn too_many_vertices_are_refused() {
        // The complete digraph on 5 vertices has no chain to contract.
        let edges: Vec<(u32, u32, u64)> = (0..5u32)
            .flat_map(|a| (0..5u32).filter(move |&b| b != a).map(move |b| (a, b, 1)))
            .collect();
        assert_eq!(solve(5, &edges, 4), None);
        assert_eq!(solve(5, &edges, 5).map(|c| c.len()), Some(10));
    }
}
