//! Sharing cut points with the triangles across an edge, so that cuts leave no T-junctions.
//!
//! A cut that crosses an edge of its triangle puts a vertex on that edge. The triangle on the
//! other side of the edge (same node, same two corner positions bit for bit) would keep the
//! whole edge: a T-junction, where rasterization can leave a crack. So every point a cut puts
//! on an edge is inserted into every triangle sharing that edge, at the same parameter from
//! the edge's canonical first corner, which gives the same f32 position bits (see
//! `Source::edge_point`).
//!
//! Points of one edge closer together than [`MERGE_ROUNDINGS`] roundings of a stored point
//! (`√3 · 2⁻²⁴ · max |corner coordinate|`, in the node's local space) are one point: cuts by
//! coplanar partners (one flat mesh) cross an edge at parameters a rounding apart, and two
//! such vertices would only leave a sliver between them. Each is replaced by the first of its
//! run (by parameter), which moves it by at most that: the crossing tests' bands allow for it
//! (see `narrow`).

use glam::DVec3;
use rayon::prelude::*;
use trisort_format::Geometry;

use crate::cut::Bary;
use crate::detect::Prepared;

/// How many roundings apart points of one edge may be and still be merged.
pub(crate) const MERGE_ROUNDINGS: f64 = 2.0;

/// An edge: the node, and the position bits of its two corners in canonical (ascending)
/// order.
type EdgeKey = (u32, [u32; 3], [u32; 3]);

/// The key of edge `k` (opposite corner `k`) of triangle `t` and its corners in canonical
/// order; `None` for an edge whose corners coincide.
fn edge_key(geometry: &Geometry, t: u32, k: usize) -> Option<(EdgeKey, [usize; 2])> {
    let tri = geometry.triangles[t as usize];
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let vertex = |c: usize| &geometry.vertices[tri[c] as usize];
    let bits = |c: usize| vertex(c).position.map(f32::to_bits);
    let node = vertex(0).node;
    match bits(i).cmp(&bits(j)) {
        std::cmp::Ordering::Less => Some(((node, bits(i), bits(j)), [i, j])),
        std::cmp::Ordering::Greater => Some(((node, bits(j), bits(i)), [j, i])),
        std::cmp::Ordering::Equal => None,
    }
}

/// The corners of an edge in f64.
fn corners(key: &EdgeKey) -> (DVec3, DVec3) {
    let p = |bits: [u32; 3]| DVec3::from(bits.map(|b| f64::from(f32::from_bits(b))));
    (p(key.1), p(key.2))
}

/// The position of the point at parameter `s` of edge `key`, as `Source::position` computes
/// and rounds it.
fn position_on(key: &EdgeKey, s: f64) -> DVec3 {
    let (a, b) = corners(key);
    (a + (b - a) * s).as_vec3().as_dvec3()
}

/// The points cuts put on edges, merged (see the module documentation).
pub(crate) struct EdgePoints {
    /// The points kept, as (edge, bits of the parameter), sorted.
    kept: Vec<(EdgeKey, u64)>,
    /// The points merged into a kept one: (edge, bits of the parameter, bits of the kept
    /// parameter), sorted.
    merged: Vec<(EdgeKey, u64, u64)>,
}

/// The points that the pieces of the split triangles put on their triangles' edges.
pub(crate) fn edge_points(geometry: &Geometry, split: &[(u32, &Vec<Vec<Bary>>)]) -> EdgePoints {
    let mut points = Vec::new();
    for &(t, polygons) in split {
        for b in polygons.iter().flatten() {
            let Some(k) = b.edge() else { continue };
            if let Some((key, [_, second])) = edge_key(geometry, t, k) {
                points.push((key, b.0[second]));
            }
        }
    }
    points.sort_unstable_by(|x, y| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)));
    let mut kept: Vec<(EdgeKey, u64)> = Vec::new();
    let mut merged = Vec::new();
    let mut run: Option<(EdgeKey, f64, DVec3)> = None;
    for (key, s) in points {
        let at = position_on(&key, s);
        if let Some((run_key, run_s, run_at)) = run {
            let (a, b) = corners(&key);
            let rounding = 3f64.sqrt() * 2f64.powi(-24) * a.abs().max(b.abs()).max_element();
            if run_key == key && (at - run_at).length() <= MERGE_ROUNDINGS * rounding {
                if s != run_s {
                    merged.push((key, s.to_bits(), run_s.to_bits()));
                }
                continue;
            }
        }
        run = Some((key, s, at));
        kept.push((key, s.to_bits()));
    }
    merged.sort_unstable();
    merged.dedup();
    EdgePoints { kept, merged }
}

/// What one triangle takes on its edges: points to insert and points of its own to move,
/// as (edge, parameter) and (edge, from, to).
#[derive(Clone, Debug, Default)]
pub(crate) struct EdgeChanges {
    /// Points to insert where the triangle's pieces run along the edge.
    pub insert: Vec<(usize, f64)>,
    /// Vertices of the pieces on the edge to move to the kept point of their run.
    pub merge: Vec<(usize, f64, f64)>,
}

/// Every triangle (with an area) that has an edge holding some of `points`, with what it
/// takes, ascending by triangle.
pub(crate) fn receivers(
    geometry: &Geometry,
    prepared: &Prepared,
    points: &EdgePoints,
) -> Vec<(u32, EdgeChanges)> {
    if points.kept.is_empty() {
        return Vec::new();
    }
    (0..geometry.triangles.len() as u32)
        .into_par_iter()
        .filter(|&t| prepared.tris[t as usize].is_some())
        .filter_map(|t| {
            let mut changes = EdgeChanges::default();
            for k in 0..3 {
                let Some((key, _)) = edge_key(geometry, t, k) else {
                    continue;
                };
                let kept = &points.kept[points.kept.partition_point(|(e, _)| *e < key)..];
                let kept = &kept[..kept.partition_point(|(e, _)| *e == key)];
                changes
                    .insert
                    .extend(kept.iter().map(|&(_, s)| (k, f64::from_bits(s))));
                let merged = &points.merged[points.merged.partition_point(|m| m.0 < key)..];
                let merged = &merged[..merged.partition_point(|m| m.0 == key)];
                changes.merge.extend(
                    merged
                        .iter()
                        .map(|&(_, from, to)| (k, f64::from_bits(from), f64::from_bits(to))),
                );
            }
            (!changes.insert.is_empty()).then_some((t, changes))
        })
        .collect()
}
