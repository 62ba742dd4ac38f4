//! The merger: per-frame occlusion graphs into one sorted triangle list and a sliding window
//! of draws per frame (paper 003 §3.2, §4.2, §5, with the rules below: an order between two
//! drawn triangles counts even when it runs through triangles that are not drawn).
//!
//! Pure CPU: [`Recording`]s in, a [`Baked`] file out. The steps, one file each:
//!
//! | step | file |
//! |---|---|
//! | input checks, G-local frame graphs | `graph.rs` |
//! | cycle breaking inside a frame (minimum-weight feedback arc set per SCC: exact for small components, weighted Eades–Lin–Smyth above) | [`cycles`] |
//! | strategy order and layouts (cell keys) | [`strategy`] |
//! | cells, copies, per-cell constraint graphs | `cells.rs` |
//! | seeding and interval splitting | `split/` |
//! | the paper's diagonal-by-diagonal seeding | `paper.rs` |
//! | serialization (Kahn levels, vertex-cache order) | `serialize.rs` |
//! | transitive reduction of final graphs | [`reduction`] |
//! | index buffer, windows and statistics | `assemble.rs` |
//! | 32-bit counts, checked | `limits.rs` ([`Limit`]) |
//! | synthetic recordings for tests and benchmarks | [`synth`] |
//!
//! **Rules** (the `trisort-verify` crate checks them from the two files alone), for every
//! frame f:
//! 1. every t ∈ V_f is drawn exactly once, no triangle twice, and every copy spans at least
//!    one frame where its triangle is visible;
//! 2. a copy may span a frame where its triangle is not visible only as the bridge policy
//!    allows ([`Bridge`]);
//! 3. with E_f* = E_f minus the removed intra-frame cycle edges: if b is reachable from a in
//!    E_f* through any triangles, drawn or not, and both are drawn, a is drawn before b.
#![deny(missing_docs)]

mod assemble;
mod cells;
pub mod cycles;
mod graph;
mod limits;
mod paper;
pub mod reduction;
mod serialize;
pub mod shards;
mod split;
pub mod strategy;
pub mod synth;

use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use trisort_format::{Baked, MatrixCell, Recording};

pub use limits::Limit;
pub use shards::{
    device_differences, differences, join, list_differences, settings_differences, Difference,
};
pub use strategy::{Layout, Strategy};
pub use trisort_format::{Bridge, Choice, Seeding};

/// The order in which `auto` runs the combinations: those that needed the fewest copies on
/// the synthetic turntable and the demo car first (ILB and IBL), so that the bound they set
/// stops the others early. Only the running time depends on it.
const PRIORITY: [(Strategy, Layout); 12] = [
    (Strategy::Ilb, Layout::Compact),
    (Strategy::Ibl, Layout::Compact),
    (Strategy::Ibl, Layout::Paper),
    (Strategy::Ilb, Layout::Paper),
    (Strategy::Bil, Layout::Compact),
    (Strategy::Bli, Layout::Compact),
    (Strategy::Lib, Layout::Paper),
    (Strategy::Lbi, Layout::Paper),
    (Strategy::Bli, Layout::Paper),
    (Strategy::Lbi, Layout::Compact),
    (Strategy::Bil, Layout::Paper),
    (Strategy::Lib, Layout::Compact),
];

/// How many combinations of `PRIORITY` `auto` runs to the end before bounding the others.
const LEADERS: usize = 2;

/// `auto` abandons a combination once its copies, before adjacent copies are joined, exceed
/// this multiple (numerator, denominator) of the leaders' best final count. Splitting only
/// adds copies and joining removed at most 15 % of them on the demo car, CarConcept and the
/// synthetic turntables, so the bound discards only combinations that end up worse.
const PRUNE_FACTOR: (u64, u64) = (3, 2);

/// Merge options (the flags of `trisort merge`). [`MergeOptions::default`] is the one
/// definition of the merge's defaults: the CLI's flags, `demo`, `bench` and the sweep take
/// theirs from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MergeOptions {
    /// Strategy (default `auto`).
    pub strategy: Choice<Strategy>,
    /// Layout (default `auto`).
    pub layout: Choice<Layout>,
    /// Bridge policy (default [`Bridge::Visible`]).
    pub bridge: Bridge,
    /// Keep only tie edges ([`trisort_format::FrameRecord::ties`]); the bake then plays only
    /// with the depth test.
    pub depth_only: bool,
    /// Cut the path into segments of this many frames, each with its own matrix, so draws per
    /// frame stay bounded on long paths (default [`MergeOptions::DEFAULT_SEGMENT`]; `None`:
    /// one matrix for the whole path).
    pub segment: Option<u32>,
    /// Seeding (default [`Seeding::Interval`]).
    pub seeding: Seeding,
    /// Accept recordings made on different devices (adapter, driver or backend; everything
    /// else must still agree). The baked file then names every device with its frames, each
    /// field of its `device` starting `mixed: ` (`merge --allow-mixed-devices`). Off by
    /// default: graphs from different rasterizers make a bake that is exact on neither.
    pub allow_mixed_devices: bool,
}

