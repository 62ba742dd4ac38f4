//! Cutting one triangle along the planes of the triangles it crosses.
//!
//! The triangle is a list of convex polygons in its own barycentric coordinates, at first
//! the whole triangle. Each crossing partner's plane is an affine function on the triangle,
//! `h(λ) = Σ λᵢ dᵢ` with `dᵢ = orient3d(partner, cornerᵢ)`; a cut splits every polygon that
//! has corners strictly on both sides of `h = 0` (beyond the pair's precision; corners within
//! it count as on the line and go to both sides) into its two halves, keeping the vertex order
//! and therefore the winding. Points are computed so that every polygon sharing an edge
//! computes the same bits for a crossing on it: crossings on an edge of the original triangle
//! from that edge's corners (in a canonical order, so the neighbour across the edge gets the
//! same point when the same plane cuts it), others from the polygon edge's ends taken in a
//! canonical order.
//!
//! Slivers: a cut is applied to the whole triangle or not at all. It is skipped when one of
//! the polygons it creates cannot be fan-triangulated, after rounding its vertices to f32 in
//! the node's local space, into triangles that each keep the original's orientation and at
//! least `min_piece_area_fraction` of its area. Polygons that later take points on their
//! edges (`edges`) are triangulated by ear clipping where no fan qualifies.

use glam::DVec3;
use trisort_format::Vertex;

use crate::narrow::{Tri, CUT_FACTOR};

/// A point of the triangle in barycentric coordinates (weights of corners 0, 1, 2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Bary(pub [f64; 3]);

impl Bary {
    /// Corner `i`.
    pub fn corner(i: usize) -> Bary {
        let mut l = [0.0; 3];
        l[i] = 1.0;
        Bary(l)
    }

    /// The bits, for canonical ordering and deduplication.
    pub fn key(&self) -> [u64; 3] {
        self.0.map(f64::to_bits)
    }

    /// The corner this point is, if it has two zero weights.
    pub fn as_corner(&self) -> Option<usize> {
        match self.0.iter().filter(|&&x| x == 0.0).count() {
            2.. => self.0.iter().position(|&x| x != 0.0),
            _ => None,
        }
    }

    /// The original edge (named by its opposite corner) this point lies on, if it has exactly
    /// one zero weight.
    pub fn edge(&self) -> Option<usize> {
        match self.0.iter().filter(|&&x| x == 0.0).count() {
            1 => self.0.iter().position(|&x| x == 0.0),
            _ => None,
        }
    }
}

/// One cutting plane, seen from the triangle.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cut {
    /// The crossing partner whose plane cuts.
    pub partner: Tri,
    /// `orient3d` of the partner's corners and each of this triangle's corners.
    pub sides: [f64; 3],
}

impl Cut {
    fn h(&self, b: &Bary) -> f64 {
        b.0[0] * self.sides[0] + b.0[1] * self.sides[1] + b.0[2] * self.sides[2]
    }

    /// Which side of the plane `b` is on: 0 within [`CUT_FACTOR`] times the band of
    /// [`Tri::band`].
    fn side(&self, source: &Source, b: &Bary) -> i8 {
        let h = self.h(b);
        let x = source.common[0] * b.0[0] + source.common[1] * b.0[1] + source.common[2] * b.0[2];
        let limit = CUT_FACTOR * self.partner.band(x, source.delta) * self.partner.normal_len;
        if h > limit {
            1
        } else if h < -limit {
            -1
        } else {
            0
        }
    }
}

/// The triangle being cut, in its node's local space.
pub(crate) struct Source {
    /// Corner positions as stored.
    local: [[f32; 3]; 3],
    /// Corner positions in the group's common space.
    common: [DVec3; 3],
    /// How far rounding moves a point of the triangle in the common space.
    delta: f64,
    /// `(p1 − p0) × (p2 − p0)` of the stored corners, in f64: the winding every piece keeps.
    normal: DVec3,
    /// Smallest area of an output triangle, as a fraction of the original's.
    min_fraction: f64,
    /// For each edge (named by its opposite corner), its two corners in canonical order: by
    /// position bits, then index.
    edge_order: [[usize; 2]; 3],
}

