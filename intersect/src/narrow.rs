//! The narrow phase: does a pair of triangles cross, and how deeply.
//!
//! Signs come from Shewchuk's adaptive exact `orient3d` (the `robust` crate), so "on the
//! plane", "coplanar" and "one side" are decided exactly for the f64 coordinates of the common
//! space. A pair crosses when each triangle has corners strictly on both sides of the other's
//! plane and the two chords they cut from the planes' common line overlap (Möller's interval
//! test).
//!
//! A crossing only counts when it is deeper than what rounding vertices to f32 could produce.
//! Each triangle carries `delta`, how far rounding can move one of its points (see
//! `detect::node_delta`). A point `x` of triangle `a` counts as beyond the plane of `b` only
//! when its distance exceeds [`DETECT_FACTOR`] × [`Tri::band`]: `δₐ + δ_b · Σ|λᵢ(x)|`, with
//! `λ` the barycentric coordinates of `x` in `b`, because moving `b`'s corners by `δ_b` moves
//! its plane at `x` by up to `δ_b · Σ|λᵢ(x)|` (1 inside `b`, growing away from it: a thin
//! piece's plane tilts). The chords must overlap by more than `DETECT_FACTOR · (δₐ + δ_b)`.
//! Cuts use a third of that band ([`CUT_FACTOR`]), so that the pieces of a cut triangle,
//! rounded (by up to `δₐ`) and with edge points merged (moved by up to `2δₐ`, see `edges`),
//! are never found crossing the other triangle or its pieces again: a piece's vertex is then
//! within `3δₐ + δ_b · Σ|λᵢ|` of the other piece's plane.

use glam::DVec3;
use robust::{orient3d, Coord3D};

/// Multiple of [`Tri::band`] a point must be beyond a plane for a crossing to count: the
/// cut's band, plus the rounding of a cut point, plus the merge of edge points
/// (`edges::MERGE_ROUNDINGS` roundings).
pub(crate) const DETECT_FACTOR: f64 = 3.0;
/// Multiple of [`Tri::band`] within which a point counts as on the plane when cutting.
pub(crate) const CUT_FACTOR: f64 = 1.0;

/// A triangle in its group's common space, with what the tests reuse.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tri {
    /// Corners in the common space.
    pub p: [DVec3; 3],
    /// Unnormalised normal `(p1 − p0) × (p2 − p0)`.
    pub normal: DVec3,
    /// Its length (twice the area).
    pub normal_len: f64,
    /// How far rounding to f32 in the node's local space can move a point of the triangle,
    /// in the common space.
    pub delta: f64,
}

impl Tri {
    /// The triangle with corners `p` and rounding bound `delta`.
    pub fn new(p: [DVec3; 3], delta: f64) -> Tri {
        let normal = (p[1] - p[0]).cross(p[2] - p[0]);
        Tri {
            p,
            normal,
            normal_len: normal.length(),
            delta,
        }
    }

    /// `orient3d` of this triangle's corners and `q`: zero exactly when `q` is on the plane,
    /// its sign says the side, its magnitude over [`Tri::normal_len`] is the distance.
    pub fn side(&self, q: DVec3) -> f64 {
        let c = |v: DVec3| Coord3D {
            x: v.x,
            y: v.y,
            z: v.z,
        };
        orient3d(c(self.p[0]), c(self.p[1]), c(self.p[2]), c(q))
    }

    /// [`Tri::side`] of each corner of `other`.
    pub fn sides(&self, other: &Tri) -> [f64; 3] {
        other.p.map(|q| self.side(q))
    }

    /// How far from this plane a point `x` of a triangle with rounding bound `delta_x` can be
    /// because of rounding alone: `delta_x + self.delta · Σ|λᵢ(x)|`.
    pub fn band(&self, x: DVec3, delta_x: f64) -> f64 {
        let n2 = self.normal_len * self.normal_len;
        let lambda = |i: usize| {
            let (b, c) = (self.p[(i + 1) % 3] - x, self.p[(i + 2) % 3] - x);
            self.normal.dot(b.cross(c)) / n2
        };
        let leverage = lambda(0).abs() + lambda(1).abs() + lambda(2).abs();
        delta_x + self.delta * leverage
    }

    /// Whether `other` reaches beyond this plane, by more than `factor` times the band, on
    /// both sides. `sides` are [`Tri::sides`] of `other`.
    fn straddled_deeply_by(&self, other: &Tri, sides: &[f64; 3], factor: f64) -> bool {
        let (mut above, mut below) = (false, false);
        for (x, &s) in other.p.iter().zip(sides) {
            let limit = factor * self.band(*x, other.delta) * self.normal_len;
            above |= s > limit;
            below |= s < -limit;
        }
        above && below
    }
}

