//! The order of the conservative recording's grown fragments, pair by pair where each
//! pair's order holds over the whole box around the sample ([`GrownOrder`]).

use glam::{DVec2, DVec3};
use trisort_format::{FrameState, RecordSettings};
use trisort_gpu::raster_probe::standard_location;

use super::{Relation, TieRule};

/// How many earlier fragments of a sample's grown list [`GrownOrder::push`] orders a
/// fragment against by geometry, where their depth ranges over the box overlap (ranges apart
/// are ordered up to [`REACH_BACK`] back).
pub const LOOK_BACK: usize = 8;

/// How far back in a sample's grown list [`GrownOrder::push`] looks for fragments whose
/// ranges lie apart from the new one's at most. The look stops earlier where everything before
/// is ordered through what it found; wide boxes (the `browser` profile's whole pixel) over
/// lists of hundreds (CarConcept at 128²) would otherwise look back over every fragment.
pub const REACH_BACK: usize = 64;

/// Window depths of two planes closer than this at a point are taken as equal there (they
/// meet: f64 rounding; the rasterizer's f32 depth steps are 60 times coarser near 1).
const TOUCH: f64 = 1e-9;

/// Depths closer than this (window depth) are not taken to order two grown fragments: the
/// rasterizer's f32 depths and the host's f64 spread differ by some ulps.
const DEPTH_SLACK: f32 = 1e-6;

/// The order of the conservative recording's grown fragments (phase 2's grown capture and
/// grown peel, `graph_frame` in `graph.rs`), as edges.
///
/// A grown fragment may come from a triangle that does not cover the sample, at its plane's
/// depth extended to the sample. Two such depths order the pair where both cover only if the
/// planes do not cross over the sample's box, and a chain of consecutive fragments orders
/// pairs that never cover one point together: on CarConcept, the coplanar pieces of a panel
/// that the splitter cut along a surface passing through it lie at equal depths, and the chain
/// put the piece behind that surface in front of it, where a sample moved by 1/512 px showed
/// the other order (BENCHMARKS § Raster profiles, "Grown order"). So fragments are ordered a
/// pair at a time, each pair only where its order holds wherever both triangles cover a point
/// of the box around the sample ([`Robust::depth_box`](trisort_format::Robust::depth_box)):
/// - their planes' depth ranges over the box lie apart: the nearer first. These orders compose
///   (an interval order), so only the nearest of them become edges, and the rest follow
///   through those, up to [`REACH_BACK`] fragments back;
/// - the ranges overlap (one of the [`LOOK_BACK`] fragments before): the part of the box both
///   projected triangles cover is clipped out, and where one plane is nearer at every corner
///   of it, that one first; where they cover none of it together, no edge (a fan's
///   neighbours); where the planes cross inside it, a separable pair's
///   ([`Relation::Separable`]) eye-side one first, else no edge (they pass through each other
///   there: the splitter's part).
pub struct GrownOrder<'r> {
    rule: &'r TieRule,
    /// Per drawn triangle: how far its plane's window depth moves over the box (∞ where the
    /// plane passes through the eye or is degenerate).
    spread: Vec<f32>,
    /// Per drawn triangle: its plane's window depth as `z = [0] + [1] x + [2] y` in pixels (x
    /// right, y down), `None` where the plane passes through the eye or is degenerate.
    depth_planes: Vec<Option<[f64; 3]>>,
    /// Per drawn triangle: its corners in pixels, `None` where one lies on or behind the eye
    /// plane (the drawn part is then not their triangle).
    corners: Vec<Option<[DVec2; 3]>>,
    /// Half-size of the box in pixels (`Robust::depth_box`).
    reach: f64,
    width: u32,
    samples: u32,
}

/// One grown fragment taken by [`GrownOrder::push`]: drawn position, depth at the sample, its
/// range over the box (near, far), and the farthest `far` up to it in the list.
#[derive(Clone, Copy, Debug)]
struct Taken {
    id: u32,
    near: f32,
    far: f32,
    far_so_far: f32,
}

/// A sample's grown fragments taken so far, for [`GrownOrder::push`].
#[derive(Clone, Debug, Default)]
pub struct GrownList {
    taken: Vec<Taken>,
}

impl GrownList {
    /// Empties the list for the next sample.
    pub fn clear(&mut self) {
        self.taken.clear();
    }
}

