//! Planes, triangles, the viewpoint regions of paper 000 (occlusion regions as intersections of
//! half-spaces) and their vertices.
//!
//! Everything here works in the presort's normalised space: the scene's bounding sphere is the
//! unit sphere at the origin, so the tolerances below are absolute.

use glam::DVec3;

/// Distance below which a point counts as on a plane.
pub const ON_PLANE: f64 = 1e-9;

/// Depth a region must have at its vertices' centroid to count as a region of viewpoints
/// (thinner slivers, of no volume a camera could be in, are ignored).
pub const INTERIOR: f64 = 1e-7;

/// A plane; its positive side is `n · x − d ≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub n: DVec3,
    /// Offset.
    pub d: f64,
}

impl Plane {
    /// Signed distance of `x`.
    pub fn eval(&self, x: DVec3) -> f64 {
        self.n.dot(x) - self.d
    }

    /// The same plane with the other side positive.
    pub fn flip(self) -> Plane {
        Plane {
            n: -self.n,
            d: -self.d,
        }
    }

    /// The plane through `a`, `b`, `c` with the side their counter-clockwise order faces
    /// positive (`None` when they are collinear).
    pub fn through(a: DVec3, b: DVec3, c: DVec3) -> Option<Plane> {
        let n = (b - a).cross(c - a);
        let l = n.length();
        if l.is_nan() || l < 1e-300 {
            return None;
        }
        let n = n / l;
        Some(Plane { n, d: n.dot(a) })
    }
}

/// One oriented instance of a triangle: it is drawn only from its front side.
#[derive(Clone, Copy, Debug)]
pub struct Tri {
    /// Corners, counter-clockwise seen from the front.
    pub v: [DVec3; 3],
    /// Its plane, front side positive (`None`: zero area, never drawn).
    pub plane: Option<Plane>,
    /// The scene id (ties at equal depth go to the lower id, as the exact reference's peel).
    pub id: u32,
}

impl Tri {
    /// A triangle from its corners.
    pub fn new(v: [DVec3; 3], id: u32) -> Tri {
        // Zero or sliver area in normalised space: nothing a sample can hit reliably; the
        // list keeps it, untested and unordered.
        let area = (v[1] - v[0]).cross(v[2] - v[0]).length();
        let plane = if area > 1e-14 {
            Plane::through(v[0], v[1], v[2])
        } else {
            None
        };
        Tri { v, plane, id }
    }

    /// The same triangle seen from the back.
    pub fn reversed(&self) -> Tri {
        Tri {
            v: [self.v[0], self.v[2], self.v[1]],
            plane: self.plane.map(Plane::flip),
            id: self.id,
        }
    }

    /// Centroid.
    pub fn centroid(&self) -> DVec3 {
        (self.v[0] + self.v[1] + self.v[2]) / 3.0
    }
}

/// The half-spaces whose intersection contains every viewpoint from which `i` occludes `j`
/// (some ray from the viewpoint meets `i`, then `j`, both seen from the front), or `None` when
/// there is none. The region is conservative, never smaller than the true one: `i`'s and
/// `j`'s front sides, and every plane through an edge of one and a corner of the other that
/// has the two triangles on opposite sides (the viewpoint is on `i`'s side of it: along a ray
/// from a point of `j` through a point of `i`, the signed distance only grows past `i`).
/// Coplanar triangles facing the same way meet only at equal depth, where the lower scene id
/// is in front; they occlude where they overlap.
pub fn occlusion(i: &Tri, j: &Tri) -> Option<Vec<Plane>> {
    let (pi, pj) = (i.plane?, j.plane?);
    let dj = j.v.map(|x| pi.eval(x));
    if dj.iter().all(|d| d.abs() <= ON_PLANE) {
        let same_side = pi.n.dot(pj.n) > 0.0;
        return (same_side && i.id < j.id && overlap_in_plane(i, j, pi.n)).then(|| vec![pi]);
    }
    // `j` must reach behind `i`'s plane and `i` in front of `j`'s.
    if !dj.iter().any(|&d| d < -ON_PLANE) {
        return None;
    }
    let di = i.v.map(|x| pj.eval(x));
    if !di.iter().any(|&d| d > ON_PLANE) {
        return None;
    }
    let mut planes = vec![pi, pj];
    for (a, b, a_is_i) in [(i, j, true), (j, i, false)] {
        for e in 0..3 {
            let (p0, p1) = (a.v[e], a.v[(e + 1) % 3]);
            for w in b.v {
                let Some(pl) = Plane::through(p0, p1, w) else {
                    continue;
                };
                let (on_i, on_j) = if a_is_i { (a, b) } else { (b, a) };
                let si = side(on_i, &pl);
                let sj = side(on_j, &pl);
                match (si, sj) {
                    (Side::Positive, Side::Negative) => planes.push(pl),
                    (Side::Negative, Side::Positive) => planes.push(pl.flip()),
                    _ => {}
                }
            }
        }
    }
    dedup(&mut planes);
    Some(planes)
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Side {
    /// Every corner on the positive side or on the plane, one strictly positive.
    Positive,
    /// Every corner on the negative side or on the plane, one strictly negative.
    Negative,
    /// Both sides, or all on the plane.
    Neither,
}

fn side(t: &Tri, pl: &Plane) -> Side {
    let d = t.v.map(|x| pl.eval(x));
    let pos = d.iter().all(|&x| x >= -ON_PLANE);
    let neg = d.iter().all(|&x| x <= ON_PLANE);
    match (pos, neg) {
        (true, false) => Side::Positive,
        (false, true) => Side::Negative,
        // On the plane entirely: on either side, so the plane separates whatever the other is.
        (true, true) => Side::Neither,
        (false, false) => Side::Neither,
    }
}

/// Whether two triangles in one plane (normal `n`) overlap with some area: no edge normal
/// separates them (separating axes in the plane).
fn overlap_in_plane(i: &Tri, j: &Tri, n: DVec3) -> bool {
    for (a, b) in [(i, j), (j, i)] {
        for e in 0..3 {
            let axis = n.cross(a.v[(e + 1) % 3] - a.v[e]);
            let range = |t: &Tri| {
                t.v.iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                        let p = axis.dot(*x);
                        (lo.min(p), hi.max(p))
                    })
            };
            let ((alo, ahi), (blo, bhi)) = (range(a), range(b));
            if ahi <= blo + ON_PLANE || bhi <= alo + ON_PLANE {
                return false;
            }
        }
    }
    true
}

