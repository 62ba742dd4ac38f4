//! The rounds of splitting: detect, cut, and detect again around what changed.
//!
//! Cutting a triangle changes its vertices, and the pieces of a triangle can cross a
//! triangle that the whole one only touched within precision (the test of `narrow` looks at
//! corners, and a piece has new ones). So after each round of cuts the detector runs again
//! on the pairs that involve a piece made in that round, or a triangle of a pair left
//! crossing, and cuts what it finds, for at most [`MAX_ROUNDS`] rounds. Pairs found again
//! whose two triangles did not change since they were last cut at are not cut again: they
//! are left crossing. The last detection is exact for the whole output: a pair with neither
//! triangle changed nor left crossing was already found not to cross.

use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap};

use rayon::prelude::*;
use trisort_format::{FrameState, Geometry, Vertex};

use crate::cut::{cut_triangle, interpolate, Bary, Cut, Pieces, Source};
use crate::detect::Prepared;
use crate::edges::{self, EdgeChanges};
use crate::{SplitOptions, SplitReport, SplitScene};

/// Most rounds of cutting (the first included).
pub(crate) const MAX_ROUNDS: u32 = 4;

/// See [`crate::split_intersections`]: the pairs of each rigid group, then (with
/// [`SplitOptions::across_groups`] and more than one group) the pairs of different groups as
/// the first frame places them, on the first pass's output.
pub(crate) fn split(
    geometry: &Geometry,
    frames: &[FrameState],
    options: &SplitOptions,
) -> SplitScene {
    let within = split_pass(geometry, frames, options, false);
    if !options.across_groups || within.report.groups <= 1 {
        return within;
    }
    let across = split_pass(&within.geometry, frames, options, true);
    let r = across.report;
    let mut report = within.report;
    report.pairs_split_across_groups = r.pairs_split;
    report.pairs_skipped_sliver += r.pairs_skipped_sliver;
    report.pairs_below_precision += r.pairs_below_precision;
    report.candidate_pairs += r.candidate_pairs;
    report.rounds += r.rounds;
    report.neighbours_split += r.neighbours_split;
    report.t_junctions_left += r.t_junctions_left;
    report.triangles_added = (across.geometry.triangles.len() - geometry.triangles.len()) as u64;
    let origin: Vec<u32> = across
        .origin
        .iter()
        .map(|&t| within.origin[t as usize])
        .collect();
    report.triangles_split = origin
        .windows(2)
        .enumerate()
        .filter(|&(k, w)| w[0] == w[1] && (k == 0 || origin[k - 1] != w[0]))
        .count() as u64;
    let mut skipped = within.skipped;
    skipped.extend(across.skipped.iter().map(|&[a, b]| {
        let (a, b) = (within.origin[a as usize], within.origin[b as usize]);
        [a.min(b), a.max(b)]
    }));
    skipped.sort_unstable();
    skipped.dedup();
    SplitScene {
        geometry: across.geometry,
        origin,
        skipped,
        report,
    }
}

