//! The independent validator: checks a [`Baked`] file against the [`Recording`]s it was merged
//! from, using only the file formats (it shares no code with the merger). It trusts nothing in
//! the baked file that it can derive from the recordings, so a merger's mistake cannot vouch
//! for itself.
//!
//! [`check_graph`] checks the rules every baked frame must obey, for every frame f, from the
//! two files alone:
//! 1. every t ∈ V_f is drawn exactly once in f; no triangle is drawn twice in f; every copy
//!    (index-buffer position) is drawn in a contiguous run of frames that contains a frame
//!    where its triangle is visible;
//! 2. a drawn triangle that is not visible is allowed by the file's bridge policy: `hidden`
//!    allows any such frame, `ignored` only frames where the triangle has no fragment
//!    (t ∉ C_f), `visible` none;
//! 3. with E_f* = E_f (or, for a depth-only bake checked for depth mode, the edges depth mode
//!    needs: [`Recording::depth_mode_edges`]) minus the file's removed edges of
//!    f: every removed edge is an edge of E_f with its weight, lies on a cycle of E_f (both
//!    ends in one strongly connected component) and is *needed* (its head still reaches its
//!    tail in E_f*, so keeping it alone would close a cycle); E_f* is acyclic; and for drawn
//!    a, b with b reachable from a in E_f* through any triangles (drawn or not), a is drawn
//!    before b. The order is checked in linear time: in a topological order of E_f*, each
//!    vertex carries the latest draw position of any drawn ancestor, and every drawn vertex
//!    must come after it. The removed weight is the frame's `unordered_samples`. In every
//!    cyclic component of at most 20 triangles the removed weight is also the least possible
//!    (an exact subset programme of the validator's own), as the merger's exact cut makes it.
//!
//! It also runs [`Baked::check_structure`] and every recording's
//! [`Recording::check_structure`] first, and compares what the file repeats from the
//! recordings: scene and path hashes, settings, device, G, the geometry of G, every frame's
//! camera and node poses, the frame count against the path's, the recordings' own hashes; and
//! every figure of the file's [`trisort_format::MergeStats`] that its draws and the recordings
//! determine (`index_triangles`, `source_triangles`, `unique_visible`, draws per frame,
//! `drawn_not_visible_mean`, `unordered_samples`).
//!
//! The file's claims about its own merge are checked where the recordings and its draws
//! decide them: a depth-only file (`merge.depth_only`) is checked against the edges
//! depth mode needs only when it is checked for depth mode ([`PlayedIn::Depth`]); for blend and saturate
//! its order must hold every edge of E_f, as any other file's. The matrix cells
//! (`merge.cells`) must tile the index buffer, each copy drawn in exactly its cell's frames;
//! the frame rate must be the recording's; and the report names the strictest bridge policy
//! the draws obey beside the one the file claims.
//!
//! [`cycle_edges`] is the same cycle test for others (the image check's unordered mask).
#![deny(missing_docs)]

mod files;
mod graph;
mod rule3;

use serde::Serialize;
use trisort_format::{Baked, Bridge, FrameRecord, Recording};

/// The compositing a file is checked for: which of the recording's edges its order must hold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlayedIn {
    /// Blend or saturate (no depth test): every edge of E_f.
    #[default]
    Blend,
    /// Depth mode (depth test on): a depth-only file only the edges depth mode needs
    /// ([`Recording::depth_mode_edges`]: ties, where the depth test keeps the first drawn, and
    /// edges behind translucent fragments); any other file still every edge of E_f.
    Depth,
}

pub use graph::cycle_edges;

/// One frame's findings.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct FrameReport {
    /// Frame index.
    pub frame: u32,
    /// Rule 3: drawn triangles drawn before some drawn ancestor in E_f* (reachable through
    /// any triangles), plus one if E_f* has a cycle, plus removed edges that are not edges of
    /// E_f, lie on no cycle or are not needed, plus one per component whose cut is heavier
    /// than the least (`cut_excess`).
    pub graph_violations: u64,
    /// Total weight of the removed intra-frame cycle edges of this frame.
    pub unordered_samples: u64,
    /// Rule 3: removed edges whose ends lie in different strongly connected components of
    /// E_f (nothing forced them out).
    pub removed_not_on_cycle: u64,
    /// Rule 3: removed edges on a cycle whose head does not reach their tail in E_f minus the
    /// removed edges (keeping them would close no cycle).
    pub removed_not_needed: u64,
    /// Rule 3: samples the file's cut removes beyond the least cut, over the cyclic
    /// components of at most 20 triangles (solved exactly here, as the merger solves them).
    pub cut_excess: u64,
    /// Cyclic components of more than 20 triangles that the file cuts: their cut is checked
    /// to be needed, not to be least.
    pub cut_components_unbounded: u64,
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
    /// Which edges the order was checked against: `"edges"` (E_f) or `"depth"` (a depth-only
    /// file checked for depth mode: [`Recording::depth_mode_edges`], ties and the edges
    /// behind translucent fragments).
    pub checked: &'static str,
    /// The bridge policy the file claims (`merge.bridge`).
    pub bridge_claimed: Bridge,
    /// The strictest bridge policy the file's draws obey (`visible` ⊂ `ignored` ⊂ `hidden`).
    pub bridge_derived: Bridge,
    /// Whether the file is depth-only (`merge.depth_only`): it plays right only in depth mode.
    pub depth_only: bool,
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
    /// The strictest bridge policy the frames so far obey.
    bridge: Bridge,
}

