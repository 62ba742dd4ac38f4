//! Cutting planes by linear programming (`microlp`): a plane that separates two point sets
//! separates their convex hulls, so the hulls of paper 000's regions need not be built.

use glam::DVec3;
use microlp::{ComparisonOp, OptimizationDirection, Problem};

use crate::geom::Plane;

/// Smallest margin (normalised units) a cutting plane must leave on each side.
pub const MARGIN: f64 = 1e-6;

/// Margin (normalised units) by which two regions may overlap and still count as touching:
/// a cutting plane between them, [`separate`] with `-TOUCH`, leaves each region at most this
/// far on the other side, far below [`crate::geom::INTERIOR`], so the piece of a region cut
/// off on the wrong side has no volume and its occlusion is gone. Regions that touch along
/// a face are common where nearly coplanar neighbours fold (a gently curved pane): every pair
/// of a cycle of three such copies may touch and none overlap, so no plane leaves them
/// [`MARGIN`] apart, while one through their common face separates them.
pub const TOUCH: f64 = 1e-9;

/// A plane with every point of `positive` on its positive side and every point of `negative`
/// on its negative side, each more than `margin` away, maximising that distance (normal
/// bounded per component); `None` when the hulls come closer than that. `margin` is
/// [`MARGIN`] for a clear cut, `-TOUCH` for one between regions that touch.
///
/// By constraint generation: the program is solved over a few extreme points of each set,
/// then the points its plane violates are added and it is solved again, until none is
/// violated. A plane optimal for a subset of the constraints that satisfies them all is
/// optimal for all of them, and a subset without a separating plane means the whole has none;
/// the programs stay a few dozen constraints where the sets have thousands of points.
pub fn separate(negative: &[DVec3], positive: &[DVec3], margin: f64) -> Option<Plane> {
    let sets = [(negative, -1.0), (positive, 1.0)];
    let mut working: [Vec<usize>; 2] = [extremes(negative), extremes(positive)];
    // At a margin of zero or less the null plane (normal 0, margin 0) is a solution: the
    // normal is then held to lean from the negative set's centroid towards the positive's
    // (as every separating plane's does, for sets with volume).
    let along = (margin <= 0.0).then(|| {
        let centroid = |v: &[DVec3]| v.iter().copied().sum::<DVec3>() / v.len().max(1) as f64;
        (centroid(positive) - centroid(negative)).normalize_or_zero()
    });
    if along == Some(DVec3::ZERO) {
        return None;
    }
    let (normal, d, s) = loop {
        let (normal, d, s) = solve(&sets, &working, along)?;
        let mut added = false;
        for ((points, sign), w) in sets.iter().zip(&mut working) {
            let mut violated: Vec<(f64, usize)> = points
                .iter()
                .enumerate()
                .map(|(k, p)| (sign * (normal.dot(*p) - d) - s, k))
                .filter(|(slack, _)| *slack < -1e-12)
                .collect();
            violated.sort_by(|a, b| a.0.total_cmp(&b.0));
            for &(_, k) in violated.iter().take(16) {
                if !w.contains(&k) {
                    w.push(k);
                    added = true;
                }
            }
        }
        if !added {
            break (normal, d, s);
        }
    };
    let len = normal.length();
    if !(s / len.max(1e-300) > margin && len > 1e-12) {
        return None;
    }
    let plane = Plane {
        n: normal / len,
        d: d / len,
    };
    // Trust, but check: the LP's tolerance is absolute.
    let least = margin.min(MARGIN * 0.5);
    let ok = negative.iter().all(|p| -plane.eval(*p) > least)
        && positive.iter().all(|p| plane.eval(*p) > least);
    ok.then_some(plane)
}