impl MergeOptions {
    /// The default segment length: it bounds draws per frame by 64 and changes nothing on
    /// paths of up to 64 frames (BENCHMARKS.md § Sweep).
    pub const DEFAULT_SEGMENT: u32 = 64;
}

impl Default for MergeOptions {
    /// `auto` strategy and layout, bridge `visible`, no depth-only, segments of
    /// [`MergeOptions::DEFAULT_SEGMENT`] frames, interval seeding.
    fn default() -> MergeOptions {
        MergeOptions {
            strategy: Choice::Auto,
            layout: Choice::Auto,
            bridge: Bridge::default(),
            depth_only: false,
            segment: Some(MergeOptions::DEFAULT_SEGMENT),
            seeding: Seeding::default(),
            allow_mixed_devices: false,
        }
    }
}

/// Why recordings could not be merged. Variants name the recording (its index in the slice
/// given to [`merge`]) and, where it applies, the frame and triangle.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// No recording was given.
    #[error("no recording to merge")]
    NoRecordings,
    /// A recording fails its own structure check ([`Recording::check_structure`]).
    #[error("recording {recording} is malformed: {why}")]
    Invalid {
        /// Index of the recording.
        recording: usize,
        /// The first problem found.
        why: trisort_format::StructureError,
    },
    /// A recording holds only phase 1 (visibility).
    #[error("recording {recording} has no graphs (phase 1 only); record phase 2 first")]
    NotGraphs {
        /// Index of the recording.
        recording: usize,
    },
    /// A recording differs from the first in something that must be equal.
    #[error("recording {recording} differs from recording 0 in its {what}")]
    Mismatch {
        /// Index of the recording.
        recording: usize,
        /// What differs.
        what: &'static str,
    },
    /// A recording differs from recording 0 in what makes it part of another bake (see
    /// [`differences`]): device, driver, settings, scene, path, phase or G.
    #[error("recording {recording} differs from recording 0: {differences}")]
    Differs {
        /// Index of the recording.
        recording: usize,
        /// Every difference found, with both values, `; `-separated.
        differences: String,
    },
    /// A recording holds no frame.
    #[error("recording {recording} holds no frame")]
    NoFrames {
        /// Index of the recording.
        recording: usize,
    },
    /// The frame ranges do not follow each other.
    #[error("recording {recording} covers frames {found:?}, but frame {expected} comes next")]
    NotContiguous {
        /// Index of the recording.
        recording: usize,
        /// The frame that should start it.
        expected: u32,
        /// Its range.
        found: Range<u32>,
    },
    /// The recordings end before the path does.
    #[error("the recordings cover frames 0..{covered} of a {total}-frame path")]
    MissingFrames {
        /// Frames covered.
        covered: u32,
        /// Frames of the path.
        total: u32,
    },
    /// A frame names a triangle outside G.
    #[error("recording {recording}, frame {frame}: triangle {triangle} is not in G")]
    UnknownTriangle {
        /// Index of the recording.
        recording: usize,
        /// Frame.
        frame: u32,
        /// Scene triangle id.
        triangle: u32,
    },
    /// A frame record is malformed.
    #[error("recording {recording}, frame {frame}: {why}")]
    BadFrame {
        /// Index of the recording.
        recording: usize,
        /// Frame.
        frame: u32,
        /// What is wrong.
        why: String,
    },
    /// `segment` is zero.
    #[error("segment length must be at least one frame")]
    ZeroSegment,
    /// A count exceeds what the merger's or the baked file's 32-bit offsets address.
    #[error("{count} {limit} exceed the limit of {max} ({why}); {hint}",
            max = .limit.max(), why = .limit.why(), hint = .limit.hint())]
    TooLarge {
        /// Which limit.
        limit: Limit,
        /// The count found (saturated at `u64::MAX`).
        count: u64,
    },
}