/// One pass of rounds of detection and cuts: within rigid groups, or (`across`) between
/// different groups in the first frame's world space.
fn split_pass(
    geometry: &Geometry,
    frames: &[FrameState],
    options: &SplitOptions,
    across: bool,
) -> SplitScene {
    let n = geometry.triangles.len();
    let mut current = Cow::Borrowed(geometry);
    let mut origin: Vec<u32> = (0..n as u32).collect();
    let mut query: Option<Vec<bool>> = None;
    let mut changed: Option<Vec<bool>> = None;
    let mut report = SplitReport::default();
    let mut input_pairs = Vec::new();
    let mut left;
    loop {
        let prepared = if across {
            Prepared::across_groups(&current, frames)
        } else {
            Prepared::new(&current, frames)
        };
        let found = prepared.find(query.as_deref());
        if report.rounds == 0 {
            report.groups = match &prepared.rigid {
                Some(rigid) => rigid.iter().map(|&g| g as usize + 1).max().unwrap_or(0),
                None => prepared.group_count,
            };
            report.candidate_pairs = found.candidates;
            report.pairs_below_precision = found.below_precision;
            input_pairs.clone_from(&found.pairs);
        }
        let is_new = |t: u32| changed.as_ref().is_none_or(|c| c[t as usize]);
        let (retry, known): (Vec<[u32; 2]>, Vec<[u32; 2]>) = found
            .pairs
            .iter()
            .partition(|&&[a, b]| is_new(a) || is_new(b));
        left = known;
        if retry.is_empty() {
            break;
        }
        if report.rounds == MAX_ROUNDS {
            left.extend(retry);
            left.sort_unstable();
            break;
        }
        let round = cut_round(&current, &prepared, &retry, options);
        report.rounds += 1;
        report.neighbours_split += round.neighbours_split;
        report.t_junctions_left += round.t_junctions_left;
        // What the next detection asks about: the pieces made now, and the triangles of the
        // pairs left crossing.
        let mut first_piece = vec![u32::MAX; current.triangles.len()];
        for (k, &t) in round.origin.iter().enumerate().rev() {
            first_piece[t as usize] = k as u32;
        }
        let mut next_changed = vec![false; round.origin.len()];
        for (k, &t) in round.origin.iter().enumerate() {
            next_changed[k] = round.split[t as usize];
        }
        let mut next_query = next_changed.clone();
        for &[a, b] in left.iter().chain(&round.skipped) {
            for t in [a, b] {
                if !round.split[t as usize] {
                    next_query[first_piece[t as usize] as usize] = true;
                }
            }
        }
        origin = round.origin.iter().map(|&t| origin[t as usize]).collect();
        current = Cow::Owned(round.geometry);
        changed = Some(next_changed);
        query = Some(next_query);
    }
    finish(
        geometry,
        current.into_owned(),
        origin,
        &input_pairs,
        &left,
        report,
    )
}

/// The scene and its report from the final state: `left` are the crossing pairs of `out`.
fn finish(
    input: &Geometry,
    out: Geometry,
    origin: Vec<u32>,
    input_pairs: &[[u32; 2]],
    left: &[[u32; 2]],
    mut report: SplitReport,
) -> SplitScene {
    let mut skipped: Vec<[u32; 2]> = left
        .iter()
        .map(|&[a, b]| {
            let (a, b) = (origin[a as usize], origin[b as usize]);
            [a.min(b), a.max(b)]
        })
        .collect();
    skipped.sort_unstable();
    skipped.dedup();
    report.pairs_split = input_pairs
        .iter()
        .filter(|p| skipped.binary_search(p).is_err())
        .count() as u64;
    report.pairs_skipped_sliver = skipped.len() as u64;
    report.triangles_added = (out.triangles.len() - input.triangles.len()) as u64;
    // Runs of equal origins longer than one: the input triangles replaced by pieces.
    report.triangles_split = origin
        .windows(2)
        .enumerate()
        .filter(|&(k, w)| w[0] == w[1] && (k == 0 || origin[k - 1] != w[0]))
        .count() as u64;
    SplitScene {
        geometry: out,
        origin,
        skipped,
        report,
    }
}

/// One round of cuts.
struct Round {
    /// The geometry after the round.
    geometry: Geometry,
    /// Per output triangle, the triangle of the round's input it comes from.
    origin: Vec<u32>,
    /// Per triangle of the round's input: whether it was replaced by pieces.
    split: Vec<bool>,
    /// The pairs cut at whose cut was skipped on both triangles.
    skipped: Vec<[u32; 2]>,
    /// Triangles split only to take the cut points on their edges.
    neighbours_split: u64,
    /// Cut points on an edge that a triangle sharing it could not take (slivers).
    t_junctions_left: u64,
}

