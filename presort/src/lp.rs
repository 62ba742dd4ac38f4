//! Cutting planes by linear programming (`microlp`): a plane that separates two point sets
//! separates their convex hulls, so the hulls of paper 000's regions need not be built.

use glam::DVec3;
use microlp::{ComparisonOp, OptimizationDirection, Problem};

use crate::geom::Plane;

/// Smallest margin (normalised units) a cutting plane must leave on each side.
pub const MARGIN: f64 = 1e-6;

/// A plane with every point of `positive` on its positive side and every point of `negative`
/// on its negative side, each at least [`MARGIN`] away, maximising that margin (normal bounded
/// per component); `None` when the hulls come closer than that (they overlap or touch).
///
/// By constraint generation: the program is solved over a few extreme points of each set,
/// then the points its plane violates are added and it is solved again, until none is
/// violated. A plane optimal for a subset of the constraints that satisfies them all is
/// optimal for all of them, and a subset without a separating plane means the whole has none;
/// the programs stay a few dozen constraints where the sets have thousands of points.
pub fn separate(negative: &[DVec3], positive: &[DVec3]) -> Option<Plane> {
    let sets = [(negative, -1.0), (positive, 1.0)];
    let mut working: [Vec<usize>; 2] = [extremes(negative), extremes(positive)];
    let (normal, d, s) = loop {
        let (normal, d, s) = solve(&sets, &working)?;
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
    let margin = s / len.max(1e-300);
    if !(margin > MARGIN && len > 1e-12) {
        return None;
    }
    let plane = Plane {
        n: normal / len,
        d: d / len,
    };
    // Trust, but check: the LP's tolerance is absolute.
    let ok = negative.iter().all(|p| plane.eval(*p) < -MARGIN * 0.5)
        && positive.iter().all(|p| plane.eval(*p) > MARGIN * 0.5);
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
/// or `None` when it has no solution.
fn solve(sets: &[(&[DVec3], f64); 2], working: &[Vec<usize>; 2]) -> Option<(DVec3, f64, f64)> {
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
        let p = separate(&a, &b).expect("disjoint");
        assert!(a.iter().all(|x| p.eval(*x) < 0.0) && b.iter().all(|x| p.eval(*x) > 0.0));
        // Moved within its own plane (normal (1, -1, 1)): the triangles overlap.
        let c: Vec<DVec3> = a.iter().map(|p| *p + DVec3::new(0.3, 0.3, 0.0)).collect();
        assert!(separate(&a, &c).is_none());
    }
}