/// Merges recordings (contiguous frame ranges of one scene and path, any order) into a
/// [`Merged`] file whose draws satisfy rules 1–3 at every frame; [`Merged::lit`] attaches
/// the light and gives the [`Baked`] file. The merger does not choose a light: whoever runs
/// the pipeline does (the studio by default).
///
/// For every strategy × layout the options allow (in parallel with rayon), each segment is
/// seeded, split until valid, its adjacent copies joined where the rules allow, and
/// serialized; the result kept is the best by the objective (fewest index triangles, then
/// fewest draws in the worst frame, then the first in [`Strategy::ALL`] × [`Layout::ALL`]
/// order). A path of several segments picks the combination by that objective on its first
/// segment and merges every segment with it. With several combinations, ILB and IBL compact
/// run first and the others are abandoned once their copies exceed 1.5 × the better of those
/// two (`PRUNE_FACTOR`). Output ids are G-local. The result is deterministic — the same
/// inputs give the same bytes whatever the thread count — so `stats.seconds` is left 0
/// (callers measure and report the time).
///
/// Errors when the recordings are not frame ranges of one path recorded with graphs (see
/// [`MergeError`]). Frames the recorder marked truncated are merged as recorded (their graph
/// is incomplete); the validator fails on them. Recordings made on different devices (adapter,
/// driver or backend) are refused ([`MergeError::Differs`]) unless
/// [`MergeOptions::allow_mixed_devices`]: their graphs come from different rasterizers, so
/// the bake would be exact on neither.
pub fn merge(recordings: &[Recording], opts: &MergeOptions) -> Result<Merged, MergeError> {
    if opts.segment == Some(0) {
        return Err(MergeError::ZeroSegment);
    }
    let input = graph::check_recordings(recordings, opts.allow_mixed_devices)?;
    let index_of = |r: &Recording| {
        recordings
            .iter()
            .position(|x| std::ptr::eq(x, r))
            .unwrap_or(0)
    };
    let jobs: Vec<(usize, &Recording, &trisort_format::FrameRecord)> = input
        .recordings
        .iter()
        .flat_map(|&r| r.frames.iter().map(move |fr| (index_of(r), r, fr)))
        .collect();
    let graphs: Vec<graph::FrameGraph> = jobs
        .par_iter()
        .map(|&(k, r, fr)| graph::frame_graph(k, r, fr, opts.depth_only))
        .collect::<Result<_, _>>()?;
    let first = input.recordings[0];
    let g = first.unique_visible.len();
    let mut visible_frames: Vec<Vec<u32>> = vec![Vec::new(); g];
    for (f, fg) in graphs.iter().enumerate() {
        for &t in &fg.visible {
            visible_frames[t as usize].push(f as u32);
        }
    }
    let cx = split::Context {
        graphs: &graphs,
        visible_frames: &visible_frames,
        bridge: opts.bridge,
    };
    let len = opts.segment.unwrap_or(input.frames.max(1));
    let segments: Vec<Range<u32>> = (0..input.frames)
        .step_by(len as usize)
        .map(|s| s..(s + len).min(input.frames))
        .collect();
    let vertices: Vec<u64> = graphs.iter().map(|g| g.nodes.len() as u64).collect();
    limits::check_segments(&vertices, &segments)?;
    let combos: Vec<(Strategy, Layout)> = opts
        .strategy
        .candidates()
        .into_iter()
        .flat_map(|s| opts.layout.candidates().into_iter().map(move |l| (s, l)))
        .collect();
    let best = best_combination(&cx, &segments, &combos, opts.seeding, first)?;
    let recording_hashes: Vec<trisort_format::Hash> = input
        .recordings
        .par_iter()
        .map(|r| r.content_hash())
        .collect();
    let mut baked = best.into_baked(first, recording_hashes, &graphs, opts);
    baked.device = shards::device_of(&input.recordings);
    Ok(Merged { baked })
}

/// A merged file without its light: every part of the [`Baked`] file but the environment,
/// which the merger does not choose. [`Merged::lit`] attaches it.
#[derive(Clone, Debug)]
pub struct Merged {
    /// The baked file, its environment a placeholder that [`Merged::lit`] replaces.
    baked: Baked,
}

impl Merged {
    /// The baked file, lit by `environment`.
    pub fn lit(mut self, environment: trisort_format::Environment) -> Baked {
        self.baked.environment = environment;
        self.baked
    }

    /// The merge's statistics (the same as the lit file's).
    pub fn stats(&self) -> &trisort_format::MergeStats {
        &self.baked.stats
    }
}

