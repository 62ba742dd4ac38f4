//! The independent validator: checks a [`Baked`] file against the [`Recording`]s it was merged
//! from, using only the file formats (it shares no code with the merger).
//!
//! [`check_graph`] checks DESIGN's rules for every frame f, from the two files alone:
//! 1. every t ∈ V_f is drawn exactly once in f; no triangle is drawn twice in f; every copy
//!    (index-buffer position) is drawn in a contiguous run of frames that contains a frame
//!    where its triangle is visible;
//! 2. a drawn triangle that is not visible is allowed by the file's bridge policy: `hidden`
//!    allows any such frame, `ignored` only frames where the triangle has no fragment
//!    (t ∉ C_f), `visible` none;
//! 3. with E_f* = E_f (or the tie edges of a depth-only bake) minus the file's removed edges of
//!    f: E_f* is acyclic, every removed edge is an edge of E_f with its weight, and for drawn
//!    a, b with b reachable from a in E_f* through any triangles (drawn or not), a is drawn
//!    before b. Checked in linear time: in a topological order of E_f*, each vertex carries
//!    the latest draw position of any drawn ancestor, and every drawn vertex must come after
//!    it. The removed weight is the frame's `unordered_samples`, and its sum must equal the
//!    file's `stats.unordered_samples`.
//!
//! It also runs [`Baked::check_structure`] and every recording's
//! [`Recording::check_structure`] first, and compares the hashes, settings and G.
#![deny(missing_docs)]

use serde::Serialize;
use trisort_format::{Baked, Bridge, Edge, FrameRecord, Phase, Recording};

/// One frame's findings.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct FrameReport {
    /// Frame index.
    pub frame: u32,
    /// Rule 3: drawn triangles drawn before some drawn ancestor in E_f* (reachable through
    /// any triangles), plus one if E_f* has a cycle, plus removed edges that are not edges of
    /// E_f.
    pub graph_violations: u64,
    /// Total weight of the removed intra-frame cycle edges of this frame.
    pub unordered_samples: u64,
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
    /// Everything found that is not a per-frame count (structure, hashes, first examples).
    pub problems: Vec<String>,
}

const MAX_PROBLEMS: usize = 20;

impl GraphReport {
    fn problem(&mut self, p: String) {
        if self.problems.len() < MAX_PROBLEMS {
            self.problems.push(p);
        }
    }
}