impl<'r> GrownOrder<'r> {
    /// The order for `rule`'s drawn list at `frame` (the rule's own frame), recorded with
    /// `settings` (image size, samples, the robust settings' box).
    pub fn new(rule: &'r TieRule, frame: &FrameState, settings: &RecordSettings) -> GrownOrder<'r> {
        let (w, h) = (settings.width.max(1) as f64, settings.height.max(1) as f64);
        let reach = settings.robust.depth_box() as f64;
        // The rule's corners are world minus eye; the view's rotation makes them view space.
        let view = frame.camera.view_matrix();
        let proj = frame.camera.projection(w / h);
        // Window depth is affine in 1/w: z = a + b / w (w = −z in view space).
        let depth_at = |d: f64| proj.project_point3(DVec3::new(0.0, 0.0, -d)).z;
        let b = 2.0 * (depth_at(1.0) - depth_at(2.0));
        let a = depth_at(1.0) - b;
        // A point of plane n·X = d seen at (x, y) in NDC has 1/w = (n.x x tx + n.y y ty − n.z)
        // / d, with tx = 1 / proj[0][0] and ty = 1 / proj[1][1]; NDC x = 2 px / width − 1,
        // y = 1 − 2 py / height.
        let (tx, ty) = (1.0 / proj.x_axis.x, 1.0 / proj.y_axis.y);
        let n = rule.planes.len();
        let mut spread = Vec::with_capacity(n);
        let mut depth_planes = Vec::with_capacity(n);
        let mut corners = Vec::with_capacity(n);
        for plane in &rule.planes {
            let Some(triangle) = plane else {
                // Degenerate in f64: no plane to order by, nothing it covers.
                spread.push(f32::INFINITY);
                depth_planes.push(None);
                corners.push(None);
                continue;
            };
            let c = triangle.corners.map(|p| view.transform_vector3(p));
            let n = (c[1] - c[0]).cross(c[2] - c[0]);
            let d = n.dot(c[0]);
            let plane = [
                a + b * (-n.x * tx + n.y * ty - n.z) / d,
                b * n.x * tx / d * 2.0 / w,
                -b * n.y * ty / d * 2.0 / h,
            ];
            let ok = n != DVec3::ZERO && plane.iter().all(|x| x.is_finite());
            depth_planes.push(ok.then_some(plane));
            let s = (plane[1].abs() + plane[2].abs()) * reach;
            spread.push(if ok && s.is_finite() {
                s as f32
            } else {
                f32::INFINITY
            });
            let on_screen = c.map(|p| {
                let clip = proj * p.extend(1.0);
                (clip.w > 0.0).then(|| {
                    let ndc = clip.truncate() / clip.w;
                    DVec2::new((ndc.x + 1.0) / 2.0 * w, (1.0 - ndc.y) / 2.0 * h)
                })
            });
            corners.push(match on_screen {
                [Some(p0), Some(p1), Some(p2)] => Some([p0, p1, p2]),
                _ => None,
            });
        }
        GrownOrder {
            rule,
            spread,
            depth_planes,
            corners,
            reach,
            width: settings.width,
            samples: settings.samples,
        }
    }

    /// The position in pixels of the sample in image slot `slot` (`(y · width + x) · samples
    /// + s`), at the standard sample locations.
    fn sample_position(&self, slot: usize) -> DVec2 {
        let samples = self.samples.max(1) as usize;
        let pixel = slot / samples;
        let (x, y) = (pixel % self.width as usize, pixel / self.width as usize);
        let [sx, sy] = standard_location(self.samples, (slot % samples) as u32);
        DVec2::new(x as f64 + sx, y as f64 + sy)
    }

    /// Whether drawn triangle `p` lies in front of `q` wherever both cover a point of the box
    /// around `at` (`Some(true)`), behind (`Some(false)`), or neither is known: they cover no
    /// point of it together, or their planes cross where they do (then the rule's separable
    /// verdict, if it has one, as the f64 depths there are within rounding of each other).
    fn in_front(&self, p: u32, q: u32, at: DVec2) -> Option<bool> {
        let (pu, qu) = (p as usize, q as usize);
        if let (Some(cp), Some(cq), Some(zp), Some(zq)) = (
            self.corners[pu],
            self.corners[qu],
            self.depth_planes[pu],
            self.depth_planes[qu],
        ) {
            let r = self.reach;
            let mut poly = vec![
                at + DVec2::new(-r, -r),
                at + DVec2::new(r, -r),
                at + DVec2::new(r, r),
                at + DVec2::new(-r, r),
            ];
            for c in [cp, cq] {
                clip_by_triangle(&mut poly, &c);
            }
            if polygon_area(&poly) <= 1e-12 {
                return None;
            }
            let diff = |v: &DVec2| (zp[0] - zq[0]) + (zp[1] - zq[1]) * v.x + (zp[2] - zq[2]) * v.y;
            // Touching along the part's border (a shared edge, where the difference is 0 up
            // to f64 rounding) still orders the inside.
            let d: Vec<f64> = poly.iter().map(diff).collect();
            if d.iter().all(|&x| x <= TOUCH) && d.iter().any(|&x| x < -TOUCH) {
                return Some(true);
            }
            if d.iter().all(|&x| x >= -TOUCH) && d.iter().any(|&x| x > TOUCH) {
                return Some(false);
            }
        }
        match self.rule.relation(p, q) {
            Relation::Separable { first } => Some(first == p),
            Relation::Coplanar | Relation::Neither => None,
        }
    }

    /// Takes fragment `next` (drawn position, depth) of the grown list of the sample in image
    /// slot `slot` (`(y · width + x) · samples + s`), in peel order ((depth, id) ascending),
    /// after the fragments `list` holds, and calls `edge(front, back)` for each order it finds
    /// against them (see [`GrownOrder`]).
    pub fn push(
        &self,
        list: &mut GrownList,
        slot: usize,
        next: (u32, f32),
        mut edge: impl FnMut(u32, u32),
    ) {
        let (id, depth) = next;
        let spread = self.spread[id as usize] + DEPTH_SLACK / 2.0;
        let (near, far) = (depth - spread, depth + spread);
        // The nearest `near` of the ranges found apart so far: one that ends before it lies
        // in front of that one, and is ordered through it.
        let mut cover = f32::NEG_INFINITY;
        let mut at = None;
        for (back, t) in list.taken.iter().rev().enumerate() {
            if t.far_so_far < cover || back >= REACH_BACK {
                break;
            }
            if t.id == id {
                continue;
            }
            if t.far < near {
                if t.far >= cover {
                    edge(t.id, id);
                    cover = cover.max(t.near);
                }
            } else if back < LOOK_BACK {
                let at = *at.get_or_insert_with(|| self.sample_position(slot));
                match self.in_front(t.id, id, at) {
                    Some(true) => edge(t.id, id),
                    Some(false) => edge(id, t.id),
                    None => {}
                }
            }
        }
        let far_so_far = list.taken.last().map_or(far, |t| t.far_so_far.max(far));
        list.taken.push(Taken {
            id,
            near,
            far,
            far_so_far,
        });
    }
}

/// Clips convex polygon `poly` (pixels) to triangle `c`, in place (Sutherland–Hodgman).
fn clip_by_triangle(poly: &mut Vec<DVec2>, c: &[DVec2; 3]) {
    let orient = (c[1] - c[0]).perp_dot(c[2] - c[0]).signum();
    if orient == 0.0 {
        poly.clear();
        return;
    }
    let mut out = Vec::with_capacity(poly.len() + 3);
    for k in 0..3 {
        let (a, b) = (c[k], c[(k + 1) % 3]);
        let side = |v: DVec2| orient * (b - a).perp_dot(v - a);
        out.clear();
        for i in 0..poly.len() {
            let (u, v) = (poly[i], poly[(i + 1) % poly.len()]);
            let (su, sv) = (side(u), side(v));
            if su >= 0.0 {
                out.push(u);
            }
            if (su >= 0.0) != (sv >= 0.0) {
                out.push(u + (v - u) * (su / (su - sv)));
            }
        }
        std::mem::swap(poly, &mut out);
        if poly.is_empty() {
            return;
        }
    }
}

/// The area of polygon `poly` (shoelace), 0 with fewer than 3 corners.
fn polygon_area(poly: &[DVec2]) -> f64 {
    if poly.len() < 3 {
        return 0.0;
    }
    let twice: f64 = (0..poly.len())
        .map(|i| poly[i].perp_dot(poly[(i + 1) % poly.len()]))
        .sum();
    twice.abs() / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An order over `n` triangles whose screen corners and depth planes are given directly.
    fn grown<'r>(
        rule: &'r TieRule,
        corners: Vec<Option<[DVec2; 3]>>,
        depth_planes: Vec<[f64; 3]>,
        reach: f64,
    ) -> GrownOrder<'r> {
        let spread = depth_planes
            .iter()
            .map(|p| ((p[1].abs() + p[2].abs()) * reach) as f32)
            .collect();
        GrownOrder {
            rule,
            spread,
            depth_planes: depth_planes.into_iter().map(Some).collect(),
            corners,
            reach,
            width: 64,
            samples: 1,
        }
    }

    fn pushed(order: &GrownOrder, slot: usize, list: &[(u32, f32)]) -> Vec<(u32, u32)> {
        let mut edges = Vec::new();
        let mut taken = GrownList::default();
        for &f in list {
            order.push(&mut taken, slot, f, |a, b| edges.push((a, b)));
        }
        edges.sort_unstable();
        edges
    }

    #[test]
    fn a_fans_pieces_are_not_chained_past_a_surface_between_them() {
        // Pieces 0 (x < 10.5) and 1 (x > 10.5) of a panel at depth 0.5, sharing the edge at
        // x = 10.5; surface 2 covers both, rising through the panel along that edge: in front
        // of piece 1, behind piece 0. The sample at (10.5, 10.5) (slot 10 · 64 + 10 of a
        // 64-wide image at 1×) lists 0, 1, 2 by depth there: the chain would say 1 before 2.
        let big = |x0: f64, x1: f64| {
            Some([
                DVec2::new(x0, 0.0),
                DVec2::new(x1, 0.0),
                DVec2::new(x0, 30.0),
            ])
        };
        let corners = vec![
            Some([
                DVec2::new(0.0, 0.0),
                DVec2::new(10.5, 0.0),
                DVec2::new(10.5, 30.0),
            ]),
            Some([
                DVec2::new(10.5, 0.0),
                DVec2::new(30.0, 0.0),
                DVec2::new(10.5, 30.0),
            ]),
            big(0.0, 60.0),
        ];
        let planes = vec![
            [0.5, 0.0, 0.0],
            [0.5, 0.0, 0.0],
            // 0.5 at x = 10.5, nearer to the right.
            [0.5 + 0.01 * 10.5, -0.01, 0.0],
        ];
        // Planes that the rule cannot order (no camera-space triangles): geometry only.
        let r = TieRule {
            planes: vec![None; 3],
            moves: None,
        };
        let order = grown(&r, corners, planes, 1.0 / 256.0);
        let slot = 10 * 64 + 10;
        let edges = pushed(&order, slot, &[(0, 0.5), (1, 0.5), (2, 0.500001)]);
        assert_eq!(
            edges,
            vec![(0, 2), (2, 1)],
            "0 before 2 before 1, and 0, 1 unordered"
        );
    }

    #[test]
    fn ranges_apart_are_ordered_through_the_nearest_however_far_back() {
        // Ten flat, overlapping triangles at growing depths, all far apart: only consecutive
        // edges, yet every pair is ordered through them.
        let tri = Some([
            DVec2::new(0.0, 0.0),
            DVec2::new(60.0, 0.0),
            DVec2::new(0.0, 60.0),
        ]);
        let r = TieRule {
            planes: vec![None; 10],
            moves: None,
        };
        let depth = |k: u32| 0.1 + 0.05 * k as f64;
        let planes: Vec<[f64; 3]> = (0..10).map(|k| [depth(k), 0.0, 0.0]).collect();
        let list: Vec<(u32, f32)> = (0..10).map(|k| (k, depth(k) as f32)).collect();
        let order = grown(&r, vec![tri; 10], planes, 1.0 / 256.0);
        let edges = pushed(&order, 5 * 64 + 5, &list);
        let want: Vec<(u32, u32)> = (0..9).map(|k| (k, k + 1)).collect();
        assert_eq!(edges, want);
        // Triangle 3 steep: its range overlaps those of 2 and 4, which its plane orders
        // (farther than 2, nearer than 4 over the whole part they share); 1 before it and 5
        // after it by ranges, and 2 before 4 directly, as 3 no longer links them.
        let mut order = order;
        order.spread[3] = 0.06;
        let edges = pushed(&order, 5 * 64 + 5, &list);
        for e in [(1, 3), (2, 3), (3, 4), (3, 5), (2, 4)] {
            assert!(edges.contains(&e), "{e:?} missing from {edges:?}");
        }
        assert!(
            !edges.contains(&(4, 3)) && !edges.contains(&(0, 3)),
            "{edges:?}"
        );
    }

    #[test]
    fn clipping_keeps_the_common_part_of_box_and_triangle() {
        let mut poly = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(0.0, 2.0),
        ];
        // Clockwise or not, the half of the square below its diagonal.
        for c in [
            [
                DVec2::new(-1.0, -1.0),
                DVec2::new(5.0, 5.0),
                DVec2::new(5.0, -1.0),
            ],
            [
                DVec2::new(-1.0, -1.0),
                DVec2::new(5.0, -1.0),
                DVec2::new(5.0, 5.0),
            ],
        ] {
            let mut p = poly.clone();
            clip_by_triangle(&mut p, &c);
            assert!((polygon_area(&p) - 2.0).abs() < 1e-12, "{p:?}");
        }
        // A triangle beside the square: nothing left.
        clip_by_triangle(
            &mut poly,
            &[
                DVec2::new(3.0, 0.0),
                DVec2::new(4.0, 0.0),
                DVec2::new(3.0, 1.0),
            ],
        );
        assert_eq!(polygon_area(&poly), 0.0);
    }
}