/// The best combination of `combos` for `segments` (see [`merge`]). With several segments and
/// several combinations, the combinations compete on the first segment alone
/// ([`best_of`]) and only the winner merges the whole path: every combination over every
/// segment cost 20× the winner's merge on the car tour (1,581 s against 79 s, 301 frames,
/// BENCHMARKS § Raster profiles), and segments of one path favour the same combination. One
/// segment (paths up to the segment length) decides as before. Should the winner exceed a
/// 32-bit limit over the whole path, every combination is tried there after all.
fn best_combination(
    cx: &split::Context<'_>,
    segments: &[Range<u32>],
    combos: &[(Strategy, Layout)],
    seeding: Seeding,
    first: &Recording,
) -> Result<assemble::Assembled, MergeError> {
    if segments.len() > 1 && combos.len() > 1 {
        let probe = best_of(cx, &segments[..1], combos, seeding, first)?;
        let winner = [(probe.strategy, probe.layout)];
        if let Ok(a) = best_of(cx, segments, &winner, seeding, first) {
            return Ok(a);
        }
    }
    best_of(cx, segments, combos, seeding, first)
}

/// Runs every combination of `combos` and keeps the best (see [`merge`]). Combinations run
/// in `PRIORITY` order (the ones that usually win first). The first `LEADERS` run to the
/// end; the others share a fixed bound derived from the leaders' best result and stop once
/// their copies before joining exceed it (see `PRUNE_FACTOR`). The bound depends only on the
/// leaders' results, never on timing, so the output is the same whatever the thread count.
/// A combination whose counts exceed a 32-bit limit ([`Limit`]) is skipped; if every one
/// does, the first one's error (in `PRIORITY` order) is returned.
fn best_of(
    cx: &split::Context<'_>,
    segments: &[Range<u32>],
    combos: &[(Strategy, Layout)],
    seeding: Seeding,
    first: &Recording,
) -> Result<assemble::Assembled, MergeError> {
    let triangles = &first.geometry.triangles;
    let mut queue: Vec<usize> = (0..combos.len()).collect();
    queue.sort_by_key(|&k| {
        PRIORITY
            .iter()
            .position(|p| *p == combos[k])
            .unwrap_or(PRIORITY.len())
    });
    type Outcome = Result<Option<assemble::Assembled>, MergeError>;
    let run = |ks: &[usize], limit: u64| -> Vec<(usize, Outcome)> {
        let next = AtomicUsize::new(0);
        (0..ks.len())
            .into_par_iter()
            .with_max_len(1)
            .map(|_| {
                let k = ks[next.fetch_add(1, Ordering::Relaxed)];
                let (s, l) = combos[k];
                (
                    k,
                    assemble::build(cx, segments, s, l, seeding, triangles, limit),
                )
            })
            .collect()
    };
    let (leaders, rest) = queue.split_at(LEADERS.min(queue.len()));
    let mut results = run(leaders, u64::MAX);
    if !rest.is_empty() {
        // No bound if no leader could be laid out.
        let lead = results
            .iter()
            .filter_map(|(_, a)| Some(a.as_ref().ok()?.as_ref()?.copies.len() as u64))
            .min()
            .map_or(u64::MAX, |c| {
                c.saturating_mul(PRUNE_FACTOR.0) / PRUNE_FACTOR.1
            });
        results.extend(run(rest, lead));
    }
    // In `PRIORITY` order: the pool finishes them in any order.
    results.sort_by_key(|(k, _)| queue.iter().position(|q| q == k));
    let mut first_error = None;
    let mut best: Option<(usize, assemble::Assembled)> = None;
    for (k, outcome) in results {
        match outcome {
            Ok(Some(a)) => {
                let key = |k: usize, a: &assemble::Assembled| {
                    (a.copies.len(), a.draws_per_frame_max(), k)
                };
                if best.as_ref().is_none_or(|(bk, b)| key(k, &a) < key(*bk, b)) {
                    best = Some((k, a));
                }
            }
            Ok(None) => {}
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    match (best, first_error) {
        (Some((_, a)), _) => Ok(a),
        (None, Some(e)) => Err(e),
        (None, None) => unreachable!("leaders are never abandoned"),
    }
}

/// The non-empty cells of a baked file's matrix as `(first frame, last frame, triangles)`, in
/// index-buffer order: the data of `trisort inspect --matrix` (the paper's Figure 14).
pub fn cell_counts(baked: &Baked) -> Vec<(u32, u32, u32)> {
    baked
        .merge
        .cells
        .iter()
        .map(|c: &MatrixCell| (c.first_frame, c.last_frame, c.triangles))
        .collect()
}
