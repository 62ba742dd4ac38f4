//! Building the matrix of one segment by interval splitting: seed each triangle with copies
//! spanning its visible frames (bridged per the policy), then split until rules 1–3 hold (the
//! rules every frame of a baked file obeys, as `trisort-verify` checks them: each visible
//! triangle drawn exactly once, drawn-but-hidden frames allowed by the bridge policy, and
//! every order E_f demands kept).
//!
//! Every round finds, on a snapshot of the copies,
//! - *inter-cell conflicts*: at frame f, a drawn ancestor x of drawn y in E_f* (through any
//!   triangles) whose cell comes later in the layout than y's. Found in linear time per frame
//!   by carrying, in topological order, the latest cell of any drawn ancestor;
//! - *cell cycles* (searched only in rounds with no conflict: they are rare and cost more to
//!   find): cycles in a cell's union-over-frames constraint graph (the camera turned around),
//!   found by Kahn's algorithm and a walk back through the left-over vertices;
//!
//! and then fixes each one whose copies are still untouched this round:
//! - a conflicting pair (x, y), with all the frames `lo..=hi` (sorted set S) where x must
//!   precede y but its cell comes later, by the best pair of splits of x and y among: keep,
//!   cut before lo, cut after hi, isolate lo..=hi, cut after lo, isolate lo, and — where the
//!   triangle is not visible there — drop lo..=hi or drop lo. A frame of S is fixed when x's
//!   piece there lies in an earlier cell than y's, in the same cell (whose own order then
//!   decides), or one of them is no longer drawn. Best = fewest frames of S left unfixed,
//!   then fewest new copies, then the longest pieces; lo is always fixed;
//! - a cycle by splitting one multi-frame copy on it between the frames that demand its
//!   incoming and its outgoing edge, in the middle of the gap that separates them (else
//!   between two frames that only one of them demands, else in the middle of the longest
//!   copy on the cycle).
//!
//! Pieces are trimmed to the triangle's visible frames inside them, then extended (inside the
//! piece) through the neighbouring frames where the triangle has no fragment, which is free
//! (no pixel, no edge) and lets copies share cells; a piece with no visible frame is dropped.
//! So a copy always spans a visible frame, and what it bridges only ever shrinks.
//!
//! Once the rules hold, adjacent copies of a triangle are joined again wherever the joined
//! copy sits strictly between the cells of its drawn ancestors and descendants at every
//! frame it spans (`merge_back`): the greedy fixes often split a copy that later splits made
//! safe to keep whole. With `--bridge hidden` two copies separated by frames where the
//! triangle is hidden may be joined the same way (the joined copy is then drawn, and checked,
//! there too). Joining changes cells, so passes repeat until one joins nothing. On the demo car
//! (48 frames, 256²) this removes 13–14 % of the copies.
//!
//! Each fix adds a copy or shortens one; copies are bounded by Σ|V_f|, so the loop
//! terminates, at worst at one copy per frame on the diagonal, which is always valid. When a
//! round finds nothing the copies satisfy rules 1–3: with no inter-cell conflict every path
//! between drawn copies rises in the layout, so the only remaining demands lie inside cells,
//! and those graphs are acyclic.
//!
//! Variants measured on the synthetic turntable and rejected (`merger/BENCHMARKS.md`):
//! extending seeds through *hidden* frames (every copy starting in the corner cell), letting
//! a fix extend both copies into one cell, snapping seed spans to a frame grid, and fixing
//! only a fraction of the conflicts per round: none saved more than 5 % of the copies, and
//! each cost fill or time.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

mod cell_cycles;

use cell_cycles::find_cell_cycles;

use crate::cells::{CellOrder, Copy, CopyTable, NONE};
use crate::graph::FrameGraph;
use crate::Bridge;

/// What the splitter works on.
pub(crate) struct Context<'a> {
    /// Every frame's graph (global frame index).
    pub graphs: &'a [FrameGraph],
    /// Per G-local triangle: the frames where it is visible, ascending.
    pub visible_frames: &'a [Vec<u32>],
    /// Bridging policy.
    pub bridge: Bridge,
}