/// A vertex of an output triangle of a cut: an existing vertex or a new one.
#[derive(Clone, Copy, Debug)]
enum PieceVertex {
    Old(u32),
    New(Vertex),
}

/// What became of one triangle: its output triangles (`None`: unchanged) and the edge points
/// it could not take.
struct Outcome {
    triangles: Option<Vec<[PieceVertex; 3]>>,
    dropped: u64,
}

/// Cuts every triangle of `pairs` along the planes of its partners, then inserts the points
/// the cuts put on edges into every triangle sharing those edges; in parallel.
fn cut_round(
    geometry: &Geometry,
    prepared: &Prepared,
    pairs: &[[u32; 2]],
    options: &SplitOptions,
) -> Round {
    let PairCuts {
        triangles: to_cut,
        lists,
        pieces: cuts,
    } = cut_pairs(geometry, prepared, pairs, options);
    let mut resolved = vec![false; pairs.len()];
    for ((&t, c), list) in to_cut.iter().zip(&cuts).zip(&lists) {
        debug_assert_eq!(list.len(), c.applied.len(), "triangle {t}");
        for (&(_, p), &ok) in list.iter().zip(&c.applied) {
            resolved[p] |= ok;
        }
    }
    let skipped = pairs
        .iter()
        .zip(&resolved)
        .filter(|(_, &r)| !r)
        .map(|(&pair, _)| pair)
        .collect();

    let split: Vec<(u32, &Vec<Vec<Bary>>)> = to_cut
        .iter()
        .zip(&cuts)
        .filter(|(_, c)| c.polygons.len() > 1)
        .map(|(&t, c)| (t, &c.polygons))
        .collect();
    let receivers = match options.close_t_junctions {
        true => edges::receivers(geometry, prepared, &edges::edge_points(geometry, &split)),
        false => Vec::new(),
    };
    // Everything that may change, ascending: split triangles and those taking edge points.
    let mut changing: BTreeMap<u32, Change> = split
        .iter()
        .map(|&(t, polygons)| (t, (Some(polygons), None)))
        .collect();
    for (t, changes) in &receivers {
        changing.entry(*t).or_insert((None, None)).1 = Some(changes);
    }
    let changing: Vec<_> = changing.into_iter().collect();
    let outcomes: Vec<Outcome> = changing
        .par_iter()
        .map(|&(t, (polygons, changes))| {
            finish_triangle(geometry, prepared, t, polygons, changes, options)
        })
        .collect();
    let neighbours_split = changing
        .iter()
        .zip(&outcomes)
        .filter(|((_, (polygons, _)), o)| polygons.is_none() && o.triangles.is_some())
        .count() as u64;
    let t_junctions_left = outcomes.iter().map(|o| o.dropped).sum();
    let changed: Vec<u32> = changing.iter().map(|&(t, _)| t).collect();
    let (geometry, origin, split) = assemble(geometry, &changed, outcomes);
    Round {
        geometry,
        origin,
        split,
        skipped,
        neighbours_split,
        t_junctions_left,
    }
}

/// What may change in a triangle: the polygons it was cut into, and what it takes on its
/// edges.
type Change<'a> = (Option<&'a Vec<Vec<Bary>>>, Option<&'a EdgeChanges>);

/// The cuts of a round.
struct PairCuts {
    /// The triangles cut, ascending.
    triangles: Vec<u32>,
    /// Per triangle cut: its cuts, as (partner, pair index), ascending.
    lists: Vec<Vec<(u32, usize)>>,
    /// Per triangle cut: what the cuts gave.
    pieces: Vec<Pieces>,
}