/// Drops planes that repeat an earlier one.
fn dedup(planes: &mut Vec<Plane>) {
    let mut out: Vec<Plane> = Vec::with_capacity(planes.len());
    for p in planes.drain(..) {
        if !out
            .iter()
            .any(|q| (q.n - p.n).length_squared() < 1e-20 && (q.d - p.d).abs() < 1e-12)
        {
            out.push(p);
        }
    }
    *planes = out;
}

/// The vertices of the bounded region where every plane's positive side holds (brute force
/// over triples of planes: the regions here have a few dozen planes).
pub fn vertices(planes: &[Plane]) -> Vec<DVec3> {
    let mut out: Vec<DVec3> = Vec::new();
    let n = planes.len();
    for i in 0..n {
        for j in i + 1..n {
            let nij = planes[i].n.cross(planes[j].n);
            if nij.length_squared() < 1e-20 {
                continue;
            }
            for k in j + 1..n {
                let det = nij.dot(planes[k].n);
                if det.abs() < 1e-10 {
                    continue;
                }
                let x = (planes[i].d * planes[j].n.cross(planes[k].n)
                    + planes[j].d * planes[k].n.cross(planes[i].n)
                    + planes[k].d * nij)
                    / det;
                if planes.iter().all(|p| p.eval(x) >= -ON_PLANE * 100.0)
                    && !out.iter().any(|y| (*y - x).length_squared() < 1e-18)
                {
                    out.push(x);
                }
            }
        }
    }
    out
}

/// The vertices of the region of `planes` when it has volume, else `None`.
pub fn region(planes: &[Plane]) -> Option<Vec<DVec3>> {
    let v = vertices(planes);
    if v.len() < 4 {
        return None;
    }
    let c = v.iter().copied().sum::<DVec3>() / v.len() as f64;
    planes.iter().all(|p| p.eval(c) > INTERIOR).then_some(v)
}

/// The planes of `planes` that bound their region (a facet holds three of `vertices` or more):
/// the others are redundant.
pub fn facets(planes: &[Plane], vertices: &[DVec3]) -> Vec<Plane> {
    planes
        .iter()
        .filter(|p| vertices.iter().filter(|v| p.eval(**v).abs() < 1e-7).count() >= 3)
        .copied()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3], id: u32) -> Tri {
        Tri::new([a.into(), b.into(), c.into()], id)
    }

    fn cube(r: f64) -> Vec<Plane> {
        let mut p = Vec::new();
        for k in 0..3 {
            let mut e = DVec3::ZERO;
            e[k] = 1.0;
            p.push(Plane { n: e, d: -r });
            p.push(Plane { n: -e, d: -r });
        }
        p
    }

    #[test]
    fn a_cube_has_eight_vertices_and_six_facets() {
        let planes = cube(2.0);
        let v = region(&planes).unwrap();
        assert_eq!(v.len(), 8);
        assert_eq!(facets(&planes, &v).len(), 6);
    }

    #[test]
    fn a_triangle_in_front_occludes_one_behind_only_from_the_front() {
        // Both face +z; `front` at z = 1 covers `back` at z = 0.
        let front = tri([-1., -1., 1.], [1., -1., 1.], [0., 1., 1.], 0);
        let back = tri([-1., -1., 0.], [1., -1., 0.], [0., 1., 0.], 1);
        let mut planes = occlusion(&front, &back).expect("front occludes back");
        planes.extend(cube(10.0));
        let v = region(&planes).expect("from above");
        assert!(v.iter().all(|x| x.z >= 1.0 - 1e-9));
        // The viewpoint straight above is inside, one far off to the side is not.
        assert!(planes
            .iter()
            .all(|p| p.eval(DVec3::new(0.0, 0.0, 5.0)) >= 0.0));
        assert!(planes
            .iter()
            .any(|p| p.eval(DVec3::new(9.0, 0.0, 1.5)) < 0.0));
        assert!(
            occlusion(&back, &front).is_none(),
            "back is behind front's plane"
        );
    }

    #[test]
    fn coplanar_triangles_order_by_id_where_they_overlap() {
        let a = tri([0., 0., 0.], [2., 0., 0.], [0., 2., 0.], 3);
        let b = tri([0.5, 0.5, 0.], [2.5, 0.5, 0.], [0.5, 2.5, 0.], 7);
        let far = tri([5., 5., 0.], [6., 5., 0.], [5., 6., 0.], 9);
        assert!(occlusion(&a, &b).is_some());
        assert!(occlusion(&b, &a).is_none());
        assert!(occlusion(&a, &far).is_none(), "no overlap");
        assert!(occlusion(&a, &a.reversed()).is_none());
    }

    #[test]
    fn degenerate_triangles_occlude_nothing() {
        let line = tri([0., 0., 0.], [1., 0., 0.], [2., 0., 0.], 0);
        let t = tri([-1., -1., -1.], [1., -1., -1.], [0., 1., -1.], 1);
        assert!(line.plane.is_none());
        assert!(occlusion(&line, &t).is_none() && occlusion(&t, &line).is_none());
    }
}
