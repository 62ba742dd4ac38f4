//! The recorder: GPU depth peeling per frame and per MSAA sample into visibility sets and
//! occlusion graphs (DESIGN.md § Recorder; paper 003 §3.1, §4.1).
//!
//! Phase 1 (visibility) peels every triangle of the scene until each sample is saturated
//! (accumulated opacity ≥ the threshold) or has no fragment left: the triangles reached before
//! saturation form V_f, and their union over the whole path is G. Phase 2 (graphs) peels only
//! G, completely: every triangle seen is covered (C_f), and consecutive fragments at a sample
//! give an edge front → back weighted by the samples showing it (E_f); equal-depth neighbours
//! are also listed as ties.
//!
//! The layers of a sample are its fragments in (depth, id) order. Where the device has
//! primitive ids and writable storage in fragment shaders (`capture::supported`; lavapipe and
//! most desktop Vulkan drivers have both, neither is required by Vulkan), one render pass
//! captures every fragment of the frame on per-sample lists and the host sorts each list
//! (`capture.rs`, `shaders/record/capture.wgsl`; conservative recording's grown peel likewise,
//! `capture_grown.wgsl`). Elsewhere each layer is one depth-peeling render pass: triangles in
//! ascending id order, depth test `Less`, the depth written explicitly, and fragments whose
//! (depth, id) key is not greater than the previous layer's at that sample discarded (see
//! `shaders/record/peel.wgsl`); samples that are finished are masked so later layers do no work
//! there. Both give the same layers, so the same recordings (test `capture_matches_peeling`).
#![deny(missing_docs)]

pub mod bench;
mod capture;
mod conservative;
#[cfg(test)]
mod coverage_test;
mod envelope;
pub mod partial;
mod peeler;
pub mod tie_rule;

use std::collections::HashMap;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering::Relaxed};

use crate::tie_rule::{GrownList, GrownOrder, TieRule};
use trisort_format::{
    Edge, FrameRecord, FrameState, Geometry, Hash, Phase, RecordSettings, Recording, Robust,
};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Gpu;

#[doc(hidden)]
pub use capture::capture_counters;
pub use conservative::Conservative;
use partial::{Graph, Visibility};
#[doc(hidden)]
pub use peeler::readback_counters;
pub use peeler::{Layer, Peeler};

/// How the recorder works inside. The default is how recordings are made; every other value
/// makes the same recordings by another route (the recorder's tests check that each does),
/// for tests that compare the routes and benchmarks that measure what one saves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Internals {
    /// Peel one render pass per layer even where the device can capture every fragment of a
    /// frame in one pass (what devices without primitive ids and fragment storage do).
    pub peel: bool,
    /// `--conservative`: take phase 1's extra triangles from the three conservative passes
    /// ([`Conservative`]) even where the device can capture the envelope bound (what devices
    /// without capture do).
    pub conservative_passes: bool,
    /// Peelers gather every layer interleaved (16 bytes a sample, unpacked sample by
    /// sample), and phase 1 lists visible triangles sample by sample when it peels: the
    /// former readback.
    pub interleaved_readback: bool,
    /// Upload every texture as a player does instead of only what visibility reads (the
    /// linear maps are left out).
    pub full_texture_upload: bool,
    /// Captures start with a pool of this many nodes (instead of one a sample) and hold at
    /// most this many fragments a pass (instead of what one storage binding holds), so that
    /// a frame grows its pool and splits into bands on any device.
    pub pool_limits: Option<(u64, u64)>,
}

/// Errors while recording.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The device lacks something the recorder needs.
    #[error("unsupported device: {0}")]
    Unsupported(String),
    /// The GPU device was lost or a wait failed; finished frames are kept in the partial folder.
    #[error("GPU device error: {0} (finished frames are kept; rerun to resume)")]
    Device(String),
    /// The options do not fit the inputs.
    #[error("{0}")]
    Invalid(String),
    /// Writing or reading partial results failed.
    #[error(transparent)]
    Format(#[from] trisort_format::FormatError),
}

