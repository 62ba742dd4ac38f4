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
pub fn separate(negative: &[DVec3], positive: &[DVec3]) -> Option<Plane> {
    let mut lp = Problem::new(OptimizationDirection::Maximize);
    let n = [
        lp.add_var(0.0, (-1.0, 1.0)),
        lp.add_var(0.0, (-1.0, 1.0)),
        lp.add_var(0.0, (-1.0, 1.0)),
    ];
    let d = lp.add_var(0.0, (f64::NEG_INFINITY, f64::INFINITY));
    let s = lp.add_var(1.0, (f64::NEG_INFINITY, 1.0));
    for (points, sign) in [(negative, -1.0), (positive, 1.0)] {
        for p in points {
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
    let len = normal.length();
    let margin = solution.var_value(s) / len.max(1e-300);
    if !(margin > MARGIN && len > 1e-12) {
        return None;
    }
    let plane = Plane {
        n: normal / len,
        d: solution.var_value(d) / len,
    };
    // Trust, but check: the LP's tolerance is absolute.
    let ok = negative.iter().all(|p| plane.eval(*p) < -MARGIN * 0.5)
        && positive.iter().all(|p| plane.eval(*p) > MARGIN * 0.5);
    ok.then_some(plane)
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