impl Source {
    /// The triangle with corners `local` (stored) and `tri` (in the common space), keeping
    /// pieces of at least `min_fraction` of its area.
    pub fn new(local: [[f32; 3]; 3], tri: &Tri, min_fraction: f64) -> Source {
        let p = local.map(|c| DVec3::from(c.map(f64::from)));
        let key = |i: usize| (local[i].map(f32::to_bits), i);
        let edge_order = [0, 1, 2].map(|k| {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            if key(i) <= key(j) {
                [i, j]
            } else {
                [j, i]
            }
        });
        Source {
            local,
            common: tri.p,
            delta: tri.delta,
            normal: (p[1] - p[0]).cross(p[2] - p[0]),
            min_fraction,
            edge_order,
        }
    }

    /// The point's position in the node's local space, rounded to f32 as it will be stored.
    /// Corners are exact; points on an original edge interpolate its two corners in canonical
    /// order (the neighbour across the edge computes the same bits); others interpolate all
    /// three.
    pub fn position(&self, b: &Bary) -> [f32; 3] {
        if let Some(i) = b.as_corner() {
            return self.local[i];
        }
        let p = |i: usize| DVec3::from(self.local[i].map(f64::from));
        let x = match b.edge() {
            Some(k) => {
                let [i, j] = self.edge_order[k];
                p(i) + (p(j) - p(i)) * b.0[j]
            }
            None => p(0) * b.0[0] + p(1) * b.0[1] + p(2) * b.0[2],
        };
        x.as_vec3().to_array()
    }

    /// Where `cut` crosses the polygon edge from `a` to `b` (strictly on opposite sides).
    fn crossing(&self, cut: &Cut, a: &Bary, b: &Bary) -> Bary {
        if let Some(k) = (0..3).find(|&k| a.0[k] == 0.0 && b.0[k] == 0.0) {
            let [i, j] = self.edge_order[k];
            return self.edge_point(k, cut.sides[i] / (cut.sides[i] - cut.sides[j]));
        }
        let (a, b) = if a.key() <= b.key() { (a, b) } else { (b, a) };
        let (ha, hb) = (cut.h(a), cut.h(b));
        let t = ha / (ha - hb);
        Bary([0, 1, 2].map(|k| a.0[k] + t * (b.0[k] - a.0[k])))
    }

    /// The fan apex of `polygon` whose triangles' smallest signed area fraction (after
    /// rounding, against the original's orientation) is largest, and that fraction. Ties go
    /// to the first apex.
    fn best_fan(&self, polygon: &[Bary]) -> (usize, f64) {
        let pts: Vec<DVec3> = polygon
            .iter()
            .map(|b| DVec3::from(self.position(b).map(f64::from)))
            .collect();
        let n = pts.len();
        let denominator = self.normal.length_squared();
        let mut best = (0, f64::NEG_INFINITY);
        for apex in 0..n {
            let a = pts[apex];
            let worst = (1..n - 1)
                .map(|i| {
                    let (b, c) = (pts[(apex + i) % n], pts[(apex + i + 1) % n]);
                    (b - a).cross(c - a).dot(self.normal) / denominator
                })
                .fold(f64::INFINITY, f64::min);
            if worst > best.1 {
                best = (apex, worst);
            }
        }
        best
    }

    /// Whether `polygon` triangulates without slivers or flips.
    fn acceptable(&self, polygon: &[Bary]) -> bool {
        polygon.len() >= 3 && self.best_fan(polygon).1 >= self.min_fraction
    }