/// The indices of `points` extreme along the axes and the cube's diagonals (the first
/// constraints of [`separate`]).
fn extremes(points: &[DVec3]) -> Vec<usize> {
    let mut out: Vec<usize> = Vec::new();
    if points.is_empty() {
        return out;
    }
    let mut directions: Vec<DVec3> = vec![DVec3::X, DVec3::Y, DVec3::Z];
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            directions.push(DVec3::new(sx, sy, 1.0));
        }
    }
    for dir in directions {
        for sign in [-1.0, 1.0] {
            let best = (0..points.len())
                .max_by(|&a, &b| {
                    (sign * dir.dot(points[a])).total_cmp(&(sign * dir.dot(points[b])))
                })
                .expect("points");
            if !out.contains(&best) {
                out.push(best);
            }
        }
    }
    out
}

/// The program over the working sets' points: (normal, offset, margin) maximising the margin,
/// or `None` when it has no solution; with `along`, the normal's component along it is 1/2.
fn solve(
    sets: &[(&[DVec3], f64); 2],
    working: &[Vec<usize>; 2],
    along: Option<DVec3>,
) -> Option<(DVec3, f64, f64)> {
    let mut lp = Problem::new(OptimizationDirection::Maximize);
    let n = [
        lp.add_var(0.0, (-1.0, 1.0)),
        lp.add_var(0.0, (-1.0, 1.0)),
        lp.add_var(0.0, (-1.0, 1.0)),
    ];
    let d = lp.add_var(0.0, (f64::NEG_INFINITY, f64::INFINITY));
    let s = lp.add_var(1.0, (f64::NEG_INFINITY, 1.0));
    for ((points, sign), w) in sets.iter().zip(working) {
        for &k in w {
            let p = points[k];
            // sign · (n · p − d) ≥ s
            lp.add_constraint(
                [
                    (n[0], sign * p.x),
                    (n[1], sign * p.y),
                    (n[2], sign * p.z),
                    (d, -sign),
                    (s, -1.0),
                ],
                ComparisonOp::Ge,
                0.0,
            );
        }
    }
    if let Some(u) = along {
        lp.add_constraint(
            [(n[0], u.x), (n[1], u.y), (n[2], u.z)],
            ComparisonOp::Eq,
            0.5,
        );
    }
    let solution = lp.solve().ok()?.into_solution().ok()?;
    let normal = DVec3::new(
        solution.var_value(n[0]),
        solution.var_value(n[1]),
        solution.var_value(n[2]),
    );
    Some((normal, solution.var_value(d), solution.var_value(s)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separates_two_boxes_and_not_overlapping_ones() {
        let a = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 1.0),
        ];
        let b: Vec<DVec3> = a.iter().map(|p| *p + DVec3::new(3.0, 0.0, 0.0)).collect();
        let p = separate(&a, &b, MARGIN).expect("disjoint");
        assert!(a.iter().all(|x| p.eval(*x) < 0.0) && b.iter().all(|x| p.eval(*x) > 0.0));
        // Moved within its own plane (normal (1, -1, 1)): the triangles overlap.
        let c: Vec<DVec3> = a.iter().map(|p| *p + DVec3::new(0.3, 0.3, 0.0)).collect();
        assert!(separate(&a, &c, MARGIN).is_none());
    }

    #[test]
    fn touching_boxes_separate_only_when_touching_is_allowed() {
        let cube = |x0: f64| -> Vec<DVec3> {
            (0..8)
                .map(|k| DVec3::new(x0 + (k & 1) as f64, ((k >> 1) & 1) as f64, (k >> 2) as f64))
                .collect()
        };
        // Sharing the face x = 1.
        let (a, b) = (cube(0.0), cube(1.0));
        assert!(separate(&a, &b, MARGIN).is_none());
        let p = separate(&a, &b, -TOUCH).expect("they only touch");
        assert!(a.iter().all(|x| p.eval(*x) < TOUCH) && b.iter().all(|x| p.eval(*x) > -TOUCH));
        // Overlapping by more than the allowance.
        assert!(separate(&a, &cube(1.0 - 1e-6), -TOUCH).is_none());
    }
}
