//! The independent validator: checks a [`Baked`] file against the [`Recording`]s it was merged
//! from, using only the file formats (it shares no code with the merger). It trusts nothing in
//! the baked file that it can derive from the recordings (DESIGN § Second wave).
//!
//! [`check_graph`] checks DESIGN's rules for every frame f, from the two files alone:
//! 1. every t ∈ V_f is drawn exactly once in f; no triangle is drawn twice in f; every copy
//!    (index-buffer position) is drawn in a contiguous run of frames that contains a frame
//!    where its triangle is visible;
//! 2. a drawn triangle that is not visible is allowed by the file's bridge policy: `hidden`
//!    allows any such frame, `ignored` only frames where the triangle has no fragment
//!    (t ∉ C_f), `visible` none;
//! 3. with E_f* = E_f (or the tie edges of a depth-only bake) minus the file's removed edges of
//!    f: every removed edge is an edge of E_f with its weight, lies on a cycle of E_f (both
//!    ends in one strongly connected component) and is *needed* (its head still reaches its
//!    tail in E_f*, so keeping it alone would close a cycle); E_f* is acyclic; and for drawn
//!    a, b with b reachable from a in E_f* through any triangles (drawn or not), a is drawn
//!    before b. The order is checked in linear time: in a topological order of E_f*, each
//!    vertex carries the latest draw position of any drawn ancestor, and every drawn vertex
//!    must come after it. The removed weight is the frame's `unordered_samples`.
//!
//! It also runs [`Baked::check_structure`] and every recording's
//! [`Recording::check_structure`] first, and compares what the file repeats from the
//! recordings: scene and path hashes, settings, device, G, the geometry of G, every frame's
//! camera and node poses, the frame count against the path's, the recordings' own hashes; and
//! every figure of the file's [`trisort_format::MergeStats`] that its draws and the recordings
//! determine (`index_triangles`, `source_triangles`, `unique_visible`, draws per frame,
//! `drawn_not_visible_mean`, `unordered_samples`).
//!
//! [`cycle_edges`] is the same cycle test for others (the image check's unordered mask).
#![deny(missing_docs)]

mod files;
mod graph;
mod rule3;

use serde::Serialize;
use trisort_format::{Baked, Bridge, FrameRecord, Recording};

pub use graph::cycle_edges;

/// One frame's findings.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct FrameReport {
    /// Frame index.
    pub frame: u32,
    /// Rule 3: drawn triangles drawn before some drawn ancestor in E_f* (reachable through
    /// any triangles), plus one if E_f* has a cycle, plus removed edges that are not edges of
    /// E_f, lie on no cycle or are not needed.
    pub graph_violations: u64,
    /// Total weight of the removed intra-frame cycle edges of this frame.
    pub unordered_samples: u64,
    /// Rule 3: removed edges whose ends lie in different strongly connected components of
    /// E_f (nothing forced them out).
    pub removed_not_on_cycle: u64,
    /// Rule 3: removed edges on a cycle whose head does not reach their tail in E_f minus the
    /// removed edges (keeping them would close no cycle).
    pub removed_not_needed: u64,
    /// Rule 1: visible triangles not drawn.
    pub visible_missing: u64,
    /// Rule 1: triangles drawn more than once.
    pub drawn_twice: u64,
    /// Triangles drawn but not visible (fill the bridge policy allows or not).
    pub drawn_not_visible: u64,
    /// Rule 2: drawn-not-visible triangles the bridge policy does not allow.
    pub bridge_violations: u64,
    /// Whether the recorder stopped this frame's peel early (its graph is incomplete).
    pub truncated: bool,
}

impl FrameReport {
    /// Whether the frame passes.
    pub fn ok(&self) -> bool {
        self.graph_violations == 0
            && self.visible_missing == 0
            && self.drawn_twice == 0
            && self.bridge_violations == 0
            && !self.truncated
    }
}