    /// Triangles covering the convex `polygon`, in its winding, each keeping the original's
    /// orientation and at least the minimum area fraction after rounding: the best fan when it
    /// qualifies, else ear clipping (for polygons with points inserted along their edges,
    /// where every fan has a flat triangle). `None` when neither qualifies.
    pub fn triangulate(&self, polygon: &[Bary]) -> Option<Vec<[Bary; 3]>> {
        let n = polygon.len();
        if n < 3 {
            return None;
        }
        let (apex, worst) = self.best_fan(polygon);
        if worst >= self.min_fraction {
            let fan = (1..n - 1).map(|i| {
                [
                    polygon[apex],
                    polygon[(apex + i) % n],
                    polygon[(apex + i + 1) % n],
                ]
            });
            return Some(fan.collect());
        }
        self.clip_ears(polygon)
    }

    /// Ear clipping of a convex polygon whose boundary may hold collinear points: each step
    /// clips the largest ear that qualifies and leaves every other vertex clearly on the far
    /// side of its diagonal (so no flat remainder is left), first one on ties.
    fn clip_ears(&self, polygon: &[Bary]) -> Option<Vec<[Bary; 3]>> {
        let pts: Vec<DVec3> = polygon
            .iter()
            .map(|b| DVec3::from(self.position(b).map(f64::from)))
            .collect();
        let denominator = self.normal.length_squared();
        let fraction = |a: usize, b: usize, c: usize| {
            (pts[b] - pts[a]).cross(pts[c] - pts[a]).dot(self.normal) / denominator
        };
        let mut left: Vec<usize> = (0..polygon.len()).collect();
        let mut triangles = Vec::with_capacity(polygon.len() - 2);
        while left.len() > 3 {
            let m = left.len();
            let mut best: Option<(usize, f64)> = None;
            for r in 0..m {
                let (a, b, c) = (left[(r + m - 1) % m], left[r], left[(r + 1) % m]);
                let ear = fraction(a, b, c);
                let clear = left
                    .iter()
                    .filter(|&&w| w != a && w != b && w != c)
                    .all(|&w| fraction(a, c, w) >= self.min_fraction);
                if ear >= self.min_fraction && clear && best.is_none_or(|(_, f)| ear > f) {
                    best = Some((r, ear));
                }
            }
            let (r, _) = best?;
            let (a, b, c) = (left[(r + m - 1) % m], left[r], left[(r + 1) % m]);
            triangles.push([polygon[a], polygon[b], polygon[c]]);
            left.remove(r);
        }
        if fraction(left[0], left[1], left[2]) < self.min_fraction {
            return None;
        }
        triangles.push([polygon[left[0]], polygon[left[1]], polygon[left[2]]]);
        Some(triangles)
    }

    /// The point of edge `k` at parameter `s` from its canonical first corner: the same bits
    /// as a crossing computed there (by this triangle or by a neighbour sharing the edge).
    pub fn edge_point(&self, k: usize, s: f64) -> Bary {
        let [i, j] = self.edge_order[k];
        let mut l = [0.0; 3];
        l[i] = 1.0 - s;
        l[j] = s;
        Bary(l)
    }

    /// `polygon` with its vertices on original edges moved as `merges` (edge, from, to) say,
    /// vertices that became equal to their successor dropped.
    pub fn merge_edge_points(&self, polygon: &[Bary], merges: &[(usize, f64, f64)]) -> Vec<Bary> {
        let moved: Vec<Bary> = polygon
            .iter()
            .map(|b| {
                let Some(k) = b.edge() else { return *b };
                let s = b.0[self.edge_order[k][1]];
                match merges.iter().find(|m| m.0 == k && m.1 == s) {
                    Some(&(_, _, to)) => self.edge_point(k, to),
                    None => *b,
                }
            })
            .collect();
        let n = moved.len();
        (0..n)
            .filter(|&i| moved[i] != moved[(i + 1) % n])
            .map(|i| moved[i])
            .collect()
    }