impl Context<'_> {
    /// Whether a copy of `t` may span frame `f` where `t` is not visible.
    fn bridgeable(&self, t: u32, f: u32) -> bool {
        match self.bridge {
            Bridge::Hidden => true,
            Bridge::Ignored => !self.graphs[f as usize].is_covered(t),
            Bridge::Visible => false,
        }
    }

    /// The piece `[p, q]` of triangle `t` trimmed to its visible frames, then extended
    /// inside `[p, q]` through the frames next to them where `t` has no fragment; `None` if
    /// `t` is not visible in `[p, q]`.
    ///
    /// The extension is free: at those frames `t` has no fragment, so drawing it changes no
    /// pixel and it has no edge (no order constraint), but a longer copy can share a cell
    /// with more copies (the paper's ignore lists, §4.1).
    pub(crate) fn trim(&self, t: u32, p: u32, q: u32) -> Option<(u32, u32)> {
        let vis = &self.visible_frames[t as usize];
        let a = vis.partition_point(|&f| f < p);
        let b = vis.partition_point(|&f| f <= q);
        if a >= b {
            return None;
        }
        let (mut lo, mut hi) = (vis[a], vis[b - 1]);
        if self.bridge == Bridge::Visible {
            // No extension either: a copy spans only frames where its triangle is visible.
            return Some((lo, hi));
        }
        while lo > p && !self.graphs[lo as usize - 1].is_covered(t) {
            lo -= 1;
        }
        while hi < q && !self.graphs[hi as usize + 1].is_covered(t) {
            hi += 1;
        }
        Some((lo, hi))
    }
}

/// Seeds: per triangle, maximal runs of its visible frames inside `seg` whose gaps are
/// bridgeable, each extended through the neighbouring frames where the triangle has no
/// fragment (see `Context::trim`). Sorted by (triangle, first frame).
pub(crate) fn seed_intervals(cx: &Context<'_>, seg: Range<u32>) -> Vec<Copy> {
    let per_tri: Vec<Vec<Copy>> = (0..cx.visible_frames.len() as u32)
        .into_par_iter()
        .map(|t| {
            let vis = &cx.visible_frames[t as usize];
            let lo = vis.partition_point(|&f| f < seg.start);
            let hi = vis.partition_point(|&f| f < seg.end);
            let mut out = Vec::new();
            let mut run: Option<(u32, u32)> = None;
            for &f in &vis[lo..hi] {
                run = match run {
                    Some((a, b)) if (b + 1..f).all(|g| cx.bridgeable(t, g)) => Some((a, f)),
                    Some((a, b)) => {
                        out.push(Copy {
                            t,
                            first: a,
                            last: b,
                        });
                        Some((f, f))
                    }
                    None => Some((f, f)),
                };
            }
            if let Some((a, b)) = run {
                out.push(Copy {
                    t,
                    first: a,
                    last: b,
                });
            }
            // Extend each run up to its neighbours: a gap between two runs holds a frame
            // where t is covered, so the extensions never meet.
            let bounds: Vec<(u32, u32)> = (0..out.len())
                .map(|k| {
                    let p = if k == 0 {
                        seg.start
                    } else {
                        out[k - 1].last + 1
                    };
                    let q = if k + 1 == out.len() {
                        seg.end - 1
                    } else {
                        out[k + 1].first - 1
                    };
                    (p, q)
                })
                .collect();
            for (c, (p, q)) in out.iter_mut().zip(bounds) {
                let (a, b) = cx.trim(t, p, q).expect("a run has a visible frame");
                c.first = a;
                c.last = b;
            }
            out
        })
        .collect();
    per_tri.into_iter().flatten().collect()
}

/// The pieces `(first, last)` a copy is split into.
type Pieces = Vec<(u32, u32)>;

/// The split copies of one segment.
pub(crate) struct Splitting {
    /// Final copies (rules 1–3 hold for them with the segment's cell order).
    pub copies: Vec<Copy>,
}

/// A bound on the copies of one strategy × layout, shared by its segments: once the copies
/// of all segments together exceed `limit` while splitting (which only adds copies), the
/// combination is abandoned (`auto` sets the limit from its leaders' results).
pub(crate) struct Budget {
    /// Most copies allowed before joining (`u64::MAX`: no bound).
    pub limit: u64,
    /// Copies of this combination's segments so far.
    pub used: AtomicU64,
}

impl Budget {
    /// Adds `more` copies; false when the combination can no longer win.
    fn spend(&self, more: u64) -> bool {
        let used = self.used.fetch_add(more, Ordering::Relaxed) + more;
        used <= self.limit
    }
}

