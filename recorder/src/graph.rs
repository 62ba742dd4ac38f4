//! Phase 2 of a frame: the covered set, the edges between consecutive fragments of each
//! sample in the tie rule's order, and the ties among them, from captured lists or peeled
//! layers; with `--conservative`, the grown layers' edges added where they close no cycle.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering::Relaxed};

use trisort_format::{Edge, RecordSettings};

use crate::capture;
use crate::cycles::on_cycle;
use crate::layers::Layers;
use crate::partial::Graph;
use crate::tie_rule::{self, GrownList, GrownOrder, TieRule};
use crate::Peeler;
use crate::RecordError;

/// Edges and ties between consecutive fragments, by scene ids, with their weights (samples).
struct Pairs<'a> {
    /// Scene ids of the drawn list.
    g: &'a [u32],
    edges: HashMap<(u32, u32), u32>,
    ties: HashMap<(u32, u32), u32>,
}

impl<'a> Pairs<'a> {
    /// No edges, over the drawn list `g`.
    fn new(g: &'a [u32]) -> Self {
        Pairs {
            g,
            edges: HashMap::new(),
            ties: HashMap::new(),
        }
    }

    /// Adds what `other` gathered over the same drawn list: edge and tie weights.
    fn absorb(&mut self, other: Pairs) {
        for (mine, theirs) in [(&mut self.edges, other.edges), (&mut self.ties, other.ties)] {
            for (key, w) in theirs {
                *mine.entry(key).or_default() += w;
            }
        }
    }

    /// Fragment `id` (+ 1) follows fragment `prev` (+ 1) at a sample, at depths `depths`
    /// (previous, this).
    fn pair(&mut self, prev: u32, id: u32, depths: (f32, f32)) {
        let Some(key) = scene_pair(self.g, prev - 1, id - 1) else {
            return;
        };
        *self.edges.entry(key).or_default() += 1;
        if depths.0 == depths.1 {
            *self.ties.entry(key).or_default() += 1;
        }
    }
}

/// A frame's graph as it is gathered: per drawn triangle whether it was covered (shared by
/// parallel walks: a union), and the pairs.
struct GraphParts<'a> {
    covered: Vec<AtomicBool>,
    /// Per drawn triangle: reached before its sample saturates in the tie rule's order at the
    /// recorded pattern, which may bring a triangle phase 1 found hidden to the front.
    reached: Vec<AtomicBool>,
    pairs: Pairs<'a>,
}

impl<'a> GraphParts<'a> {
    /// Nothing covered, no edges, over the drawn list `g`.
    fn new(g: &'a [u32]) -> Self {
        GraphParts {
            covered: g.iter().map(|_| AtomicBool::new(false)).collect(),
            reached: g.iter().map(|_| AtomicBool::new(false)).collect(),
            pairs: Pairs::new(g),
        }
    }
}

/// Phase 2 of one frame over G (`g` = scene ids of the drawn list): covered set, edges, ties.
/// With robust settings, the union over the sample patterns of
/// [`Robust::offsets`](trisort_format::Robust::offsets) and, for conservative recording, the
/// grown peel (`grown`, `Peeler::build` with `grow`): edge weights add up.
pub(crate) fn graph_frame(
    source: &Layers,
    grown: Option<&(&Layers, GrownOrder)>,
    frame: u32,
    g: &[u32],
    s: &RecordSettings,
    rule: &TieRule,
) -> Result<Graph, RecordError> {
    let mut parts = GraphParts::new(g);
    let (mut layers, mut truncated) = (0, false);
    // Robust settings: the union over the sample patterns (edge weights add up).
    let offsets = s.robust.offsets();
    // The grown peel's edges, kept apart: they may only add order, never a cycle.
    let mut grown_edges: HashMap<(u32, u32), u32> = HashMap::new();
    for &offset in &offsets {
        if offsets.len() > 1 {
            source.set_frame_subpixel_offset(frame, offset);
        }
        let (l, t) = match source {
            Layers::Capture(c) => capture_graph(c, frame, s, rule, &mut parts, None)?,
            Layers::Peel(peeler) => peel_graph(peeler, frame, s, rule, &mut parts, None)?,
        };
        layers += l;
        truncated |= t;
    }
    if offsets.len() > 1 {
        source.set_frame_subpixel_offset(frame, [0.0, 0.0]);
    }
    if let Some((grown, order)) = grown {
        let to = Some((&mut grown_edges, order));
        let (l, t) = match grown {
            Layers::Capture(c) => capture_graph(c, frame, s, rule, &mut parts, to)?,
            Layers::Peel(p) => peel_graph(p, frame, s, rule, &mut parts, to)?,
        };
        layers += l;
        truncated |= t;
    }
    let GraphParts {
        covered,
        reached,
        pairs: Pairs {
            mut edges, ties, ..
        },
    } = parts;
    merge_grown_edges(&mut edges, grown_edges);
    // The scene ids of the drawn triangles whose flag is set.
    let flagged = |flags: Vec<AtomicBool>| -> Vec<u32> {
        flags
            .iter()
            .enumerate()
            .filter(|(_, c)| c.load(Relaxed))
            .map(|(k, _)| g[k])
            .collect()
    };
    let covered = flagged(covered);
    let to_edges = |m: HashMap<(u32, u32), u32>| {
        let mut v: Vec<Edge> = m
            .into_iter()
            .map(|((from, to), weight)| Edge { from, to, weight })
            .collect();
        v.sort_unstable();
        v
    };
    let reached = flagged(reached);
    Ok((
        covered,
        to_edges(edges),
        to_edges(ties),
        layers,
        truncated,
        reached,
    ))
}