/// Cuts the triangles of `pairs`: each along the planes of all its partners, or with
/// [`SplitOptions::cut_both_sides`] off, each pair on one side only: the triangle with fewer
/// partners (the larger id on ties), or the other one where that cut is skipped as a sliver.
fn cut_pairs(
    geometry: &Geometry,
    prepared: &Prepared,
    pairs: &[[u32; 2]],
    options: &SplitOptions,
) -> PairCuts {
    let n = geometry.triangles.len();
    let mut count = vec![0usize; n];
    for &[a, b] in pairs {
        count[a as usize] += 1;
        count[b as usize] += 1;
    }
    // The side of each pair cut first: both, or the one with fewer partners.
    let chosen = |a: u32, b: u32| (count[a as usize], b) < (count[b as usize], a);
    let mut lists: Vec<Vec<(u32, usize)>> = vec![Vec::new(); n];
    for (p, &[a, b]) in pairs.iter().enumerate() {
        if options.cut_both_sides || !chosen(a, b) {
            lists[b as usize].push((a, p));
        }
        if options.cut_both_sides || chosen(a, b) {
            lists[a as usize].push((b, p));
        }
    }
    let run = |lists: &[Vec<(u32, usize)>], ts: &[u32]| -> Vec<Pieces> {
        ts.par_iter()
            .map(|&t| cut_one(geometry, prepared, t, &lists[t as usize], options))
            .collect()
    };
    let mut to_cut: Vec<u32> = (0..n as u32)
        .filter(|&t| !lists[t as usize].is_empty())
        .collect();
    for list in &mut lists {
        list.sort_unstable();
    }
    let mut cuts = run(&lists, &to_cut);
    if !options.cut_both_sides {
        // Pairs whose chosen side could not be cut: cut the other side too.
        let mut again = vec![false; n];
        let mut fallback = Vec::new();
        for (&t, c) in to_cut.iter().zip(&cuts) {
            for (&(u, p), &ok) in lists[t as usize].iter().zip(&c.applied) {
                if !ok {
                    fallback.push((u, t, p));
                }
            }
        }
        for (u, t, p) in fallback {
            lists[u as usize].push((t, p));
            again[u as usize] = true;
        }
        let redo: Vec<u32> = (0..n as u32).filter(|&t| again[t as usize]).collect();
        for &t in &redo {
            lists[t as usize].sort_unstable();
        }
        let mut redone = run(&lists, &redo).into_iter();
        let mut old = to_cut.into_iter().zip(cuts).peekable();
        let (mut merged_ts, mut merged) = (Vec::new(), Vec::new());
        for t in 0..n as u32 {
            let previous = match old.peek() {
                Some(&(o, _)) if o == t => old.next().map(|(_, c)| c),
                _ => None,
            };
            let cut = match again[t as usize] {
                true => redone.next(),
                false => previous,
            };
            if let Some(cut) = cut {
                merged_ts.push(t);
                merged.push(cut);
            }
        }
        (to_cut, cuts) = (merged_ts, merged);
    }
    let lists = to_cut
        .iter()
        .map(|&t| std::mem::take(&mut lists[t as usize]))
        .collect();
    PairCuts {
        triangles: to_cut,
        lists,
        pieces: cuts,
    }
}

/// Triangle `t` as a [`Source`] to cut.
fn source(geometry: &Geometry, prepared: &Prepared, t: u32, options: &SplitOptions) -> Source {
    let corners = geometry.triangles[t as usize];
    let positions = corners.map(|i| geometry.vertices[i as usize].position);
    Source::new(positions, prepared.tri(t), options.min_piece_area_fraction)
}

/// Cuts triangle `t` along the planes of its crossing `partners` (ascending).
fn cut_one(
    geometry: &Geometry,
    prepared: &Prepared,
    t: u32,
    partners: &[(u32, usize)],
    options: &SplitOptions,
) -> Pieces {
    let me = prepared.tri(t);
    let cuts: Vec<Cut> = partners
        .iter()
        .map(|&(u, _)| Cut {
            partner: *prepared.tri(u),
            sides: prepared.tri(u).sides(me),
        })
        .collect();
    cut_triangle(&source(geometry, prepared, t, options), &cuts)
}