/// Checks rules 1–3 of every frame of `baked` against `recordings` (its frame ranges, any
/// order). O(Σ_f (|E_f| + draws of f) + |G|) time; never panics on malformed input.
pub fn check_graph(recordings: &[Recording], baked: &Baked) -> GraphReport {
    let mut report = GraphReport::default();
    if let Err(e) = baked.check_structure() {
        report.problems.push(format!("baked file structure: {e}"));
        return report;
    }
    let frames = match collect_frames(recordings, baked, &mut report) {
        Some(f) => f,
        None => return report,
    };
    let ids = &baked.scene_ids;
    let n = ids.len();
    // (hidden frames allowed, frames without a fragment allowed)
    let (hidden_ok, uncovered_ok) = match baked.merge.bridge {
        Bridge::Hidden => (true, true),
        Bridge::Ignored => (false, true),
        Bridge::Visible => (false, false),
    };
    let ncopies = baked.copies.len();
    // Per copy: first frame, last frame, number of frames, drawn where visible.
    let mut copy_first = vec![u32::MAX; ncopies];
    let mut copy_last = vec![0u32; ncopies];
    let mut copy_frames = vec![0u32; ncopies];
    let mut copy_visible = vec![false; ncopies];
    // Per G-local triangle, reused across frames: draw position + 1 (0 = not drawn) and the
    // stamp of the frame that set it.
    let mut pos = vec![0u64; n];
    let mut stamp = vec![u32::MAX; n];
    let mut total_unordered = 0u64;
    for (f, fr) in frames.iter().enumerate() {
        let f32_ = f as u32;
        let mut fm = FrameReport {
            frame: f32_,
            truncated: fr.truncated,
            ..FrameReport::default()
        };
        let local = |t: u32| ids.binary_search(&t).ok();
        let map_set = |set: &[u32], what: &str, rep: &mut GraphReport| -> Vec<usize> {
            let mut out = Vec::with_capacity(set.len());
            for &t in set {
                match local(t) {
                    Some(k) => out.push(k),
                    None => rep.problem(format!("frame {f}: {what} triangle {t} is not in G")),
                }
            }
            out.sort_unstable();
            out
        };
        let visible = map_set(&fr.visible, "visible", &mut report);
        let covered = map_set(&fr.covered, "covered", &mut report);
        // Draw positions.
        let mut p = 0u64;
        for d in baked.frame_draws(f) {
            let a = (d.first_index / 3) as usize;
            for k in a..a + (d.index_count / 3) as usize {
                let t = baked.copies[k] as usize;
                p += 1;
                if stamp[t] == f32_ {
                    fm.drawn_twice += 1;
                } else {
                    stamp[t] = f32_;
                    pos[t] = p;
                }
                copy_first[k] = copy_first[k].min(f32_);
                copy_last[k] = copy_last[k].max(f32_);
                copy_frames[k] += 1;
                if visible.binary_search(&t).is_ok() {
                    copy_visible[k] = true;
                }
            }
        }
        let drawn = |t: usize| stamp[t] == f32_;
        for &t in &visible {
            if !drawn(t) {
                fm.visible_missing += 1;
            }
        }
        let drawn_count = p - fm.drawn_twice;
        fm.drawn_not_visible =
            drawn_count.saturating_sub((visible.len() as u64).saturating_sub(fm.visible_missing));
        if !uncovered_ok {
            // `visible`: no triangle may be drawn where it is not visible.
            fm.bridge_violations += fm.drawn_not_visible;
        } else if !hidden_ok {
            // Drawn, not visible and covered: not allowed under `ignored`.
            for &t in &covered {
                if drawn(t) && visible.binary_search(&t).is_err() {
                    fm.bridge_violations += 1;
                }
            }
        }
        // Rule 3.
        let removed = baked.removed_edges.get(f).map(Vec::as_slice).unwrap_or(&[]);
        fm.unordered_samples = removed.iter().map(|e| e.weight as u64).sum();
        total_unordered += fm.unordered_samples;
        let (edges, cut) = frame_edges(baked, fr, f, &local, &mut fm, &mut report);
        fm.graph_violations +=
            order_violations(&edges, &cut, &|t| drawn(t).then(|| pos[t]), f, &mut report);
        report.frames.push(fm);
    }
    if total_unordered != baked.stats.unordered_samples {
        report.problem(format!(
            "removed edges weigh {total_unordered} samples, the file reports {}",
            baked.stats.unordered_samples
        ));
    }
    for k in 0..ncopies {
        let bad = copy_frames[k] == 0
            || copy_frames[k] != copy_last[k] - copy_first[k] + 1
            || !copy_visible[k];
        if bad {
            report.bad_copies += 1;
            if report.bad_copies <= 5 {
                report.problem(format!(
                    "copy {k} (triangle {}) is drawn in {} frames, none visible or not contiguous",
                    baked.copies[k], copy_frames[k]
                ));
            }
        }
    }
    report.ok = report.problems.is_empty()
        && report.bad_copies == 0
        && report.frames.iter().all(FrameReport::ok);
    report
}

/// Frame f's graph for rule 3: its edges (ties only for a depth-only bake) in G-local ids,
/// sorted, and which of them the merger removed, each of the file's removed edges matched to
/// one edge of E_f of the same weight. A removed edge that is not in E_f is a graph violation
/// of the frame; an edge leaving G is a problem of the file.
fn frame_edges(
    baked: &Baked,
    fr: &FrameRecord,
    f: usize,
    local: &dyn Fn(u32) -> Option<usize>,
    fm: &mut FrameReport,
    report: &mut GraphReport,
) -> (Vec<(usize, usize, u32)>, Vec<bool>) {
    let source: &[Edge] = if baked.merge.depth_only {
        &fr.ties
    } else {
        &fr.edges
    };
    let mut edges: Vec<(usize, usize, u32)> = Vec::with_capacity(source.len());
    for e in source {
        match (local(e.from), local(e.to)) {
            (Some(a), Some(b)) => edges.push((a, b, e.weight)),
            _ => report.problem(format!("frame {f}: edge {}→{} leaves G", e.from, e.to)),
        }
    }
    edges.sort_unstable();
    let mut cut = vec![false; edges.len()];
    let removed = baked.removed_edges.get(f).map(Vec::as_slice).unwrap_or(&[]);
    for r in removed {
        let hit = edges
            .iter()
            .enumerate()
            .skip(edges.partition_point(|e| (e.0, e.1) < (r.from as usize, r.to as usize)))
            .take_while(|(_, e)| (e.0, e.1) == (r.from as usize, r.to as usize))
            .find(|&(k, e)| !cut[k] && e.2 == r.weight)
            .map(|(k, _)| k);
        match hit {
            Some(k) => cut[k] = true,
            None => {
                fm.graph_violations += 1;
                report.problem(format!(
                    "frame {f}: removed edge {}→{} is not an edge of E_f",
                    r.from, r.to
                ));
            }
        }
    }
    (edges, cut)
}