/// The grown layers' edges as they are gathered, and the order that makes them.
type GrownTo<'a, 'r> = Option<(&'a mut HashMap<(u32, u32), u32>, &'a GrownOrder<'r>)>;

/// Captures frame `frame` with `capture` into `parts` (into `grown` for the grown capture's
/// edges, by [`GrownOrder`]): every sample's fragments in peel order, the first `max_layers`
/// of them, walked in parallel runs of samples, each into its own pairs (covered flags are
/// shared); returns the most fragments a sample took (the layers a peel would have needed) and
/// whether any sample had more.
///
/// The grown capture's lists are walked whole: a grown triangle covers every sample within
/// the tolerance of it, so a small image of a dense scene stacks hundreds of them a sample
/// (CarConcept at 128²), and the one pass has captured them all already; `max_layers` bounds
/// the passes of a peel, which the grown peel (devices that cannot capture) still obeys.
fn capture_graph(
    capture: &std::cell::RefCell<capture::Capture>,
    frame: u32,
    s: &RecordSettings,
    rule: &TieRule,
    parts: &mut GraphParts,
    mut grown: GrownTo,
) -> Result<(u32, bool), RecordError> {
    let order = grown.as_ref().map(|(_, o)| *o);
    let max = if order.is_some() {
        usize::MAX
    } else {
        s.max_layers as usize
    };
    let g = parts.pairs.g;
    let covered = &parts.covered;
    let reached = &parts.reached;
    let residual = 1.0 - s.saturation;
    let (mut most, mut left) = (0usize, false);
    capture.borrow_mut().frame(frame, |band| {
        let runs = band.walk(
            || {
                let (pairs, grown) = (Pairs::new(g), HashMap::new());
                (
                    pairs,
                    grown,
                    0usize,
                    false,
                    Vec::new(),
                    GrownList::default(),
                )
            },
            |(run, run_grown, most, left, scratch, grown_list), slot, list| {
                *left |= list.len() > max;
                let list = &list[..list.len().min(max)];
                *most = (*most).max(list.len());
                for f in list {
                    covered[(f.id - 1) as usize].store(true, Relaxed);
                }
                if let Some(order) = order {
                    grown_list.clear();
                    for f in list {
                        order.push(grown_list, slot, (f.id - 1, f.depth), |a, b| {
                            grown_edge(g, run_grown, a, b)
                        });
                    }
                    return;
                }
                scratch.clear();
                scratch.extend_from_slice(list);
                // The tie rule's order (the peel's layers go through the same window).
                rule.order(scratch, |f| f.id - 1);
                let taken = &scratch[..];
                let mut transmittance = 1.0f32;
                for f in taken {
                    if transmittance <= residual {
                        break;
                    }
                    reached[(f.id - 1) as usize].store(true, Relaxed);
                    transmittance *= 1.0 - f.alpha;
                }
                for k in 1..taken.len() {
                    let (p, f) = (&taken[k - 1], &taken[k]);
                    run.pair(p.id, f.id, (p.depth, f.depth));
                }
            },
        );
        for (run, run_grown, m, l, _, _) in runs {
            parts.pairs.absorb(run);
            if let Some((grown, _)) = grown.as_mut() {
                for (key, w) in run_grown {
                    *grown.entry(key).or_default() += w;
                }
            }
            most = most.max(m);
            left |= l;
        }
        Ok(())
    })?;
    Ok((most as u32, left))
}

/// The edge `front` → `back` (drawn positions, 0-based) by scene ids (`g`), or `None` for two
/// fragments of one triangle: the near plane's clipper cuts a triangle into a fan whose pieces
/// can both cover a sample (and the tie rule can bring them together), with no order between
/// them.
fn scene_pair(g: &[u32], front: u32, back: u32) -> Option<(u32, u32)> {
    let key = (g[front as usize], g[back as usize]);
    (key.0 != key.1).then_some(key)
}

/// Adds one sample's grown edge `front` → `back` (drawn positions) to `to`, by scene ids.
fn grown_edge(g: &[u32], to: &mut HashMap<(u32, u32), u32>, front: u32, back: u32) {
    if let Some(key) = scene_pair(g, front, back) {
        *to.entry(key).or_default() += 1;
    }
}

/// Peels frame `frame` completely with `peeler` into `parts` (into `grown` for the grown
/// peel's edges, by [`GrownOrder`]), each sample's fragments put in the tie rule's order as
/// they come (a window of [`tie_rule::MOVES`] per sample); returns layers peeled and whether
/// `max_layers` truncated the peel.
fn peel_graph(
    peeler: &Peeler,
    frame: u32,
    s: &RecordSettings,
    rule: &TieRule,
    parts: &mut GraphParts,
    grown: GrownTo,
) -> Result<(u32, bool), RecordError> {
    let slots = peeler.slots();
    if let Some((grown, order)) = grown {
        // The grown peel: each layer's fragments ordered against the sample's earlier ones.
        let g = parts.pairs.g;
        let mut lists = vec![GrownList::default(); slots];
        return peeler.peel(frame, s.max_layers, |_, layer, _| {
            for (i, list) in lists.iter_mut().enumerate() {
                let id = layer.ids[i];
                if id == 0 {
                    continue;
                }
                parts.covered[(id - 1) as usize].store(true, Relaxed);
                order.push(list, i, (id - 1, layer.depth[i]), |a, b| {
                    grown_edge(g, grown, a, b)
                });
            }
            Ok(true)
        });
    }
    let residual = 1.0 - s.saturation;
    let mut last = vec![(0u32, 0f32); slots];
    let mut transmittance = vec![1.0f32; slots];
    let mut windows = vec![tie_rule::Window::<(f32, f32)>::default(); slots];
    let mut settle = |i: usize, (id, (depth, alpha)): (u32, (f32, f32)), parts: &mut GraphParts| {
        let (prev, prev_depth) = last[i];
        if prev != 0 {
            parts.pairs.pair(prev, id, (prev_depth, depth));
        }
        last[i] = (id, depth);
        if transmittance[i] > residual {
            parts.reached[(id - 1) as usize].store(true, Relaxed);
            transmittance[i] *= 1.0 - alpha;
        }
    };
    let result = peeler.peel(frame, s.max_layers, |_, layer, _| {
        for (i, window) in windows.iter_mut().enumerate() {
            let id = layer.ids[i];
            if id == 0 {
                continue;
            }
            parts.covered[(id - 1) as usize].store(true, Relaxed);
            let alpha = layer.alpha.get(i).copied().unwrap_or(1.0);
            // Drawn positions go through the rule 0-based, as the capture's do.
            if let Some((p, d)) = rule.push(window, (id - 1, (layer.depth[i], alpha))) {
                settle(i, (p + 1, d), parts);
            }
        }
        Ok(true)
    })?;
    for (i, w) in windows.iter_mut().enumerate() {
        for (p, d) in w.drain() {
            settle(i, (p + 1, d), parts);
        }
    }
    Ok(result)
}

/// Adds the grown peel's edges to the patterns' `edges` (weights add up), except those that
/// would close a cycle the patterns' edges do not have: a grown-only edge on a cycle of the
/// union (both ends in one strongly connected component) is dropped. The union's cycles are
/// then those of the patterns' edges alone (any kept grown-only edge joins two components),
/// so the order the recorded pattern needs is never given up for a speculative one: depths
/// extended past a triangle's edges can disagree where the triangles never overlap.
fn merge_grown_edges(edges: &mut HashMap<(u32, u32), u32>, grown: HashMap<(u32, u32), u32>) {
    if grown.is_empty() {
        return;
    }
    let union: Vec<(u32, u32)> = edges
        .keys()
        .chain(grown.keys().filter(|k| !edges.contains_key(k)))
        .copied()
        .collect();
    let on_cycle = on_cycle(&union);
    for (key, w) in grown {
        match edges.get_mut(&key) {
            Some(v) => *v += w,
            None if !on_cycle.contains(&key) => {
                edges.insert(key, w);
            }
            None => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grown_edges_add_order_but_never_a_cycle() {
        let mut edges: HashMap<(u32, u32), u32> = [((1, 2), 5), ((2, 3), 4)].into();
        let grown: HashMap<(u32, u32), u32> = [
            ((1, 2), 2), // seen by the patterns too: weights add
            ((3, 1), 1), // would close 1 → 2 → 3 → 1: dropped
            ((3, 4), 7), // new order: kept
            ((5, 6), 1),
            ((6, 5), 1), // a cycle of grown edges alone: both dropped
        ]
        .into();
        merge_grown_edges(&mut edges, grown);
        let mut got: Vec<_> = edges.into_iter().collect();
        got.sort();
        assert_eq!(got, vec![((1, 2), 7), ((2, 3), 4), ((3, 4), 7)]);
    }

    #[test]
    fn a_triangle_after_itself_orders_nothing() {
        // Drawn list: scene triangles 5 and 7 (ids 1 and 2). Sample lists A A B (two pieces of
        // one clipped triangle, brought together) and A B.
        let g = [5u32, 7];
        let mut pairs = Pairs::new(&g);
        pairs.pair(1, 1, (0.5, 0.5));
        pairs.pair(1, 2, (0.5, 0.6));
        pairs.pair(1, 1, (0.5, 0.5));
        let edges: Vec<_> = pairs.edges.into_iter().collect();
        assert_eq!(edges, vec![((5, 7), 1)]);
        assert!(pairs.ties.is_empty());
    }
}