/// The output triangles of triangle `t`: its cut `polygons` (the whole triangle if `None`)
/// with the `changes` to their edge points, triangulated. A polygon that cannot take them
/// without slivers is triangulated without them (they are counted).
fn finish_triangle(
    geometry: &Geometry,
    prepared: &Prepared,
    t: u32,
    polygons: Option<&Vec<Vec<Bary>>>,
    changes: Option<&EdgeChanges>,
    options: &SplitOptions,
) -> Outcome {
    let source = source(geometry, prepared, t, options);
    let whole = [vec![Bary::corner(0), Bary::corner(1), Bary::corner(2)]];
    let polygons = polygons.map_or(&whole[..], |p| &p[..]);
    let mut triangles = Vec::new();
    let mut dropped = 0;
    for polygon in polygons {
        let with = match changes {
            Some(c) => {
                let merged = source.merge_edge_points(polygon, &c.merge);
                source.insert_edge_points(&merged, &c.insert)
            }
            None => polygon.clone(),
        };
        match source.triangulate(&with) {
            Some(pieces) => triangles.extend(pieces),
            None => {
                dropped += with.iter().filter(|b| !polygon.contains(b)).count() as u64;
                // Cut pieces passed this test when they were made; the whole triangle is
                // itself.
                let pieces = source.triangulate(polygon);
                triangles
                    .extend(pieces.unwrap_or_else(|| vec![[polygon[0], polygon[1], polygon[2]]]));
            }
        }
    }
    if triangles.len() == 1 {
        return Outcome {
            triangles: None,
            dropped,
        };
    }
    let corners = geometry.triangles[t as usize];
    let v = corners.map(|i| &geometry.vertices[i as usize]);
    let triangles = triangles
        .iter()
        .map(|tri| {
            tri.map(|b| match b.as_corner() {
                Some(i) => PieceVertex::Old(corners[i]),
                None => PieceVertex::New(interpolate(&source, v, &b)),
            })
        })
        .collect();
    Outcome {
        triangles: Some(triangles),
        dropped,
    }
}

/// The output geometry: the vertices as they were, then new ones (deduplicated by value, in
/// order of first use); each triangle or, in its place, its pieces. `changed` (ascending)
/// are the triangles with an outcome. Returns it with the origin of every output triangle and
/// which triangles were split.
fn assemble(
    geometry: &Geometry,
    changed: &[u32],
    outcomes: Vec<Outcome>,
) -> (Geometry, Vec<u32>, Vec<bool>) {
    let mut vertices = geometry.vertices.clone();
    let mut triangles = Vec::with_capacity(geometry.triangles.len());
    let mut origin = Vec::with_capacity(geometry.triangles.len());
    let mut split = vec![false; geometry.triangles.len()];
    let mut index_of: HashMap<[u32; std::mem::size_of::<Vertex>() / 4], u32> = HashMap::new();
    let mut next = changed.iter().zip(outcomes).peekable();
    for (t, &tri) in geometry.triangles.iter().enumerate() {
        let pieces = match next.peek() {
            Some(&(&c, _)) if c as usize == t => next.next().and_then(|(_, o)| o.triangles),
            _ => None,
        };
        let Some(pieces) = pieces else {
            triangles.push(tri);
            origin.push(t as u32);
            continue;
        };
        split[t] = true;
        for piece in pieces {
            triangles.push(piece.map(|pv| match pv {
                PieceVertex::Old(i) => i,
                PieceVertex::New(v) => *index_of.entry(bytemuck::cast(v)).or_insert_with(|| {
                    vertices.push(v);
                    (vertices.len() - 1) as u32
                }),
            }));
            origin.push(t as u32);
        }
    }
    let out = Geometry {
        vertices,
        triangles,
        materials: geometry.materials.clone(),
        textures: geometry.textures.clone(),
        nodes: geometry.nodes.clone(),
        variants: geometry.variants.clone(),
    };
    (out, origin, split)
}