/// What to record.
#[derive(Clone, Debug)]
pub struct RecordJob<'a> {
    /// The full scene geometry (scene ids are indices of its triangles).
    pub geometry: &'a Geometry,
    /// Every frame of the path.
    pub frames: &'a [FrameState],
    /// Scene hash (stored in the recording).
    pub scene_hash: Hash,
    /// Path hash (stored in the recording).
    pub path_hash: Hash,
    /// Settings.
    pub settings: RecordSettings,
    /// Frames to record (half-open); `None` for all.
    pub range: Option<Range<u32>>,
    /// Phase 1 only (`Visibility`) or both (`Graphs`).
    pub phase: Phase,
    /// For phase 2 of a range: G from the union of phase-1 recordings of the whole path; `None`
    /// to run phase 1 over every frame of the path first.
    pub known_visible: Option<Vec<u32>>,
    /// How the recorder works inside (the default: as recordings are made).
    pub internals: Internals,
}

/// Progress reports while recording.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// 1 or 2.
    pub phase: u8,
    /// Frame just finished.
    pub frame: u32,
    /// Frames finished in this phase (including resumed ones).
    pub done: u32,
    /// Frames in this phase.
    pub total: u32,
    /// Layers peeled for this frame.
    pub layers: u32,
}

fn check_job(job: &RecordJob) -> Result<Range<u32>, RecordError> {
    let n = job.frames.len() as u32;
    let s = &job.settings;
    if n == 0 {
        return Err(RecordError::Invalid("the path has no frames".into()));
    }
    let range = job.range.clone().unwrap_or(0..n);
    if range.start >= range.end || range.end > n {
        return Err(RecordError::Invalid(format!(
            "frame range {}..{} is empty or outside the path's 0..{n}",
            range.start, range.end
        )));
    }
    s.validate()
        .map_err(|e| RecordError::Invalid(e.to_string()))?;
    Ok(range)
}

fn view_of(s: &RecordSettings) -> View {
    View {
        width: s.width,
        height: s.height,
        samples: s.samples,
        glass_opacity: s.glass_opacity,
    }
}

/// Whether `gpu` can capture fragments (and so bound `--conservative`'s envelope) rather than
/// only peel: for tests that check what capturing alone does.
#[doc(hidden)]
pub fn can_capture(gpu: &Gpu) -> bool {
    capture::supported(gpu)
}

/// Whether recordings on `gpu` capture (one pass a frame) rather than peel: the device can
/// ([`capture::supported`]: primitive ids and writable storage in fragment shaders), and
/// `internals` do not ask for peeling.
fn captures(gpu: &Gpu, internals: &Internals) -> bool {
    capture::supported(gpu) && !internals.peel
}

/// Where a phase's layers come from: one capture pass a frame, or one peel pass a layer.
enum Layers<'g> {
    Capture(std::cell::RefCell<capture::Capture<'g>>),
    Peel(Peeler<'g>),
}

/// What a phase's layers are for, which decides what is drawn and read back.
#[derive(Clone, Copy)]
enum Purpose {
    /// Phase 1: ids and opacity until saturation (a capture may stop at the first opaque
    /// fragment; a peeler reads back alpha, not depth).
    Visibility,
    /// Phase 2: ids and depth of every layer (a peeler reads back depth, not alpha).
    Graphs,
    /// Phase 2 of `record --conservative`: the triangles grown by this tolerance in pixels
    /// ([`Peeler::grown`]).
    Grown(Robust),
}

impl<'g> Layers<'g> {
    /// Capture where the device can (and `internals` do not say otherwise), else peel, as
    /// `purpose` needs.
    fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        triangles: &[u32],
        frames: &[FrameState],
        view: View,
        purpose: Purpose,
        internals: &Internals,
    ) -> Result<Self, RecordError> {
        let (g, t, f, i) = (geometry, triangles, frames, internals);
        if captures(gpu, internals) {
            let c = match purpose {
                Purpose::Visibility => capture::Capture::new(gpu, g, t, f, view, true, i)?,
                Purpose::Graphs => capture::Capture::new(gpu, g, t, f, view, false, i)?,
                Purpose::Grown(robust) => {
                    let grow = capture::Grow::Peel(&robust);
                    capture::Capture::grown(gpu, g, t, f, view, grow, i)?
                }
            };
            return Ok(Layers::Capture(std::cell::RefCell::new(c)));
        }
        Ok(Layers::Peel(match purpose {
            Purpose::Visibility => {
                Peeler::build(gpu, g, t, f, view, None, i)?.with_readback(true, false)
            }
            // Opacity too: the tie rule's order may reach a triangle before saturation.
            Purpose::Graphs => {
                Peeler::build(gpu, g, t, f, view, None, i)?.with_readback(true, true)
            }
            Purpose::Grown(robust) => {
                Peeler::build(gpu, g, t, f, view, Some(&robust), i)?.with_readback(false, true)
            }
        }))
    }

    fn set_frame_subpixel_offset(&self, frame: u32, offset: [f64; 2]) {
        match self {
            Layers::Capture(c) => c.borrow().set_frame_subpixel_offset(frame, offset),
            Layers::Peel(p) => p.set_frame_subpixel_offset(frame, offset),
        }
    }

    fn triangles(&self) -> usize {
        match self {
            Layers::Capture(c) => c.borrow().triangles(),
            Layers::Peel(p) => p.triangles(),
        }
    }
}