    /// `polygon` with `points` (edge, parameter) inserted where its boundary runs along those
    /// edges strictly between two of its vertices, in order along the boundary.
    pub fn insert_edge_points(&self, polygon: &[Bary], points: &[(usize, f64)]) -> Vec<Bary> {
        let n = polygon.len();
        let mut out = Vec::with_capacity(n + points.len());
        for i in 0..n {
            let (a, b) = (polygon[i], polygon[(i + 1) % n]);
            out.push(a);
            let Some(k) = (0..3).find(|&k| a.0[k] == 0.0 && b.0[k] == 0.0) else {
                continue;
            };
            let second = self.edge_order[k][1];
            let (sa, sb) = (a.0[second], b.0[second]);
            let mut between: Vec<(f64, [f32; 3])> = points
                .iter()
                .filter(|&&(e, s)| e == k && s > sa.min(sb) && s < sa.max(sb))
                .map(|&(_, s)| (s, self.position(&self.edge_point(k, s))))
                .collect();
            between.sort_by(|x, y| match sa < sb {
                true => x.0.total_cmp(&y.0),
                false => y.0.total_cmp(&x.0),
            });
            // A point at the position of a vertex already there is that vertex.
            let mut last = self.position(&a);
            let end = self.position(&b);
            for (s, position) in between {
                if position != last && position != end {
                    out.push(self.edge_point(k, s));
                    last = position;
                }
            }
        }
        out
    }

    /// The two halves of `polygon` on either side of `cut`, or `None` when it does not
    /// straddle the cut.
    fn split(&self, polygon: &[Bary], cut: &Cut) -> Option<(Vec<Bary>, Vec<Bary>)> {
        let sides: Vec<i8> = polygon.iter().map(|b| cut.side(self, b)).collect();
        if !(sides.contains(&1) && sides.contains(&-1)) {
            return None;
        }
        let n = polygon.len();
        let (mut plus, mut minus) = (Vec::with_capacity(n + 1), Vec::with_capacity(n + 1));
        for i in 0..n {
            let j = (i + 1) % n;
            if sides[i] >= 0 {
                plus.push(polygon[i]);
            }
            if sides[i] <= 0 {
                minus.push(polygon[i]);
            }
            if sides[i] * sides[j] < 0 {
                let x = self.crossing(cut, &polygon[i], &polygon[j]);
                plus.push(x);
                minus.push(x);
            }
        }
        Some((plus, minus))
    }
}

/// The result of cutting one triangle.
pub(crate) struct Pieces {
    /// The convex pieces, in barycentric coordinates; one (the whole triangle) when no cut
    /// was applied.
    pub polygons: Vec<Vec<Bary>>,
    /// Per cut, in order: whether it was applied (or nothing straddled it any more).
    pub applied: Vec<bool>,
}

/// Cuts the triangle by each of `cuts` in turn (see the module documentation).
pub(crate) fn cut_triangle(source: &Source, cuts: &[Cut]) -> Pieces {
    let mut polygons = vec![vec![Bary::corner(0), Bary::corner(1), Bary::corner(2)]];
    let mut applied = Vec::with_capacity(cuts.len());
    for cut in cuts {
        let mut next = Vec::with_capacity(polygons.len() + 1);
        let mut ok = true;
        for polygon in &polygons {
            match source.split(polygon, cut) {
                None => next.push(polygon.clone()),
                Some((plus, minus)) => {
                    if !(source.acceptable(&plus) && source.acceptable(&minus)) {
                        ok = false;
                        break;
                    }
                    next.push(plus);
                    next.push(minus);
                }
            }
        }
        if ok {
            polygons = next;
        }
        applied.push(ok);
    }
    Pieces { polygons, applied }
}