/// Splits `copies` (of segment `seg`, ordered by `order`) until no conflict and no cell cycle
/// is left, or returns `None` once `budget` says the result cannot win. See the module
/// documentation for the policy.
pub(crate) fn split_until_valid(
    cx: &Context<'_>,
    seg: Range<u32>,
    order: CellOrder,
    mut copies: Vec<Copy>,
    budget: &Budget,
) -> Option<Splitting> {
    let mut spent = 0u64;
    let mut table = CopyTable::new(cx.graphs, seg.clone(), cx.visible_frames.len(), &copies);
    // Conflicts per frame of the segment. A frame's conflicts depend only on the copies drawn
    // there, so only frames spanned by a copy that changed are searched again.
    let mut per_frame: Vec<Vec<(u32, u32, u32)>> = vec![Vec::new(); seg.len()];
    let mut dirty: Vec<bool> = vec![true; seg.len()];
    loop {
        let more = copies.len() as u64 - spent;
        spent = copies.len() as u64;
        if !budget.spend(more) {
            return None;
        }
        let stale: Vec<u32> = seg
            .clone()
            .filter(|f| dirty[(f - seg.start) as usize])
            .collect();
        let found: Vec<Vec<(u32, u32, u32)>> = stale
            .par_iter()
            .map(|&f| frame_conflicts(cx, f, order, &copies, table.frame(f)))
            .collect();
        for (f, c) in stale.into_iter().zip(found) {
            per_frame[(f - seg.start) as usize] = c;
            dirty[(f - seg.start) as usize] = false;
        }
        let conflicts: Vec<(u32, u32, u32)> = per_frame.iter().flatten().copied().collect();
        // Cell cycles are rare and costlier to find: look for them once no conflict is left.
        let cycles = if conflicts.is_empty() {
            find_cell_cycles(cx, seg.clone(), &copies, &table)
        } else {
            Vec::new()
        };
        if conflicts.is_empty() && cycles.is_empty() {
            // Joining changes cells, which can allow joins tried earlier: repeat until a pass
            // joins nothing (each pass that continues removes a copy, so this ends).
            let mut copies = merge_back(cx, order, copies, &mut table);
            loop {
                let n = copies.len();
                table = CopyTable::new(cx.graphs, seg.clone(), cx.visible_frames.len(), &copies);
                copies = merge_back(cx, order, copies, &mut table);
                if copies.len() == n {
                    break;
                }
            }
            return Some(Splitting { copies });
        }
        let mut touched = vec![false; copies.len()];
        let mut plans: Vec<(u32, Vec<(u32, u32)>)> = Vec::new();
        // Group the conflicts by pair: one fix considers every frame where the pair conflicts.
        let mut pairs: Vec<(u32, u32, u32)> =
            conflicts.iter().map(|&(f, x, y)| (x, y, f)).collect();
        pairs.sort_unstable();
        let mut groups: Vec<&[(u32, u32, u32)]> =
            pairs.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)).collect();
        groups.sort_by_key(|g| (g[0].2, g[0].0, g[0].1));
        for g in groups {
            let (x, y) = (g[0].0, g[0].1);
            if touched[x as usize] || touched[y as usize] {
                continue;
            }
            let frames: Vec<u32> = g.iter().map(|e| e.2).collect();
            let (px, py) = fix_conflict(cx, order, copies[x as usize], copies[y as usize], &frames);
            touched[x as usize] = true;
            touched[y as usize] = true;
            plans.push((x, px));
            plans.push((y, py));
        }
        for &(x, m) in &cycles {
            if touched[x as usize] {
                continue;
            }
            touched[x as usize] = true;
            let c = copies[x as usize];
            let pieces = [cx.trim(c.t, c.first, m), cx.trim(c.t, m + 1, c.last)];
            plans.push((x, pieces.into_iter().flatten().collect()));
        }
        for (x, pieces) in plans {
            let old = copies[x as usize];
            debug_assert!(!pieces.is_empty(), "a split keeps the visible frames");
            if pieces == [(old.first, old.last)] {
                continue;
            }
            // The pieces lie inside the old span: only its frames see other copies now.
            table.set(old.t, old.first, old.last, NONE);
            for f in old.first..=old.last {
                dirty[(f - seg.start) as usize] = true;
            }
            for (k, &(a, b)) in pieces.iter().enumerate() {
                let c = Copy {
                    t: old.t,
                    first: a,
                    last: b,
                };
                let id = if k == 0 {
                    copies[x as usize] = c;
                    x
                } else {
                    copies.push(c);
                    copies.len() as u32 - 1
                };
                table.set(c.t, a, b, id);
            }
        }
    }
}

