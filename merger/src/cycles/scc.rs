//! Strongly connected components by Tarjan's algorithm, without recursion.
//!
//! R. Tarjan, "Depth-first search and linear graph algorithms", SIAM J. Computing 1 (1972).
//! petgraph's `tarjan_scc` recurses once per vertex of a path, so a long chain of triangles
//! (40,000 in one cycle) overflows a rayon worker's 2 MiB stack; here the depth-first search
//! keeps its own stack on the heap.

/// Marks a vertex not reached yet (`index`) or not yet in a component (`component`).
const UNSET: u32 = u32::MAX;

/// The strongly connected component of every vertex of a graph in [`super::csr`] form
/// (`off`, `succ`), numbered from 0 in the order Tarjan's algorithm completes them (a
/// reverse topological order of the condensation), and the number of components. Roots are
/// tried in ascending order and successors in list order, so the numbering is deterministic.
/// O(V + E) time, O(V) memory besides the input; no recursion.
pub(crate) fn strongly_connected(off: &[u32], succ: &[u32]) -> (Vec<u32>, u32) {
    let n = off.len() - 1;
    let mut s = Search {
        index: vec![UNSET; n],
        low: vec![0; n],
        next_index: 0,
        open: Vec::new(),
        calls: Vec::new(),
    };
    let mut component = vec![UNSET; n];
    let mut count = 0u32;
    for root in 0..n as u32 {
        if s.index[root as usize] != UNSET {
            continue;
        }
        s.enter(root, off);
        while let Some(&(v, next)) = s.calls.last() {
            let vi = v as usize;
            if next < off[vi + 1] {
                s.calls.last_mut().expect("a call").1 += 1;
                let w = succ[next as usize] as usize;
                if s.index[w] == UNSET {
                    s.enter(w as u32, off);
                } else if component[w] == UNSET {
                    // Reached but in no component yet: w is open, on this search's stack.
                    s.low[vi] = s.low[vi].min(s.index[w]);
                }
                continue;
            }
            s.calls.pop();
            if let Some(&(parent, _)) = s.calls.last() {
                s.low[parent as usize] = s.low[parent as usize].min(s.low[vi]);
            }
            if s.low[vi] == s.index[vi] {
                loop {
                    let w = s.open.pop().expect("v is open");
                    component[w as usize] = count;
                    if w == v {
                        break;
                    }
                }
                count += 1;
            }
        }
    }
    (component, count)
}

/// The depth-first search's state.
struct Search {
    /// Discovery index of each vertex ([`UNSET`] before).
    index: Vec<u32>,
    /// Smallest discovery index reachable through the vertex's subtree and one back edge.
    low: Vec<u32>,
    next_index: u32,
    /// Tarjan's stack: vertices reached and not yet in a component.
    open: Vec<u32>,
    /// The search's own call stack: (vertex, position of its next successor in `succ`).
    calls: Vec<(u32, u32)>,
}

impl Search {
    /// Discovers `v` and pushes its call.
    fn enter(&mut self, v: u32, off: &[u32]) {
        self.index[v as usize] = self.next_index;
        self.low[v as usize] = self.next_index;
        self.next_index += 1;
        self.open.push(v);
        self.calls.push((v, off[v as usize]));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycles::csr;
    use proptest::prelude::*;

    /// Whether `b` is reachable from `a` (a plain breadth-first search).
    fn reaches(off: &[u32], succ: &[u32], a: u32, b: u32) -> bool {
        let mut seen = vec![false; off.len() - 1];
        let mut queue = vec![a];
        seen[a as usize] = true;
        while let Some(v) = queue.pop() {
            if v == b {
                return true;
            }
            for &w in &succ[off[v as usize] as usize..off[v as usize + 1] as usize] {
                if !std::mem::replace(&mut seen[w as usize], true) {
                    queue.push(w);
                }
            }
        }
        false
    }

    proptest! {
        /// Two vertices share a component exactly when each reaches the other, and the
        /// numbering is a reverse topological order of the components.
        #[test]
        fn components_are_mutual_reachability(
            n in 1usize..10,
            raw in proptest::collection::vec((0u32..10, 0u32..10), 0..30),
        ) {
            let pairs: Vec<(u32, u32)> =
                raw.into_iter().map(|(a, b)| (a % n as u32, b % n as u32)).collect();
            let (off, succ) = csr(n, pairs.iter().copied());
            let (component, count) = strongly_connected(&off, &succ);
            prop_assert!(component.iter().all(|&c| c < count));
            for a in 0..n as u32 {
                for b in 0..n as u32 {
                    let same = reaches(&off, &succ, a, b) && reaches(&off, &succ, b, a);
                    prop_assert_eq!(component[a as usize] == component[b as usize], same);
                }
            }
            for &(a, b) in &pairs {
                prop_assert!(component[a as usize] >= component[b as usize]);
            }
        }
    }

    #[test]
    fn a_long_path_needs_no_deep_stack() {
        let n = 100_000u32;
        let (off, succ) = csr(n as usize, (0..n - 1).map(|v| (v, v + 1)));
        let run = move || strongly_connected(&off, &succ).1;
        let count = std::thread::Builder::new()
            .stack_size(64 << 10)
            .spawn(run)
            .expect("a thread")
            .join()
            .expect("no overflow");
        assert_eq!(count, n);
    }
}