/// The vertex at `b` of the triangle with vertices `v`: position from
/// [`Source::position`], normal, tangent and both uvs interpolated with the same weights
/// (normal and tangent renormalised; each kept bit for bit when the three corners agree),
/// material and node kept.
pub(crate) fn interpolate(source: &Source, v: [&Vertex; 3], b: &Bary) -> Vertex {
    let weights = || (0..3).filter(|&i| b.0[i] != 0.0).map(|i| (i, b.0[i]));
    let normal = if v[0].normal == v[1].normal && v[0].normal == v[2].normal {
        v[0].normal
    } else {
        let n: DVec3 = weights()
            .map(|(i, w)| DVec3::from(v[i].normal.map(f64::from)) * w)
            .sum();
        let len = n.length();
        if len > 0.0 && len.is_finite() {
            (n / len).as_vec3().to_array()
        } else {
            n.as_vec3().to_array()
        }
    };
    // Per-vertex attributes, interpolated in f64 (kept exactly where the corners agree).
    fn lerp<const N: usize>(
        v: &[&Vertex; 3],
        weights: impl Iterator<Item = (usize, f64)>,
        get: impl Fn(&Vertex) -> [f32; N],
    ) -> [f32; N] {
        if get(v[0]) == get(v[1]) && get(v[0]) == get(v[2]) {
            return get(v[0]);
        }
        let mut out = [0.0f64; N];
        for (i, w) in weights {
            for (o, x) in out.iter_mut().zip(get(v[i])) {
                *o += f64::from(x) * w;
            }
        }
        out.map(|x| x as f32)
    }
    let uv = lerp(&v, weights(), |v| v.uv);
    let uv1 = lerp(&v, weights(), |v| v.uv1);
    // The tangent's direction is interpolated and renormalised; its handedness is the first
    // corner's (a triangle's corners share one in any file that mirrors UVs per triangle).
    let t = lerp(&v, weights(), |v| {
        [v.tangent[0], v.tangent[1], v.tangent[2]]
    });
    let t = glam::Vec3::from(t);
    let t = if t.length() > 0.0 && t.is_finite() {
        t.normalize()
    } else {
        t
    };
    let tangent = [t.x, t.y, t.z, v[0].tangent[3]];
    Vertex {
        position: source.position(b),
        normal,
        uv,
        material: v[0].material,
        node: v[0].node,
        tangent,
        uv1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corners() -> [[f32; 3]; 3] {
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    }

    fn tri(p: [[f32; 3]; 3]) -> Tri {
        Tri::new(p.map(|c| DVec3::from(c.map(f64::from))), 1e-12)
    }

    fn right_triangle() -> Source {
        Source::new(corners(), &tri(corners()), 1e-6)
    }

    /// The plane `x = c` as a cut, from a large triangle in it.
    fn plane_x(c: f32) -> Cut {
        let partner = tri([[c, -10.0, -10.0], [c, 10.0, -10.0], [c, 0.0, 10.0]]);
        Cut {
            partner,
            sides: partner.sides(&tri(corners())),
        }
    }

    #[test]
    fn one_cut_makes_a_triangle_and_a_quad_with_the_same_winding() {
        let s = right_triangle();
        let pieces = cut_triangle(&s, &[plane_x(0.5)]);
        assert_eq!(pieces.applied, vec![true]);
        assert_eq!(pieces.polygons.len(), 2);
        let mut area = 0.0;
        for polygon in &pieces.polygons {
            for t in s.triangulate(polygon).unwrap() {
                let p = t.map(|b| DVec3::from(s.position(&b).map(f64::from)));
                let n = (p[1] - p[0]).cross(p[2] - p[0]);
                assert!(n.z > 0.0, "winding kept");
                area += n.z / 2.0;
            }
        }
        assert!((area - 0.5).abs() < 1e-12);
    }

    #[test]
    fn a_cut_near_a_corner_is_a_sliver() {
        let s = right_triangle();
        let pieces = cut_triangle(&s, &[plane_x(1.0 - 1e-4)]);
        assert_eq!(pieces.applied, vec![false]);
        assert_eq!(pieces.polygons.len(), 1);
    }

    #[test]
    fn crossings_on_an_edge_are_the_same_from_both_sides() {
        let s = right_triangle();
        let cut = plane_x(0.3);
        let a = Bary::corner(0);
        let b = Bary::corner(1);
        assert_eq!(s.crossing(&cut, &a, &b), s.crossing(&cut, &b, &a));
        let inner = Bary([0.2, 0.3, 0.5]);
        let other = Bary([0.6, 0.1, 0.3]);
        let cut = Cut {
            sides: [1.0, -2.0, 0.5],
            ..cut
        };
        assert_eq!(
            s.crossing(&cut, &inner, &other),
            s.crossing(&cut, &other, &inner)
        );
    }
}
