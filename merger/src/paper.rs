//! The paper's diagonal-by-diagonal merge (§3.2 Figures 2–4, §4 Figure 6, §5.1 Figure 12) as
//! an alternative *seeding* for interval splitting.
//!
//! The visible sets start on the diagonal. For d = 1, 2, …, every cell I = (i, i+d) takes the
//! triangles that its sources L = (i, i+d−1) and B = (i+1, i+d) share, where a triangle absent
//! from one source may still be taken if every frame of that source could bridge it (the
//! paper's ignore lists, here the bridge policy). Then the violators are removed until none
//! is left: if a source S is drawn before I (by the layout), a triangle of I may have no
//! predecessor in S \ I at S's frames; if S is drawn after I, no successor in S \ I. The
//! triangles kept move up: they leave both sources. All cells of a diagonal are merged in
//! parallel from the previous diagonal, then removed from it (Figure 4's serialized
//! subtraction).
//!
//! Departures from the paper: no transitive reduction before violator removal
//! (dropping a middle triangle after reduction loses constraints), and no cycle removal by
//! dropping edges across frames; cycles and the conflicts the pairwise test cannot see (cells
//! other than L and B in a window, paths through undrawn triangles) are left to interval
//! splitting, which runs after this seeding. A triangle that two overlapping cells both kept
//! (a rejected merge) is trimmed so that no frame draws it twice: longer copies keep their
//! frames, shorter ones lose the overlap, and every piece is trimmed as interval splitting trims
//! (to its visible frames, extended through frames without fragments).
//!
//! Cost: O(Σ over cells of (d + 1) · edges of its triangles), quadratic in the segment length
//! — use `--segment` on long paths.

use std::ops::Range;

use rayon::prelude::*;

use crate::cells::{CellOrder, Copy};
use crate::split::Context;

/// Seeds segment `seg` by the paper's diagonal merge; returns non-overlapping copies, each
/// spanning a visible frame of its triangle, together covering every visible (t, f).
pub(crate) fn seed_diagonal_merge(
    cx: &Context<'_>,
    seg: Range<u32>,
    order: CellOrder,
) -> Vec<Copy> {
    let n = (seg.end - seg.start) as usize;
    let s0 = seg.start;
    // diag[d][i]: triangles (sorted) of cell (s0 + i, s0 + i + d).
    let mut diag: Vec<Vec<Vec<u32>>> = vec![(0..n)
        .map(|i| cx.graphs[s0 as usize + i].visible.clone())
        .collect()];
    for d in 1..n {
        let prev = &diag[d - 1];
        let merged: Vec<Vec<u32>> = (0..n - d)
            .into_par_iter()
            .map(|i| {
                let (a, b) = (s0 + i as u32, s0 + (i + d) as u32);
                intersect(cx, order, (a, b), &prev[i], &prev[i + 1])
            })
            .collect();
        // Remove what moved up from the sources: cell i of the previous diagonal is L of
        // merged[i] and B of merged[i − 1].
        let mut next_prev: Vec<Vec<u32>> = prev.clone();
        for (i, cell) in next_prev.iter_mut().enumerate() {
            let up: Vec<&Vec<u32>> = [i.checked_sub(1).map(|k| &merged[k]), merged.get(i)]
                .into_iter()
                .flatten()
                .collect();
            cell.retain(|t| up.iter().all(|m| m.binary_search(t).is_err()));
        }
        diag[d - 1] = next_prev;
        diag.push(merged);
    }
    let mut raw: Vec<Copy> = Vec::new();
    for (d, cells) in diag.iter().enumerate() {
        for (i, tris) in cells.iter().enumerate() {
            let (first, last) = (s0 + i as u32, s0 + (i + d) as u32);
            raw.extend(tris.iter().map(|&t| Copy { t, first, last }));
        }
    }
    remove_overlaps(cx, raw)
}

