//! Input: checks the recordings against each other and turns every frame into a
//! [`FrameGraph`] over G-local ids, with its intra-frame cycles broken (E_f*).

use trisort_format::{Edge, Phase, Recording};

use crate::cycles::{csr, feedback_arc_set, topological_order};
use crate::MergeError;

/// One frame's graph over G-local ids, after cycle breaking.
#[derive(Clone, Debug)]
pub(crate) struct FrameGraph {
    /// V_f, ascending.
    pub visible: Vec<u32>,
    /// C_f ∪ V_f, ascending.
    pub covered: Vec<u32>,
    /// Vertices of the graph: `covered` ∪ edge endpoints, ascending. Local index = position.
    pub nodes: Vec<u32>,
    /// E_f* in compressed form over local indices.
    pub off: Vec<u32>,
    /// Successor lists (local indices).
    pub succ: Vec<u32>,
    /// E_f* reversed, compressed like `off`.
    pub pred_off: Vec<u32>,
    /// Predecessor lists (local indices).
    pub pred: Vec<u32>,
    /// A topological order of E_f* (local indices).
    pub topo: Vec<u32>,
    /// The removed cycle edges (G-local ids), sorted.
    pub removed: Vec<Edge>,
    /// Strongly connected components solved exactly / by the heuristic, and the weight the
    /// heuristic removed ([`crate::cycles::ArcSet`]).
    pub components: (u32, u32, u64),
}

impl FrameGraph {
    /// Local index of G-local triangle `t`, if it is a vertex of this frame's graph.
    pub fn local(&self, t: u32) -> Option<u32> {
        self.nodes.binary_search(&t).ok().map(|k| k as u32)
    }

    /// Successors of local vertex `v`.
    pub fn successors(&self, v: u32) -> &[u32] {
        &self.succ[self.off[v as usize] as usize..self.off[v as usize + 1] as usize]
    }

    /// Predecessors of local vertex `v`.
    pub fn predecessors(&self, v: u32) -> &[u32] {
        &self.pred[self.pred_off[v as usize] as usize..self.pred_off[v as usize + 1] as usize]
    }

    /// Whether G-local `t` is covered (has a fragment).
    pub fn is_covered(&self, t: u32) -> bool {
        self.covered.binary_search(&t).is_ok()
    }
}

/// The merger's input: recordings checked and sorted into one path.
pub(crate) struct Input<'a> {
    /// The recordings, in frame order.
    pub recordings: Vec<&'a Recording>,
    /// Number of frames of the path.
    pub frames: u32,
}

/// Checks that the recordings are contiguous frame ranges of one scene, path, setting and
/// (unless `allow_mixed_devices`) device, all with graphs, together covering every frame of
/// the path.
pub(crate) fn check_recordings(
    recordings: &[Recording],
    allow_mixed_devices: bool,
) -> Result<Input<'_>, MergeError> {
    for (k, r) in recordings.iter().enumerate() {
        r.check_structure()
            .map_err(|why| MergeError::Invalid { recording: k, why })?;
        if r.phase != Phase::Graphs {
            return Err(MergeError::NotGraphs { recording: k });
        }
        if r.geometry.triangles.len() != r.unique_visible.len() {
            return Err(MergeError::Mismatch {
                recording: k,
                what: "geometry (not one triangle per member of G)",
            });
        }
    }
    crate::shards::first_difference(recordings, allow_mixed_devices)?;
    let order = crate::shards::frame_order(recordings)?;
    let first = &recordings[0];
    Ok(Input {
        recordings: order.iter().map(|&k| &recordings[k]).collect(),
        frames: first.frame_states.len() as u32,
    })
}

/// Builds frame `f`'s graph of recording `k` (frame record `fr`): maps scene ids to G-local
/// ids, keeps for a depth-only bake only the edges depth mode needs
/// ([`Recording::depth_mode_edges`]: ties and edges in front of which a fragment may be translucent), and breaks intra-frame cycles.
pub(crate) fn frame_graph(
    k: usize,
    rec: &Recording,
    fr: &trisort_format::FrameRecord,
    depth_only: bool,
) -> Result<FrameGraph, MergeError> {
    let g = &rec.unique_visible;
    let to_local = |t: u32| -> Result<u32, MergeError> {
        g.binary_search(&t)
            .map(|x| x as u32)
            .map_err(|_| MergeError::UnknownTriangle {
                recording: k,
                frame: fr.frame,
                triangle: t,
            })
    };
    let sorted = |v: &[u32], what: &str| -> Result<(), MergeError> {
        if v.windows(2).all(|w| w[0] < w[1]) {
            Ok(())
        } else {
            Err(MergeError::BadFrame {
                recording: k,
                frame: fr.frame,
                why: format!("{what} not ascending"),
            })
        }
    };
    sorted(&fr.visible, "visible set")?;
    sorted(&fr.covered, "covered set")?;
    let visible: Vec<u32> = fr
        .visible
        .iter()
        .map(|&t| to_local(t))
        .collect::<Result<_, _>>()?;
    let mut covered: Vec<u32> = fr
        .covered
        .iter()
        .map(|&t| to_local(t))
        .collect::<Result<_, _>>()?;
    covered.extend_from_slice(&visible);
    covered.sort_unstable();
    covered.dedup();
    let depth_edges;
    let source = if depth_only {
        depth_edges = rec.depth_mode_edges(fr);
        &depth_edges
    } else {
        &fr.edges
    };
    let mut edges: Vec<Edge> = source
        .iter()
        .map(|e| {
            Ok(Edge {
                from: to_local(e.from)?,
                to: to_local(e.to)?,
                weight: e.weight,
            })
        })
        .collect::<Result<_, MergeError>>()?;
    edges.sort_unstable();
    let mut nodes = covered.clone();
    nodes.extend(edges.iter().flat_map(|e| [e.from, e.to]));
    nodes.sort_unstable();
    nodes.dedup();
    let li = |t: u32| nodes.binary_search(&t).expect("endpoint is a node") as u32;
    let local_edges: Vec<(u32, u32, u32)> = edges
        .iter()
        .map(|e| (li(e.from), li(e.to), e.weight))
        .collect();
    let cut = feedback_arc_set(nodes.len(), &local_edges);
    let mut removed = Vec::new();
    let mut kept = Vec::with_capacity(edges.len());
    for (e, &c) in edges.iter().zip(&cut.removed) {
        if c {
            removed.push(*e);
        } else {
            kept.push((li(e.from), li(e.to)));
        }
    }
    kept.dedup();
    let (off, succ) = csr(nodes.len(), kept.iter().copied());
    let (pred_off, pred) = csr(nodes.len(), kept.iter().map(|&(a, b)| (b, a)));
    let topo = topological_order(&off, &succ).expect("cycle breaking leaves an acyclic graph");
    Ok(FrameGraph {
        visible,
        covered,
        nodes,
        off,
        succ,
        pred_off,
        pred,
        topo,
        removed,
        components: (
            cut.exact_components,
            cut.heuristic_components,
            cut.heuristic_weight,
        ),
    })
}