/// The laxer of two bridge policies (`visible` ⊂ `ignored` ⊂ `hidden`).
fn wider(a: Bridge, b: Bridge) -> Bridge {
    let rank = |x: Bridge| match x {
        Bridge::Visible => 0,
        Bridge::Ignored => 1,
        Bridge::Hidden => 2,
    };
    if rank(a) >= rank(b) {
        a
    } else {
        b
    }
}

/// [`check_graph_for`] for blend and saturate ([`PlayedIn::Blend`]): every edge of E_f.
pub fn check_graph(recordings: &[Recording], baked: &Baked) -> GraphReport {
    check_graph_for(recordings, baked, PlayedIn::Blend)
}

/// Checks rules 1–3 of every frame of `baked` against `recordings` (its frame ranges, any
/// order), played as `played`, and what the file repeats from them. O(Σ_f (|E_f| + draws of
/// f) + |G|) time plus one search inside its component per removed edge; never panics on
/// malformed input.
pub fn check_graph_for(recordings: &[Recording], baked: &Baked, played: PlayedIn) -> GraphReport {
    let depth_mode = baked.merge.depth_only && played == PlayedIn::Depth;
    let mut report = GraphReport {
        checked: if depth_mode { "depth" } else { "edges" },
        bridge_claimed: baked.merge.bridge,
        bridge_derived: Bridge::Visible,
        depth_only: baked.merge.depth_only,
        ..GraphReport::default()
    };
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
        depth: depth_mode.then(|| &recordings[0]),
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
    copies.check_cells(baked, &mut report);
    report.bridge_derived = tally.bridge;
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

    /// The file's matrix cells (`merge.cells`, what `inspect --matrix` draws), where it lists
    /// any: they tile the index buffer in order, and every copy of cell (i, j) is drawn in
    /// exactly frames i..=j.
    fn check_cells(&self, baked: &Baked, report: &mut GraphReport) {
        let cells = &baked.merge.cells;
        if cells.is_empty() {
            return;
        }
        let mut next = 0u64;
        let mut wrong = 0u64;
        for (c, cell) in cells.iter().enumerate() {
            let (a, n) = (cell.first_copy as u64, cell.triangles as u64);
            if a != next || n == 0 || cell.first_frame > cell.last_frame {
                report.problem(format!(
                    "merge cell {c} (frames {}..={}, copies {a}..{}) is empty or does not start at copy {next}, where the cells before it end",
                    cell.first_frame,
                    cell.last_frame,
                    a + n,
                ));
                return;
            }
            next = a + n;
            if next > self.first.len() as u64 {
                break;
            }
            for k in a as usize..next as usize {
                if self.frames[k] > 0
                    && (self.first[k] != cell.first_frame || self.last[k] != cell.last_frame)
                {
                    wrong += 1;
                    if wrong <= 3 {
                        report.problem(format!(
                            "copy {k} is drawn in frames {}..={}, its merge cell {c} says {}..={}",
                            self.first[k], self.last[k], cell.first_frame, cell.last_frame
                        ));
                    }
                }
            }
        }
        if next != self.first.len() as u64 {
            report.problem(format!(
                "the merge cells cover copies 0..{next}, the index buffer holds {}",
                self.first.len()
            ));
        }
        if wrong > 3 {
            report.problem(format!(
                "{wrong} copies in all are drawn in other frames than their merge cell says"
            ));
        }
    }
}

/// Rules 1–3 frame by frame, reusing per-triangle scratch.
struct FrameCheck<'a> {
    baked: &'a Baked,
    /// A recording (all have the same G and geometry) whose depth-mode edges rule 3 takes,
    /// for a depth-only file checked for depth mode; `None`: every edge of E_f.
    depth: Option<&'a Recording>,
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
        self.bridge(&covered, &visible, &mut fm, tally);
        let rule3 = rule3::Rule3 { f, ids };
        let depth_edges;
        let source = match self.depth {
            Some(rec) => {
                depth_edges = rec.depth_mode_edges(fr);
                &depth_edges
            }
            None => &fr.edges,
        };
        rule3.check(
            baked,
            source,
            &|t| drawn(t).then(|| pos[t]),
            &mut fm,
            report,
        );
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

    /// Rule 2: counts the drawn-not-visible triangles the file's bridge policy forbids, and
    /// widens the tally's derived policy to what the frame's draws need.
    fn bridge(
        &self,
        covered: &[usize],
        visible: &[usize],
        fm: &mut FrameReport,
        tally: &mut Tally,
    ) {
        let f32_ = fm.frame;
        // Drawn, not visible and covered (it has a fragment here): only `hidden` allows it.
        let hidden = covered
            .iter()
            .filter(|&&t| self.stamp[t] == f32_ && visible.binary_search(&t).is_err())
            .count() as u64;
        let needs = if hidden > 0 {
            Bridge::Hidden
        } else if fm.drawn_not_visible > 0 {
            Bridge::Ignored
        } else {
            Bridge::Visible
        };
        tally.bridge = wider(tally.bridge, needs);
        match self.baked.merge.bridge {
            Bridge::Hidden => {}
            // No triangle may be drawn where it is not visible.
            Bridge::Visible => fm.bridge_violations += fm.drawn_not_visible,
            Bridge::Ignored => fm.bridge_violations += hidden,
        }
    }
}