/// Whether `t`, absent from a source spanning frames `a..=b`, may be taken as if present:
/// not visible there and bridgeable at every frame.
fn wildcard(cx: &Context<'_>, t: u32, a: u32, b: u32) -> bool {
    let vis = &cx.visible_frames[t as usize];
    let p = vis.partition_point(|&f| f < a);
    if p < vis.len() && vis[p] <= b {
        return false;
    }
    match cx.bridge {
        crate::Bridge::Hidden => true,
        crate::Bridge::Ignored => (a..=b).all(|f| !cx.graphs[f as usize].is_covered(t)),
        crate::Bridge::Visible => false,
    }
}

/// The "intersection" I = (a, b) of L = (a, b−1) and B = (a+1, b) after violator removal.
fn intersect(
    cx: &Context<'_>,
    order: CellOrder,
    (a, b): (u32, u32),
    l: &[u32],
    bs: &[u32],
) -> Vec<u32> {
    let mut cand: Vec<u32> = Vec::new();
    for &t in l {
        if bs.binary_search(&t).is_ok() || wildcard(cx, t, a + 1, b) {
            cand.push(t);
        }
    }
    for &t in bs {
        if l.binary_search(&t).is_err() && wildcard(cx, t, a, b - 1) {
            cand.push(t);
        }
    }
    cand.sort_unstable();
    if cand.is_empty() {
        return cand;
    }
    let key_i = order.key(a, b);
    let sources = [
        (l, a..b, order.key(a, b - 1)),
        (bs, a + 1..b + 1, order.key(a + 1, b)),
    ];
    loop {
        let mut bad: Vec<u32> = Vec::new();
        for (src, frames, key_s) in &sources {
            let rest: Vec<u32> = src
                .iter()
                .copied()
                .filter(|t| cand.binary_search(t).is_err())
                .collect();
            if rest.is_empty() {
                continue;
            }
            for f in frames.clone() {
                let fg = &cx.graphs[f as usize];
                if *key_s < key_i {
                    // S before I: no member of I may have a predecessor in S \ I.
                    for &u in &rest {
                        let Some(lu) = fg.local(u) else { continue };
                        for &v in fg.successors(lu) {
                            let tv = fg.nodes[v as usize];
                            if cand.binary_search(&tv).is_ok() {
                                bad.push(tv);
                            }
                        }
                    }
                } else {
                    // I before S: no member of I may have a successor in S \ I.
                    for &t in &cand {
                        let Some(lt) = fg.local(t) else { continue };
                        if fg
                            .successors(lt)
                            .iter()
                            .any(|&v| rest.binary_search(&fg.nodes[v as usize]).is_ok())
                        {
                            bad.push(t);
                        }
                    }
                }
            }
        }
        if bad.is_empty() {
            return cand;
        }
        bad.sort_unstable();
        bad.dedup();
        cand.retain(|t| bad.binary_search(t).is_err());
    }
}

/// Trims copies so that no two copies of a triangle share a frame (longer copies first), and
/// every piece to its visible frames. Sorted by (triangle, first frame).
fn remove_overlaps(cx: &Context<'_>, mut raw: Vec<Copy>) -> Vec<Copy> {
    raw.sort_unstable_by_key(|c| (c.t, std::cmp::Reverse(c.last - c.first), c.first));
    let mut out: Vec<Copy> = Vec::with_capacity(raw.len());
    for group in raw.chunk_by(|x, y| x.t == y.t) {
        let t = group[0].t;
        let mut taken: Vec<(u32, u32)> = Vec::new();
        for c in group {
            let mut pieces = vec![(c.first, c.last)];
            for &(p, q) in &taken {
                pieces = pieces
                    .into_iter()
                    .flat_map(|(a, b)| {
                        if q < a || p > b {
                            vec![(a, b)]
                        } else {
                            let mut v = Vec::new();
                            if a < p {
                                v.push((a, p - 1));
                            }
                            if q < b {
                                v.push((q + 1, b));
                            }
                            v
                        }
                    })
                    .collect();
            }
            for (a, b) in pieces {
                if let Some(piece) = cx.trim(t, a, b) {
                    taken.push(piece);
                }
            }
        }
        taken.sort_unstable();
        out.extend(
            taken
                .into_iter()
                .map(|(first, last)| Copy { t, first, last }),
        );
    }
    out
}