/// Phase 1's conservative set: the envelope bound where the device can capture
/// ([`envelope`]), else the three conservative passes ([`Conservative`]).
enum PhaseOneConservative<'g> {
    Envelope(Box<envelope::Envelope<'g>>),
    Passes(Box<Conservative<'g>>),
}

impl PhaseOneConservative<'_> {
    fn visible(&self, frame: u32) -> Result<Vec<u32>, RecordError> {
        match self {
            PhaseOneConservative::Envelope(e) => e.visible(frame),
            PhaseOneConservative::Passes(c) => c.visible(frame),
        }
    }
}

/// Phase 1 of one frame: the visible set, layers used, and whether `max_layers` truncated it.
/// With robust settings, the union over the sample patterns of [`Robust::offsets`] (layers
/// add up) and the conservative pass's triangles.
fn visibility_frame(
    source: &Layers,
    conservative: Option<&PhaseOneConservative>,
    frame: u32,
    s: &RecordSettings,
    interleaved: bool,
) -> Result<Visibility, RecordError> {
    let mut visible = vec![];
    // Per drawn triangle (phase 1 draws every scene triangle, in id order): reached before
    // saturation. One flag a triangle instead of one entry a sample and layer to sort.
    let reached: Vec<AtomicBool> = (0..source.triangles())
        .map(|_| AtomicBool::new(false))
        .collect();
    let residual = 1.0 - s.saturation;
    let (mut layers, mut truncated) = (0, false);
    let offsets = s.robust.offsets();
    for &offset in &offsets {
        if offsets.len() > 1 {
            source.set_frame_subpixel_offset(frame, offset);
        }
        let (l, t) = match source {
            Layers::Capture(c) => {
                // Each sample's fragments in peel order, walked as the peel's layers would be:
                // until the sample saturates or `max_layers` fragments were taken. Runs of
                // samples in parallel, each with the most fragments it took and whether any
                // were left; the reached flags are shared (a union).
                let (mut most, mut left) = (0u32, false);
                c.borrow_mut().frame(frame, |band| {
                    let runs = band.walk(
                        || (0u32, false),
                        |(most, left), _, list| {
                            let (mut transmittance, mut taken) = (1.0f32, 0u32);
                            for f in list {
                                if taken == s.max_layers {
                                    *left = true;
                                    break;
                                }
                                reached[(f.id - 1) as usize].store(true, Relaxed);
                                taken += 1;
                                transmittance *= 1.0 - f.alpha;
                                if transmittance <= residual {
                                    break;
                                }
                            }
                            *most = (*most).max(taken);
                        },
                    );
                    for (m, l) in runs {
                        most = most.max(m);
                        left |= l;
                    }
                    Ok(())
                })?;
                (most, left)
            }
            Layers::Peel(peeler) => {
                let slots = peeler.slots();
                let mut transmittance = vec![1.0f32; slots];
                peeler.peel(frame, s.max_layers, |_, layer, done| {
                    for i in 0..slots {
                        let id = layer.ids[i];
                        if id == 0 || done[i] != 0 {
                            continue;
                        }
                        // Reached before saturation: visible (its own opacity does not matter).
                        if interleaved {
                            visible.push(id - 1);
                        } else {
                            reached[(id - 1) as usize].store(true, Relaxed);
                        }
                        transmittance[i] *= 1.0 - layer.alpha[i];
                        if transmittance[i] <= residual {
                            done[i] = 1;
                        }
                    }
                    Ok(true)
                })?
            }
        };
        layers += l;
        truncated |= t;
    }
    if offsets.len() > 1 {
        source.set_frame_subpixel_offset(frame, [0.0, 0.0]);
    }
    visible.extend(
        reached
            .iter()
            .enumerate()
            .filter(|(_, r)| r.load(Relaxed))
            .map(|(t, _)| t as u32),
    );
    if let Some(c) = conservative {
        visible.extend(c.visible(frame)?);
    }
    visible.sort_unstable();
    visible.dedup();
    Ok((visible, layers, truncated))
}

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
/// With robust settings, the union over the sample patterns of [`Robust::offsets`] and, for
/// conservative recording, the grown peel (`grown`, [`Peeler::grown`]): edge weights add up.
fn graph_frame(
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
    let union: Vec<Edge> = edges
        .iter()
        .chain(grown.iter().filter(|(k, _)| !edges.contains_key(k)))
        .map(|(&(from, to), &weight)| Edge { from, to, weight })
        .collect();
    let on_cycle: std::collections::HashSet<(u32, u32)> = trisort_verify::cycle_edges(&union)
        .into_iter()
        .map(|e| (e.from, e.to))
        .collect();
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

/// Records a job. Finished frames are stored in `partial` (if given) as they finish, and
/// frames already there (from an interrupted run with the same inputs) are not recorded
/// again. The result is deterministic: identical inputs give identical recordings.
pub fn record(
    gpu: &Gpu,
    job: &RecordJob,
    partial: Option<&partial::PartialDir>,
    mut progress: impl FnMut(Progress),
) -> Result<Recording, RecordError> {
    let range = check_job(job)?;
    let s = job.settings;
    let view = view_of(&s);
    let n = job.frames.len() as u32;
    let all_ids: Vec<u32> = (0..job.geometry.triangles.len() as u32).collect();

    // Phase 1 over the frames whose visibility decides G.
    let phase1_range = match (&job.known_visible, job.phase) {
        (Some(_), _) => range.clone(),
        (None, Phase::Graphs) => 0..n,
        (None, Phase::Visibility) => range.clone(),
    };
    let mut vis: HashMap<u32, (Vec<u32>, u32, bool)> = HashMap::new();
    {
        let todo: Vec<u32> = phase1_range
            .clone()
            .filter(|&f| match partial.and_then(|p| p.load_visibility(f)) {
                Some(v) => {
                    vis.insert(f, v);
                    false
                }
                None => true,
            })
            .collect();
        let total = phase1_range.len() as u32;
        let mut done = total - todo.len() as u32;
        if !todo.is_empty() {
            let source = Layers::new(
                gpu,
                job.geometry,
                &all_ids,
                job.frames,
                view,
                Purpose::Visibility,
                &job.internals,
            )?;
            let conservative = if s.robust.conservative {
                let (g, f, t) = (job.geometry, job.frames, &s.robust);
                // The envelope needs a capture, but not the layers' way: recordings peeled
                // (`Internals::peel`) take the same conservative set as captured ones.
                let (passes, i) = (job.internals.conservative_passes, &job.internals);
                // Scenes of 2^24 triangles or more take the passes too.
                let envelope = capture::supported(gpu) && !passes && envelope::Envelope::fits(g);
                Some(if envelope {
                    PhaseOneConservative::Envelope(Box::new(envelope::Envelope::new(
                        gpu, g, f, view, t, i,
                    )?))
                } else {
                    PhaseOneConservative::Passes(Box::new(Conservative::new(
                        gpu, g, f, view, t, i,
                    )?))
                })
            } else {
                None
            };
            for f in todo {
                let interleaved = job.internals.interleaved_readback;
                let v = visibility_frame(&source, conservative.as_ref(), f, &s, interleaved)?;
                if let Some(p) = partial {
                    p.store_visibility(f, &v)?;
                }
                done += 1;
                progress(Progress {
                    phase: 1,
                    frame: f,
                    done,
                    total,
                    layers: v.1,
                });
                vis.insert(f, v);
            }
        }
    }
    let g: Vec<u32> = match &job.known_visible {
        Some(g) => g.clone(),
        None => {
            let mut g: Vec<u32> = vis.values().flat_map(|v| v.0.iter().copied()).collect();
            g.sort_unstable();
            g.dedup();
            g
        }
    };
    if g.windows(2).any(|w| w[0] >= w[1])
        || g.last()
            .is_some_and(|&t| t as usize >= job.geometry.triangles.len())
    {
        return Err(RecordError::Invalid(
            "the visible set G is not sorted or names triangles the scene lacks".into(),
        ));
    }

    let mut frames: Vec<FrameRecord> = range
        .clone()
        .map(|f| {
            let (visible, l1, t1) = vis.remove(&f).expect("phase 1 covered the range");
            FrameRecord {
                frame: f,
                visible,
                layers: [l1, 0],
                truncated: t1,
                ..Default::default()
            }
        })
        .collect();

    if job.phase == Phase::Graphs {
        let total = frames.len() as u32;
        let mut peeler = None;
        let mut grown = None;
        for (k, rec) in frames.iter_mut().enumerate() {
            let f = rec.frame;
            let result = match partial.and_then(|p| p.load_graph(f)) {
                Some(r) => r,
                None => {
                    let (geometry, frames, i) = (job.geometry, job.frames, &job.internals);
                    let layers = |purpose| Layers::new(gpu, geometry, &g, frames, view, purpose, i);
                    if peeler.is_none() {
                        peeler = Some(layers(Purpose::Graphs)?);
                    }
                    if s.robust.conservative && grown.is_none() {
                        grown = Some(layers(Purpose::Grown(s.robust))?);
                    }
                    // The rule may move any triangle of G: one it brings before saturation
                    // joins V_f (`reached`), and the reference moves those of V_f.
                    let state = &job.frames[f as usize];
                    let rule = TieRule::new(job.geometry, &g, state);
                    let source = peeler.as_ref().unwrap();
                    let grown = grown
                        .as_ref()
                        .map(|layers| (layers, GrownOrder::new(&rule, state, &s)));
                    let r = graph_frame(source, grown.as_ref(), f, &g, &s, &rule)?;
                    if let Some(p) = partial {
                        p.store_graph(f, &r)?;
                    }
                    r
                }
            };
            let (covered, edges, ties, layers, truncated, reached) = result;
            // V_f gains what the tie rule brings before saturation (sorted, no duplicates).
            rec.visible.extend(reached);
            rec.visible.sort_unstable();
            rec.visible.dedup();
            rec.covered = covered;
            rec.edges = edges;
            rec.ties = ties;
            rec.layers[1] = layers;
            rec.truncated |= truncated;
            progress(Progress {
                phase: 2,
                frame: f,
                done: k as u32 + 1,
                total,
                layers,
            });
        }
    }

    let geometry = if job.phase == Phase::Graphs {
        job.geometry.subset(&g)
    } else {
        Geometry::default()
    };
    Ok(Recording {
        tool_version: trisort_format::TOOL_VERSION.to_string(),
        scene_hash: job.scene_hash,
        path_hash: job.path_hash,
        settings: s,
        device: gpu.device_info(),
        phase: job.phase,
        scene_triangles: job.geometry.triangles.len() as u32,
        frame_states: job.frames.to_vec(),
        frames,
        unique_visible: g,
        geometry,
        // The job knows frames, not the path's rate: the CLI sets it from the timeline.
        fps: None,
    })
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