/// The result of [`check_graph`].
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct GraphReport {
    /// Whether every check passed.
    pub ok: bool,
    /// Per frame, in frame order (empty when the files could not be compared at all).
    pub frames: Vec<FrameReport>,
    /// Copies drawn in no frame, in a non-contiguous set of frames, or in no frame where their
    /// triangle is visible.
    pub bad_copies: u64,
    /// Everything found that is not a per-frame count (structure, hashes, statistics) and the
    /// first examples of each per-frame violation, naming the frame and the edge.
    pub problems: Vec<String>,
}

const MAX_PROBLEMS: usize = 40;

impl GraphReport {
    fn problem(&mut self, p: String) {
        if self.problems.len() < MAX_PROBLEMS {
            self.problems.push(p);
        }
    }

    /// Records the problem `p()` when `example` holds (the first few of a kind).
    fn problem_if(&mut self, example: bool, p: impl FnOnce() -> String) {
        if example {
            self.problem(p());
        }
    }
}

/// What the frames' draws add up to, for the statistics check.
#[derive(Default)]
struct Tally {
    /// Draws per frame.
    draws: Vec<u32>,
    /// Σ_f (triangles drawn at f − |V_f|).
    drawn_minus_visible: i64,
    /// Σ_f |V_f|.
    visible: u64,
    /// Σ_f of the removed edges' weight.
    removed_weight: u64,
}

/// Checks rules 1–3 of every frame of `baked` against `recordings` (its frame ranges, any
/// order), and what the file repeats from them. O(Σ_f (|E_f| + draws of f) + |G|) time plus
/// one search inside its component per removed edge; never panics on malformed input.
pub fn check_graph(recordings: &[Recording], baked: &Baked) -> GraphReport {
    let mut report = GraphReport::default();
    if let Err(e) = baked.check_structure() {
        report.problems.push(format!("baked file structure: {e}"));
        return report;
    }
    let frames = match files::collect_frames(recordings, baked, &mut report) {
        Some(f) => f,
        None => return report,
    };
    let mut copies = Copies::new(baked.copies.len());
    let mut frame = FrameCheck {
        baked,
        pos: vec![0; baked.scene_ids.len()],
        stamp: vec![u32::MAX; baked.scene_ids.len()],
    };
    let mut tally = Tally::default();
    for (f, fr) in frames.iter().enumerate() {
        let fm = frame.check(f, fr, &mut copies, &mut tally, &mut report);
        report.frames.push(fm);
    }
    files::check_stats(recordings, baked, &tally, &mut report);
    copies.check(baked, &mut report);
    report.ok = report.problems.is_empty()
        && report.bad_copies == 0
        && report.frames.iter().all(FrameReport::ok);
    report
}

/// Per copy (index-buffer position): the frames that draw it.
struct Copies {
    first: Vec<u32>,
    last: Vec<u32>,
    frames: Vec<u32>,
    /// Whether some frame drawing it sees its triangle.
    visible: Vec<bool>,
}

impl Copies {
    fn new(n: usize) -> Copies {
        Copies {
            first: vec![u32::MAX; n],
            last: vec![0; n],
            frames: vec![0; n],
            visible: vec![false; n],
        }
    }

    /// Rule 1's condition on copies: each is drawn in a contiguous run of frames, one of
    /// them a frame where its triangle is visible.
    fn check(&self, baked: &Baked, report: &mut GraphReport) {
        for k in 0..self.frames.len() {
            let bad = self.frames[k] == 0
                || self.frames[k] != self.last[k] - self.first[k] + 1
                || !self.visible[k];
            if bad {
                report.bad_copies += 1;
                if report.bad_copies <= 5 {
                    let t = baked.copies[k];
                    report.problem(format!(
                        "copy {k} (triangle {}) is drawn in {} frames, none visible or not contiguous",
                        baked.scene_ids.get(t as usize).copied().unwrap_or(t),
                        self.frames[k]
                    ));
                }
            }
        }
    }
}

