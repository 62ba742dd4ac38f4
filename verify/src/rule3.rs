//! Rule 3 for one frame: the removed edges are edges of E_f that lie on a cycle and are
//! needed, E_f* (E_f minus them) is acyclic, and the draw order respects E_f*.

use trisort_format::{Baked, Edge};

use crate::graph::{least_cut, Csr, Search, LEAST_CUT_VERTICES};
use crate::{FrameReport, GraphReport};

/// Examples of each kind of violation reported per frame (the counts are complete).
const EXAMPLES: u64 = 3;

/// One frame's rule-3 check: where it is and how to name its triangles.
pub(crate) struct Rule3<'a> {
    /// The frame.
    pub f: usize,
    /// Scene id of each G-local triangle (the file's `scene_ids`, equal to the recording's G).
    pub ids: &'a [u32],
}

/// Frame f's graph: E_f (or its ties for a depth-only bake) in G-local ids, sorted, and which
/// edges the file removed.
struct FrameEdges {
    edges: Vec<(usize, usize, u32)>,
    cut: Vec<bool>,
}

impl Rule3<'_> {
    /// A G-local triangle by its scene id (the ids `record` and the recording speak), or the
    /// local id where the file names one outside G.
    fn name(&self, t: usize) -> String {
        match self.ids.get(t) {
            Some(s) => s.to_string(),
            None => format!("(G-local {t}, outside G)"),
        }
    }

    /// An edge by scene ids.
    fn edge(&self, a: usize, b: usize) -> String {
        format!("{}→{}", self.name(a), self.name(b))
    }

    /// Checks rule 3 of the frame against `source` (its E_f, or the edges depth mode needs), the file's
    /// removed edges of the frame and its draw positions (`draw(t)`: t's position if drawn),
    /// adding to `fm` and `report`.
    pub fn check(
        &self,
        baked: &Baked,
        source: &[Edge],
        draw: &dyn Fn(usize) -> Option<u64>,
        fm: &mut FrameReport,
        report: &mut GraphReport,
    ) {
        let removed = baked
            .removed_edges
            .get(self.f)
            .map(Vec::as_slice)
            .unwrap_or(&[]);
        fm.unordered_samples = removed.iter().map(|e| e.weight as u64).sum();
        let fe = self.frame_edges(baked, source, removed, fm, report);
        let pairs: Vec<(usize, usize)> = fe.edges.iter().map(|e| (e.0, e.1)).collect();
        let graph = Csr::new(&pairs);
        let component = graph.components();
        self.removed_on_cycles_and_needed(&fe, &graph, &component, fm, report);
        self.cut_is_least(&fe, &graph, &component, fm, report);
        fm.graph_violations += self.order_violations(&fe, &graph, draw, report);
    }

    /// The frame's edges in G-local ids, each of the file's removed edges matched to one edge
    /// of E_f of the same weight. A removed edge that is not in E_f is a graph violation of the
    /// frame; an edge leaving G is a problem of the file.
    fn frame_edges(
        &self,
        baked: &Baked,
        source: &[Edge],
        removed: &[Edge],
        fm: &mut FrameReport,
        report: &mut GraphReport,
    ) -> FrameEdges {
        let f = self.f;
        let local = |t: u32| baked.scene_ids.binary_search(&t).ok();
        let mut edges: Vec<(usize, usize, u32)> = Vec::with_capacity(source.len());
        for e in source {
            match (local(e.from), local(e.to)) {
                (Some(a), Some(b)) => edges.push((a, b, e.weight)),
                _ => report.problem(format!("frame {f}: edge {}→{} leaves G", e.from, e.to)),
            }
        }
        edges.sort_unstable();
        let mut cut = vec![false; edges.len()];
        for r in removed {
            let (a, b) = (r.from as usize, r.to as usize);
            let hit = edges
                .iter()
                .enumerate()
                .skip(edges.partition_point(|e| (e.0, e.1) < (a, b)))
                .take_while(|(_, e)| (e.0, e.1) == (a, b))
                .find(|&(k, e)| !cut[k] && e.2 == r.weight)
                .map(|(k, _)| k);
            match hit {
                Some(k) => cut[k] = true,
                None => {
                    fm.graph_violations += 1;
                    report.problem(format!(
                        "frame {f}: removed edge {} (scene ids, weight {}) is not an edge of E_f with that weight",
                        self.edge(a, b),
                        r.weight
                    ));
                }
            }
        }
        FrameEdges { edges, cut }
    }

    /// Each removed edge u → v must lie on a cycle of E_f (u and v in one strongly connected
    /// component) and be needed: v still reaches u in E_f minus *all* removed edges, so that
    /// restoring u → v alone would close a cycle. One search per removed edge, confined to its
    /// component (removed edges are few).
    fn removed_on_cycles_and_needed(
        &self,
        fe: &FrameEdges,
        graph: &Csr,
        component: &[u32],
        fm: &mut FrameReport,
        report: &mut GraphReport,
    ) {
        let f = self.f;
        let mut search = Search {
            graph,
            component,
            seen: vec![u32::MAX; graph.len()],
            queue: Vec::new(),
        };
        let kept = |k: usize| !fe.cut[k];
        // Each search stamps the vertices it reaches with its edge's id.
        for k in (0..fe.edges.len()).filter(|&k| fe.cut[k]) {
            let (u, v) = graph.ends(k);
            let (a, b, w) = fe.edges[k];
            if component[u as usize] != component[v as usize] {
                fm.removed_not_on_cycle += 1;
                fm.graph_violations += 1;
                report.problem_if(fm.removed_not_on_cycle <= EXAMPLES, || format!(
                    "frame {f}: removed edge {} (scene ids, weight {w}) lies on no cycle of E_f: its order was never in doubt",
                    self.edge(a, b)
                ));
            } else if !search.reaches(v, u, k as u32, &kept) {
                fm.removed_not_needed += 1;
                fm.graph_violations += 1;
                report.problem_if(fm.removed_not_needed <= EXAMPLES, || format!(
                    "frame {f}: removed edge {} (scene ids, weight {w}) is not needed: E_f minus the removed edges has no path {} back, so keeping it closes no cycle",
                    self.edge(a, b),
                    self.edge(b, a)
                ));
            }
        }
    }

    /// The file's cut in each cyclic component of at most [`LEAST_CUT_VERTICES`] vertices
    /// weighs the least possible (the merger solves those exactly; a forged cut of 55
    /// samples where 31 suffice once passed as "needed"). Components the file cuts nothing
    /// of cannot be over (a cycle left is an order violation); bigger cut ones are counted in
    /// `cut_components_unbounded`: their cut is only checked to be needed.
    fn cut_is_least(
        &self,
        fe: &FrameEdges,
        graph: &Csr,
        component: &[u32],
        fm: &mut FrameReport,
        report: &mut GraphReport,
    ) {
        let f = self.f;
        // Edge ids inside a component, grouped by component.
        let mut inside: Vec<(u32, usize)> = (0..fe.edges.len())
            .filter_map(|k| {
                let (u, v) = graph.ends(k);
                let c = component[u as usize];
                (c == component[v as usize]).then_some((c, k))
            })
            .collect();
        inside.sort_unstable();
        let mut over = 0u64;
        for group in inside.chunk_by(|x, y| x.0 == y.0) {
            let cut: u64 = group
                .iter()
                .filter(|&&(_, k)| fe.cut[k])
                .map(|&(_, k)| fe.edges[k].2 as u64)
                .sum();
            if cut == 0 {
                continue;
            }
            let mut verts: Vec<u32> = group
                .iter()
                .flat_map(|&(_, k)| {
                    let (u, v) = graph.ends(k);
                    [u, v]
                })
                .collect();
            verts.sort_unstable();
            verts.dedup();
            if verts.len() > LEAST_CUT_VERTICES {
                fm.cut_components_unbounded += 1;
                continue;
            }
            let local = |v: u32| verts.binary_search(&v).expect("a vertex of the group") as u32;
            let edges: Vec<(u32, u32, u64)> = group
                .iter()
                .map(|&(_, k)| {
                    let (u, v) = graph.ends(k);
                    (local(u), local(v), fe.edges[k].2 as u64)
                })
                .collect();
            let least = least_cut(verts.len(), &edges);
            if cut > least {
                fm.cut_excess += cut - least;
                fm.graph_violations += 1;
                over += 1;
                let (a, b, _) = fe.edges[group[0].1];
                report.problem_if(over <= EXAMPLES, || format!(
                    "frame {f}: the cut of the cycle component through {} ({} triangles) removes {cut} samples where {least} suffice",
                    self.edge(a, b),
                    verts.len()
                ));
            }
        }
    }

    /// The number of drawn vertices drawn before some drawn ancestor in the kept edges (plus
    /// one for a cycle). Kahn's order over the kept edges, each vertex carrying the latest
    /// draw position of a drawn ancestor and which ancestor that is, so that a violation names
    /// the order it breaks.
    fn order_violations(
        &self,
        fe: &FrameEdges,
        graph: &Csr,
        draw: &dyn Fn(usize) -> Option<u64>,
        report: &mut GraphReport,
    ) -> u64 {
        let f = self.f;
        let m = graph.len();
        let mut indeg = vec![0u32; m];
        for k in (0..fe.edges.len()).filter(|&k| !fe.cut[k]) {
            indeg[graph.ends(k).1 as usize] += 1;
        }
        // Per vertex: (latest draw position + 1 of a drawn ancestor, that ancestor); 0 = none.
        let mut latest = vec![(0u64, 0u32); m];
        let mut ready: Vec<u32> = (0..m as u32).filter(|&v| indeg[v as usize] == 0).collect();
        let mut seen = 0;
        let mut violations = 0;
        while let Some(v) = ready.pop() {
            seen += 1;
            let mut carry = latest[v as usize];
            if let Some(p) = draw(graph.id(v)) {
                let (before, ancestor) = latest[v as usize];
                if before > p {
                    violations += 1;
                    report.problem_if(violations <= EXAMPLES, || format!(
                        "frame {f}: order {} (scene ids) is violated: {} is drawn at position {p} of the frame, before {} at {before}, which lies in front of it in E_f minus the removed edges",
                        self.edge(graph.id(ancestor), graph.id(v)),
                        self.name(graph.id(v)),
                        self.name(graph.id(ancestor)),
                    ));
                }
                if p > carry.0 {
                    carry = (p, v);
                }
            }
            for &k in graph.out(v) {
                if fe.cut[k as usize] {
                    continue;
                }
                let w = graph.ends(k as usize).1 as usize;
                if carry.0 > latest[w].0 {
                    latest[w] = carry;
                }
                indeg[w] -= 1;
                if indeg[w] == 0 {
                    ready.push(w as u32);
                }
            }
        }
        if seen < m {
            let stuck = (0..m).find(|&v| indeg[v] > 0).expect("a vertex left");
            report.problem(format!(
                "frame {f}: E_f minus the removed edges still has a cycle (triangle {} lies on or behind it)",
                self.name(graph.id(stuck as u32))
            ));
            violations += 1;
        }
        violations
    }
}