/// Rule 3 for one frame: the number of drawn vertices drawn before some drawn ancestor in
/// the kept edges (plus one for a cycle). `draw(t)` is t's draw position if drawn.
fn order_violations(
    edges: &[(usize, usize, u32)],
    cut: &[bool],
    draw: &dyn Fn(usize) -> Option<u64>,
    f: usize,
    report: &mut GraphReport,
) -> u64 {
    // Compress the vertices that have kept edges.
    let mut verts: Vec<usize> = edges
        .iter()
        .zip(cut)
        .filter(|(_, &c)| !c)
        .flat_map(|(e, _)| [e.0, e.1])
        .collect();
    verts.sort_unstable();
    verts.dedup();
    let li = |t: usize| verts.binary_search(&t).expect("vertex of a kept edge");
    let m = verts.len();
    let mut off = vec![0usize; m + 1];
    let mut indeg = vec![0u32; m];
    for (e, &c) in edges.iter().zip(cut) {
        if !c {
            off[li(e.0) + 1] += 1;
            indeg[li(e.1)] += 1;
        }
    }
    for k in 0..m {
        off[k + 1] += off[k];
    }
    let mut succ = vec![0usize; off[m]];
    let mut fill = off.clone();
    for (e, &c) in edges.iter().zip(cut) {
        if !c {
            let a = li(e.0);
            succ[fill[a]] = li(e.1);
            fill[a] += 1;
        }
    }
    // Kahn, carrying the latest draw position (+1; 0 = none) of a drawn ancestor.
    let mut latest = vec![0u64; m];
    let mut ready: Vec<usize> = (0..m).filter(|&v| indeg[v] == 0).collect();
    let mut seen = 0;
    let mut violations = 0;
    while let Some(v) = ready.pop() {
        seen += 1;
        let mut carry = latest[v];
        if let Some(p) = draw(verts[v]) {
            if latest[v] > p {
                violations += 1;
                if violations <= 2 {
                    report.problem(format!(
                        "frame {f}: triangle {} (G-local) is drawn before a drawn triangle in front of it",
                        verts[v]
                    ));
                }
            }
            carry = carry.max(p);
        }
        for &w in &succ[off[v]..off[v + 1]] {
            latest[w] = latest[w].max(carry);
            indeg[w] -= 1;
            if indeg[w] == 0 {
                ready.push(w);
            }
        }
    }
    if seen < m {
        report.problem(format!(
            "frame {f}: E_f minus the removed edges still has a cycle"
        ));
        violations += 1;
    }
    violations
}

/// Checks the recordings against the file and returns their frames in order, one per frame
/// of the file.
fn collect_frames<'a>(
    recordings: &'a [Recording],
    baked: &Baked,
    report: &mut GraphReport,
) -> Option<Vec<&'a FrameRecord>> {
    if recordings.is_empty() {
        report.problems.push("no recording given".into());
        return None;
    }
    let mut fatal = false;
    for (k, r) in recordings.iter().enumerate() {
        if let Err(e) = r.check_structure() {
            report
                .problems
                .push(format!("recording {k} is malformed: {e}"));
            return None;
        }
        let mut differs = |what: &str| {
            report.problems.push(format!(
                "recording {k}: {what} differs from the baked file's"
            ));
            fatal = true;
        };
        if r.phase != Phase::Graphs {
            differs("phase (it has no graphs)");
        }
        if r.scene_hash != baked.scene_hash {
            differs("scene hash");
        }
        if r.path_hash != baked.path_hash {
            differs("path hash");
        }
        if r.settings != baked.settings {
            differs("recording settings");
        }
        if r.unique_visible != baked.scene_ids {
            differs("set G of visible triangles");
        }
    }
    if fatal {
        return None;
    }
    let mut hashes: Vec<_> = recordings.iter().map(Recording::content_hash).collect();
    let mut expected = baked.recording_hashes.clone();
    hashes.sort_unstable();
    expected.sort_unstable();
    if hashes != expected {
        report.problem("the recordings' hashes differ from those the file was merged from".into());
    }
    let nframes = baked.frames.len();
    let mut out: Vec<Option<&FrameRecord>> = vec![None; nframes];
    for r in recordings {
        for fr in &r.frames {
            match out.get_mut(fr.frame as usize) {
                Some(slot @ None) => *slot = Some(fr),
                Some(Some(_)) => report.problem(format!("frame {} is recorded twice", fr.frame)),
                None => report.problem(format!(
                    "frame {} lies beyond the file's {nframes} frames",
                    fr.frame
                )),
            }
        }
    }
    let missing = out.iter().filter(|s| s.is_none()).count();
    if missing > 0 {
        report.problems.push(format!(
            "{missing} of the file's {nframes} frames are not in the recordings"
        ));
        return None;
    }
    Some(out.into_iter().map(|s| s.expect("checked above")).collect())
}