/// Rules 1–3 frame by frame, reusing per-triangle scratch.
struct FrameCheck<'a> {
    baked: &'a Baked,
    /// Per G-local triangle: its draw position + 1 in the frame of `stamp`.
    pos: Vec<u64>,
    /// Per G-local triangle: the frame that last drew it.
    stamp: Vec<u32>,
}

impl FrameCheck<'_> {
    fn check(
        &mut self,
        f: usize,
        fr: &FrameRecord,
        copies: &mut Copies,
        tally: &mut Tally,
        report: &mut GraphReport,
    ) -> FrameReport {
        let baked = self.baked;
        let ids = &baked.scene_ids;
        let mut fm = FrameReport {
            frame: f as u32,
            truncated: fr.truncated,
            ..FrameReport::default()
        };
        let map_set = |set: &[u32], what: &str, rep: &mut GraphReport| -> Vec<usize> {
            let mut out = Vec::with_capacity(set.len());
            for &t in set {
                match ids.binary_search(&t) {
                    Ok(k) => out.push(k),
                    Err(_) => rep.problem(format!("frame {f}: {what} triangle {t} is not in G")),
                }
            }
            out.sort_unstable();
            out
        };
        let visible = map_set(&fr.visible, "visible", report);
        let covered = map_set(&fr.covered, "covered", report);
        let drawn_count = self.draw_positions(f, &visible, copies, &mut fm);
        tally.draws.push(baked.frames[f].count);
        tally.drawn_minus_visible += drawn_count as i64 - fr.visible.len() as i64;
        tally.visible += fr.visible.len() as u64;
        let f32_ = f as u32;
        let (stamp, pos) = (&self.stamp, &self.pos);
        let drawn = |t: usize| stamp[t] == f32_;
        for &t in &visible {
            if !drawn(t) {
                fm.visible_missing += 1;
            }
        }
        let distinct = drawn_count - fm.drawn_twice;
        fm.drawn_not_visible =
            distinct.saturating_sub((visible.len() as u64).saturating_sub(fm.visible_missing));
        self.bridge(&covered, &visible, &mut fm);
        let rule3 = rule3::Rule3 { f, ids };
        rule3.check(baked, fr, &|t| drawn(t).then(|| pos[t]), &mut fm, report);
        tally.removed_weight += fm.unordered_samples;
        fm
    }

    /// Walks frame f's draws: sets each drawn triangle's position, counts triangles drawn
    /// twice and records which frames draw each copy. Returns the triangles drawn (with
    /// repeats).
    fn draw_positions(
        &mut self,
        f: usize,
        visible: &[usize],
        copies: &mut Copies,
        fm: &mut FrameReport,
    ) -> u64 {
        let f32_ = f as u32;
        let mut p = 0u64;
        for d in self.baked.frame_draws(f) {
            let a = (d.first_index / 3) as usize;
            for k in a..a + (d.index_count / 3) as usize {
                let t = self.baked.copies[k] as usize;
                p += 1;
                if self.stamp[t] == f32_ {
                    fm.drawn_twice += 1;
                } else {
                    self.stamp[t] = f32_;
                    self.pos[t] = p;
                }
                copies.first[k] = copies.first[k].min(f32_);
                copies.last[k] = copies.last[k].max(f32_);
                copies.frames[k] += 1;
                if visible.binary_search(&t).is_ok() {
                    copies.visible[k] = true;
                }
            }
        }
        p
    }

    /// Rule 2: counts the drawn-not-visible triangles the file's bridge policy forbids.
    fn bridge(&self, covered: &[usize], visible: &[usize], fm: &mut FrameReport) {
        let f32_ = fm.frame;
        match self.baked.merge.bridge {
            Bridge::Hidden => {}
            // No triangle may be drawn where it is not visible.
            Bridge::Visible => fm.bridge_violations += fm.drawn_not_visible,
            // Drawn, not visible and covered: not allowed.
            Bridge::Ignored => {
                for &t in covered {
                    if self.stamp[t] == f32_ && visible.binary_search(&t).is_err() {
                        fm.bridge_violations += 1;
                    }
                }
            }
        }
    }
}
