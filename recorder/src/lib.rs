//! The recorder: GPU depth peeling per frame and per MSAA sample into visibility sets and
//! occlusion graphs (paper 003 §3.1, §4.1).
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
//! (`capture/`, `shaders/record/capture.wgsl`; conservative recording's grown peel likewise,
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
mod cycles;
mod envelope;
mod graph;
mod layers;
pub mod partial;
mod peeler;
pub mod tie_rule;
mod visibility;

use std::collections::HashMap;
use std::ops::Range;

use crate::graph::graph_frame;
use crate::layers::{Layers, Purpose};
use crate::tie_rule::{GrownOrder, TieRule};
use crate::visibility::{visibility_frame, PhaseOneConservative};
use trisort_format::{FrameRecord, FrameState, Geometry, Hash, Phase, RecordSettings, Recording};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Gpu;

#[doc(hidden)]
pub use capture::capture_counters;
pub use conservative::Conservative;
use partial::Visibility;
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
    let n = job.frames.len() as u32;

    // Phase 1 over the frames whose visibility decides G.
    let phase1_range = match (&job.known_visible, job.phase) {
        (Some(_), _) => range.clone(),
        (None, Phase::Graphs) => 0..n,
        (None, Phase::Visibility) => range.clone(),
    };
    let mut vis = phase_one(gpu, job, partial, phase1_range, &mut progress)?;
    let g = visible_set(job, &vis)?;

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
        phase_two(gpu, job, partial, &g, &mut frames, &mut progress)?;
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
        // One clip of the whole path; a bundle's caller replaces it with the bundle's clips.
        clips: vec![trisort_format::Clip::whole(
            job.frames.len() as u32,
            None,
            job.path_hash,
        )],
    })
}

/// Phase 1 over `frames`: each frame's visible set, layers and truncation, from `partial`
/// where it holds the frame, else recorded (and stored there).
fn phase_one(
    gpu: &Gpu,
    job: &RecordJob,
    partial: Option<&partial::PartialDir>,
    frames: Range<u32>,
    progress: &mut dyn FnMut(Progress),
) -> Result<HashMap<u32, Visibility>, RecordError> {
    let s = job.settings;
    let mut vis: HashMap<u32, Visibility> = HashMap::new();
    let todo: Vec<u32> = frames
        .clone()
        .filter(|&f| match partial.and_then(|p| p.load_visibility(f)) {
            Some(v) => {
                vis.insert(f, v);
                false
            }
            None => true,
        })
        .collect();
    let total = frames.len() as u32;
    // Frames found in `partial` count as done.
    let resumed = total - todo.len() as u32;
    if todo.is_empty() {
        return Ok(vis);
    }
    let view = view_of(&s);
    let all_ids: Vec<u32> = (0..job.geometry.triangles.len() as u32).collect();
    let (geometry, path, internals) = (job.geometry, job.frames, &job.internals);
    let source = Layers::new(
        gpu,
        geometry,
        &all_ids,
        path,
        view,
        Purpose::Visibility,
        internals,
    )?;
    let conservative = PhaseOneConservative::of(gpu, job, view)?;
    for (k, f) in todo.into_iter().enumerate() {
        let interleaved = job.internals.interleaved_readback;
        let v = visibility_frame(&source, conservative.as_ref(), f, &s, interleaved)?;
        if let Some(p) = partial {
            p.store_visibility(f, &v)?;
        }
        progress(Progress {
            phase: 1,
            frame: f,
            done: resumed + k as u32 + 1,
            total,
            layers: v.1,
        });
        vis.insert(f, v);
    }
    Ok(vis)
}

/// G: the job's known visible set, else the union of phase 1's visible sets; sorted, and
/// checked to name only triangles of the scene.
fn visible_set(job: &RecordJob, vis: &HashMap<u32, Visibility>) -> Result<Vec<u32>, RecordError> {
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
    Ok(g)
}

/// Phase 2 over G (`g`) for each of `frames` (phase 1 filled in): covered set, edges, ties,
/// layers, and what the tie rule brings before saturation, from `partial` where it holds the
/// frame, else recorded (and stored there).
fn phase_two(
    gpu: &Gpu,
    job: &RecordJob,
    partial: Option<&partial::PartialDir>,
    g: &[u32],
    frames: &mut [FrameRecord],
    progress: &mut dyn FnMut(Progress),
) -> Result<(), RecordError> {
    let s = job.settings;
    let view = view_of(&s);
    let total = frames.len() as u32;
    let mut peeler = None;
    let mut grown = None;
    for (k, rec) in frames.iter_mut().enumerate() {
        let f = rec.frame;
        let result = match partial.and_then(|p| p.load_graph(f)) {
            Some(r) => r,
            None => {
                let (geometry, frames, i) = (job.geometry, job.frames, &job.internals);
                let layers = |purpose| Layers::new(gpu, geometry, g, frames, view, purpose, i);
                if peeler.is_none() {
                    peeler = Some(layers(Purpose::Graphs)?);
                }
                if s.robust.conservative && grown.is_none() {
                    grown = Some(layers(Purpose::Grown(s.robust))?);
                }
                // The rule may move any triangle of G: one it brings before saturation
                // joins V_f (`reached`), and the reference moves those of V_f.
                let state = &job.frames[f as usize];
                let rule = TieRule::new(job.geometry, g, state);
                let source = peeler.as_ref().unwrap();
                let grown = grown
                    .as_ref()
                    .map(|layers| (layers, GrownOrder::new(&rule, state, &s)));
                let r = graph_frame(source, grown.as_ref(), f, g, &s, &rule)?;
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
    Ok(())
}