/// How two triangles meet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Contact {
    /// Disjoint, touching (at a point, along an edge, or one lying in a closed half-space of
    /// the other's plane), or coplanar.
    Apart,
    /// Crossing, but no deeper or longer than rounding could make it: treated as touching.
    BelowPrecision,
    /// Crossing: the pair interpenetrates along a segment.
    Crossing,
}

/// Whether every value has the same strict sign, or all are zero (coplanar).
fn one_side(d: &[f64; 3]) -> bool {
    d.iter().all(|&x| x > 0.0) || d.iter().all(|&x| x < 0.0) || d.iter().all(|&x| x == 0.0)
}

/// Whether the values have both strict signs.
fn straddles(d: &[f64; 3]) -> bool {
    d.iter().any(|&x| x > 0.0) && d.iter().any(|&x| x < 0.0)
}

/// The extent, along `dir`, of the chord a triangle with corners `p` and sides `d` (which
/// straddle) cuts from the other plane.
fn chord(p: &[DVec3; 3], d: &[f64; 3], dir: DVec3) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut add = |x: DVec3| {
        let t = x.dot(dir);
        lo = lo.min(t);
        hi = hi.max(t);
    };
    for i in 0..3 {
        let j = (i + 1) % 3;
        if d[i] == 0.0 {
            add(p[i]);
        }
        if (d[i] > 0.0 && d[j] < 0.0) || (d[i] < 0.0 && d[j] > 0.0) {
            add(p[i] + (p[j] - p[i]) * (d[i] / (d[i] - d[j])));
        }
    }
    (lo, hi)
}

/// How triangles `a` and `b` meet (see the module documentation). Symmetric in `a` and `b`
/// up to rounding of the chord ends.
pub(crate) fn contact(a: &Tri, b: &Tri) -> Contact {
    let db = a.sides(b);
    if one_side(&db) {
        return Contact::Apart;
    }
    let da = b.sides(a);
    if one_side(&da) || !straddles(&da) || !straddles(&db) {
        return Contact::Apart;
    }
    if !b.straddled_deeply_by(a, &da, DETECT_FACTOR)
        || !a.straddled_deeply_by(b, &db, DETECT_FACTOR)
    {
        return Contact::BelowPrecision;
    }
    let dir = a.normal.cross(b.normal);
    let len = dir.length();
    if len.is_nan() || len <= 0.0 {
        return Contact::BelowPrecision;
    }
    let (a_lo, a_hi) = chord(&a.p, &da, dir);
    let (b_lo, b_hi) = chord(&b.p, &db, dir);
    let overlap = (a_hi.min(b_hi) - a_lo.max(b_lo)) / len;
    if overlap > DETECT_FACTOR * (a.delta + b.delta) {
        Contact::Crossing
    } else if overlap > 0.0 {
        Contact::BelowPrecision
    } else {
        Contact::Apart
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(p: [[f64; 3]; 3]) -> Tri {
        tri_delta(p, 1e-10)
    }

    fn tri_delta(p: [[f64; 3]; 3], delta: f64) -> Tri {
        Tri::new(p.map(DVec3::from), delta)
    }

    #[test]
    fn crossing_touching_coplanar_and_shallow() {
        let floor = tri([[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 0.0, 1.0]]);
        let wall_v = tri([[0.0, -1.0, -0.5], [0.0, 1.0, -0.5], [0.0, 1.0, 0.5]]);
        assert_eq!(contact(&floor, &wall_v), Contact::Crossing);
        assert_eq!(contact(&wall_v, &floor), Contact::Crossing);
        // The wall's edge lies in the floor's plane but the wall stays above: a touch.
        let standing = tri([[0.0, 0.0, -0.5], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5]]);
        assert_eq!(contact(&floor, &standing), Contact::Apart);
        // Coplanar overlap is a tie, not a crossing.
        let flat = tri([[-0.5, 0.0, -0.5], [0.5, 0.0, -0.5], [0.0, 0.0, 2.0]]);
        assert_eq!(contact(&floor, &flat), Contact::Apart);
        // A wall reaching 1e-12 below the floor is below a rounding bound of 1e-10...
        let shallow = [[0.0, -1e-12, -0.5], [0.0, 1.0, 0.0], [0.0, -1e-12, 0.5]];
        assert_eq!(contact(&floor, &tri(shallow)), Contact::BelowPrecision);
        // ... but not below one of 1e-14.
        let exact_floor = tri_delta(
            [[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 0.0, 1.0]],
            1e-14,
        );
        assert_eq!(
            contact(&exact_floor, &tri_delta(shallow, 1e-14)),
            Contact::Crossing
        );
        // Each straddles the other's plane, but their chords are apart on the common line.
        let beyond = tri([[0.0, -1.0, 1.5], [0.0, 1.0, 1.5], [0.0, 1.0, 2.5]]);
        assert_eq!(contact(&floor, &beyond), Contact::Apart);
    }
}