/// Joins adjacent copies of a triangle ((a, m) and (m + 1, b) into (a, b)) wherever the
/// joined copy is, at every frame it spans, strictly after the cell of every drawn ancestor
/// and strictly before that of every drawn descendant (through undrawn triangles). Splitting
/// fixes conflicts greedily, one pair at a time, and later splits often make earlier ones
/// unnecessary; this undoes them. The joined copy is drawn at exactly the frames its pieces
/// were, so no other order changes, and its strict position adds no edge inside a cell:
/// the rules still hold. Copies in (triangle, first frame) order, each pair tried once,
/// chains included. Returns the copies left.
fn merge_back(
    cx: &Context<'_>,
    order: CellOrder,
    mut copies: Vec<Copy>,
    table: &mut CopyTable,
) -> Vec<Copy> {
    let mut ids: Vec<u32> = (0..copies.len() as u32).collect();
    ids.sort_unstable_by_key(|&k| (copies[k as usize].t, copies[k as usize].first));
    let mut gone = vec![false; copies.len()];
    // Vertices reached by the current search: those whose mark equals `search`.
    let most = cx.graphs.iter().map(|g| g.nodes.len()).max().unwrap_or(0);
    let mut seen = Marks::new(most);
    let mut stack: Vec<u32> = Vec::new();
    let mut head = ids.first().copied().unwrap_or(NONE);
    for &k in ids.iter().skip(1) {
        let (p, q) = (copies[head as usize], copies[k as usize]);
        let gap_ok = (p.last + 1..q.first).all(|f| cx.bridgeable(p.t, f));
        if p.t != q.t || (p.last + 1 != q.first && !gap_ok) {
            head = k;
            continue;
        }
        let joined = Copy {
            t: p.t,
            first: p.first,
            last: q.last,
        };
        let key = order.key(joined.first, joined.last);
        let fits = (joined.first..=joined.last).all(|f| {
            let fg = &cx.graphs[f as usize];
            let Some(v) = fg.local(joined.t) else {
                return true;
            };
            let drawn = table.frame(f);
            let key_of = |w: u32| {
                let c = copies[drawn[w as usize] as usize];
                order.key(c.first, c.last)
            };
            // Forward: every drawn descendant strictly later; backward: ancestors earlier.
            for forward in [true, false] {
                seen.clear();
                stack.clear();
                stack.push(v);
                while let Some(u) = stack.pop() {
                    let next = if forward {
                        fg.successors(u)
                    } else {
                        fg.predecessors(u)
                    };
                    for &w in next {
                        if drawn[w as usize] != NONE {
                            let kw = key_of(w);
                            if (forward && kw <= key) || (!forward && kw >= key) {
                                return false;
                            }
                        } else if seen.insert(w) {
                            stack.push(w);
                        }
                    }
                }
            }
            true
        });
        if fits {
            copies[head as usize] = joined;
            gone[k as usize] = true;
            table.set(joined.t, joined.first, joined.last, head);
        } else {
            head = k;
        }
    }
    copies
        .into_iter()
        .zip(gone)
        .filter(|(_, g)| !g)
        .map(|(c, _)| c)
        .collect()
}

/// A set of vertices cleared in O(1): a vertex is in it when its mark equals the current
/// round (a `Vec` with `contains` made a search through a hidden chain of 32 k triangles
/// quadratic).
struct Marks {
    mark: Vec<u32>,
    round: u32,
}

impl Marks {
    /// An empty set over vertices below `n`.
    fn new(n: usize) -> Marks {
        Marks {
            mark: vec![0; n],
            round: 1,
        }
    }

    /// Empties the set.
    fn clear(&mut self) {
        if self.round == u32::MAX {
            self.mark.fill(0);
            self.round = 0;
        }
        self.round += 1;
    }

    /// Adds `v`; false if it was in the set already.
    fn insert(&mut self, v: u32) -> bool {
        let m = &mut self.mark[v as usize];
        let new = *m != self.round;
        *m = self.round;
        new
    }
}

/// Inter-cell conflicts of frame `f` (`drawn[v]`: the copy drawn at local vertex v):
/// `(f, x, y)` with x the drawn ancestor of drawn y whose cell is latest in the layout, later
/// than y's; in y's topological order.
fn frame_conflicts(
    cx: &Context<'_>,
    f: u32,
    order: CellOrder,
    copies: &[Copy],
    drawn: &[u32],
) -> Vec<(u32, u32, u32)> {
    let fg = &cx.graphs[f as usize];
    let n = fg.nodes.len();
    // (key + 1, copy) of the latest drawn ancestor; 0 = none.
    let mut best = vec![(0u64, NONE); n];
    let mut out = Vec::new();
    for &v in &fg.topo {
        let v = v as usize;
        let k = drawn[v];
        let mut carry = best[v];
        if k != NONE {
            let c = copies[k as usize];
            let key = order.key(c.first, c.last) + 1;
            if best[v].0 > key {
                out.push((f, best[v].1, k));
            }
            carry = carry.max((key, k));
        }
        for &w in fg.successors(v as u32) {
            let b = &mut best[w as usize];
            *b = (*b).max(carry);
        }
    }
    out
}

/// The pieces the splits of copy `c` considered for a conflict at frames `lo..=hi` can leave,
/// each trimmed: keep; cut before lo; cut after hi; both (isolating lo..=hi); cut after lo;
/// isolate lo; and, where `c.t` is not visible there, drop lo..=hi or drop lo.
fn split_options(cx: &Context<'_>, c: Copy, lo: u32, hi: u32) -> Vec<Pieces> {
    let trim = |p: u32, q: u32| if p > q { None } else { cx.trim(c.t, p, q) };
    let (a, b) = (c.first, c.last);
    let pieces = |cuts: &[(u32, u32)]| -> Vec<(u32, u32)> {
        cuts.iter().filter_map(|&(p, q)| trim(p, q)).collect()
    };
    let mut options = vec![vec![(a, b)]];
    if lo > a {
        options.push(pieces(&[(a, lo - 1), (lo, b)]));
    }
    if hi < b {
        options.push(pieces(&[(a, hi), (hi + 1, b)]));
    }
    if lo > a && hi < b {
        options.push(pieces(&[(a, lo - 1), (lo, hi), (hi + 1, b)]));
    }
    if lo < hi {
        options.push(pieces(&[(a, lo), (lo + 1, b)]));
        if lo > a {
            options.push(pieces(&[(a, lo - 1), (lo, lo), (lo + 1, b)]));
        }
    }
    let invisible = |p: u32, q: u32| cx.trim(c.t, p, q).is_none();
    if invisible(lo, hi) {
        let mut v: Vec<(u32, u32)> = if lo > a {
            trim(a, lo - 1).into_iter().collect()
        } else {
            Vec::new()
        };
        v.extend(trim(hi + 1, b));
        options.push(v);
    }
    if lo < hi && invisible(lo, lo) {
        let mut v: Vec<(u32, u32)> = if lo > a {
            trim(a, lo - 1).into_iter().collect()
        } else {
            Vec::new()
        };
        v.extend(trim(lo + 1, b));
        options.push(v);
    }
    options.dedup();
    options
}

/// The best pair of splits of x and y for a conflict at `frames` (ascending; x must be drawn
/// before y at each): fewest frames left in conflict, then fewest copies, then the longest
/// pieces. Always fixes at least the first frame (isolating it in both copies puts them in
/// the same cell).
fn fix_conflict(
    cx: &Context<'_>,
    order: CellOrder,
    x: Copy,
    y: Copy,
    frames: &[u32],
) -> (Pieces, Pieces) {
    let (lo, hi) = (frames[0], *frames.last().expect("a conflict has a frame"));
    let at =
        |pieces: &[(u32, u32)], f: u32| pieces.iter().copied().find(|&(a, b)| a <= f && f <= b);
    let fixed = |px: &[(u32, u32)], py: &[(u32, u32)], f: u32| match (at(px, f), at(py, f)) {
        (Some(p), Some(q)) => p == q || order.key(p.0, p.1) < order.key(q.0, q.1),
        _ => true,
    };
    let xs = split_options(cx, x, lo, hi);
    let ys = split_options(cx, y, lo, hi);
    type Score = (usize, usize, std::cmp::Reverse<u32>);
    let mut best: Option<(Score, usize, usize)> = None;
    for (a, px) in xs.iter().enumerate() {
        for (b, py) in ys.iter().enumerate() {
            if !fixed(px, py, lo) {
                continue;
            }
            let unfixed = frames.iter().filter(|&&f| !fixed(px, py, f)).count();
            let span: u32 = [at(px, lo), at(py, lo)]
                .into_iter()
                .flatten()
                .map(|(p, q)| q - p)
                .sum();
            let score = (unfixed, px.len() + py.len(), std::cmp::Reverse(span));
            if best.as_ref().is_none_or(|b| score < b.0) {
                best = Some((score, a, b));
            }
        }
    }
    let (_, a, b) = best.expect("isolating a frame in both copies always orders them");
    (xs[a].clone(), ys[b].clone())
}
