//! The tie rule (DESIGN § Recorder, "Ties"): one order for fragments the rasterizer's depths
//! cannot be trusted to order, used alike by the recorder's phase 2 (capture and peel, the
//! grown capture included) and the exact reference (`blend` and `saturate` composite in it;
//! `depth` lets through, in it, what the depth test would).
//!
//! At a sample the peel lists fragments by (depth, id). Two of them next to each other, `p`
//! then `q`, are put the other way round, whatever their depths (an exact tie included), when
//! their triangles, in camera space,
//! - lie in one plane (each corner of each within 10⁻⁶ of the larger triangle's longest edge
//!   of the other's plane: a decal on its panel) and `q` has the lower id: coplanar surfaces
//!   are layered in glTF order, the earlier on top, wherever rounding puts their depths; or
//! - are *separable*: one lies wholly on one side of the other's plane (beyond that tolerance
//!   where it does not touch it), and `q` is the one on the eye's side. Where both cover a
//!   point, that one is nearer, so this is their order at every sample: two triangles sharing
//!   a corner or an edge (a panel meeting its neighbour at a crease, a door at its hinge) whose
//!   interpolated depths cross in the last bits near the shared corner, and the conservative
//!   recording's depths extended past a triangle's edges, no longer give both orders.
//!
//! Pairs that pass through each other (the splitter cut those it found) or are skew keep the
//! rasterizer's order. Applied as an insertion sort with the rule as the comparison of adjacent
//! fragments; a fragment moves up only past fragments the rule puts after it, at most
//! [`MOVES`] places.
//!
//! Phase 1 (visibility) peels in the rasterizer's order, so the rule can bring a triangle that
//! phase 1 found hidden to the front of a sample: phase 2 walks each sample's list in the
//! rule's order until it saturates, as phase 1 does, and what it reaches joins V_f. The
//! reference lets the rule move only triangles of the recording's V_f
//! ([`TieRule::moving_only`]): the player draws no other, and one the recorder moved but did
//! not reach lies past saturation, where order changes no pixel.
//!
//! Measured on CarConcept (BENCHMARKS § Raster profiles, "Ties"): every edge the merger had to
//! leave unordered in the close-up, at the recorded pattern and conformantly, was one of a
//! separable pair; with the rule none is left.

use glam::{DMat4, DVec2, DVec3};
use trisort_format::{world_transforms, FrameState, Geometry, RecordSettings};
use trisort_gpu::raster_probe::standard_location;

/// How two triangles lie in camera space ([`TieRule::relation`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Relation {
    /// Each lies in the other's plane (within 10⁻⁶ of the pair's longest edge).
    Coplanar,
    /// One lies wholly on one side of the other's plane: `first` (a drawn position) is on the
    /// eye's side, so it is nearer wherever both cover a point.
    Separable {
        /// The one in front.
        first: u32,
    },
    /// Each crosses the other's plane (they pass through each other, or are skew), or one is
    /// degenerate: no order holds everywhere.
    Neither,
}

/// A triangle in camera space (eye at the origin): corners, unit normal, longest edge.
#[derive(Clone, Copy, Debug)]
struct Plane {
    corners: [DVec3; 3],
    normal: DVec3,
    size: f64,
}

/// The tie rule for one frame over a drawn list of triangles (positions in the list are the
/// fragment ids, 0-based).
pub struct TieRule {
    /// Per drawn triangle: its plane, `None` when degenerate in f64.
    planes: Vec<Option<Plane>>,
    /// Per drawn triangle: whether the rule may move it up ([`TieRule::moving_only`]).
    moves: Option<Vec<bool>>,
}

/// How close to a plane, relative to the pair's longest edge, a corner counts as in it.
const IN_PLANE: f64 = 1e-6;

impl TieRule {
    /// The rule at `frame` for `triangles` (scene ids, in draw order) of `geometry`.
    pub fn new(geometry: &Geometry, triangles: &[u32], frame: &FrameState) -> TieRule {
        let world: Vec<DMat4> = world_transforms(&geometry.nodes, &frame.poses);
        let eye = frame.camera.eye();
        let planes = triangles
            .iter()
            .map(|&t| {
                let corners = geometry.triangles[t as usize].map(|v| {
                    let v = &geometry.vertices[v as usize];
                    let p = DVec3::from(v.position.map(f64::from));
                    world[v.node as usize].transform_point3(p) - eye
                });
                let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
                let size = (corners[1] - corners[0])
                    .length()
                    .max((corners[2] - corners[1]).length())
                    .max((corners[0] - corners[2]).length());
                let normal = normal.try_normalize()?;
                (size.is_finite() && size > 0.0).then_some(Plane {
                    corners,
                    normal,
                    size,
                })
            })
            .collect();
        TieRule {
            planes,
            moves: None,
        }
    }

    /// The rule moving up only the drawn triangles `moves` marks (the frame's visible set V_f,
    /// which is all the player draws): one it leaves unmarked keeps the rasterizer's place.
    /// The reference marks the recording's V_f (see the module documentation).
    pub fn moving_only(mut self, moves: Vec<bool>) -> TieRule {
        self.moves = Some(moves);
        self
    }

    /// Whether fragment `q` (a drawn position), listed right after `p` at a sample, comes
    /// first by the rule.
    pub fn precedes(&self, q: u32, p: u32) -> bool {
        if let Some(m) = &self.moves {
            if !m.get(q as usize).copied().unwrap_or(false) {
                return false;
            }
        }
        match self.relation(p, q) {
            Relation::Coplanar => q < p,
            Relation::Separable { first } => first == q,
            Relation::Neither => false,
        }
    }

    /// How drawn triangles `p` and `q` lie in camera space (see the module documentation):
    /// in one plane, separable (with the one on the eye's side), or neither (crossing, skew or
    /// degenerate). Symmetric in `p` and `q`.
    pub fn relation(&self, p: u32, q: u32) -> Relation {
        let (Some(Some(a)), Some(Some(b))) =
            (self.planes.get(p as usize), self.planes.get(q as usize))
        else {
            return Relation::Neither;
        };
        let eps = IN_PLANE * a.size.max(b.size);
        let sides = |s: &Plane, o: &Plane| o.corners.map(|c| s.normal.dot(c - s.corners[0]));
        let (q_of_p, p_of_q) = (sides(a, b), sides(b, a));
        let flat = |d: &[f64; 3]| d.iter().all(|x| x.abs() <= eps);
        if flat(&q_of_p) && flat(&p_of_q) {
            return Relation::Coplanar;
        }
        // The side of plane `s` that triangle `o` lies on (+1, −1), if it lies on one, not in it.
        let side = |d: &[f64; 3]| -> Option<f64> {
            if d.iter().all(|&x| x >= -eps) && d.iter().any(|&x| x > eps) {
                Some(1.0)
            } else if d.iter().all(|&x| x <= eps) && d.iter().any(|&x| x < -eps) {
                Some(-1.0)
            } else {
                None
            }
        };
        // The eye's side of plane `s` (the eye is the origin), if it is not in it.
        let eye = |s: &Plane| {
            let e = -s.normal.dot(s.corners[0]);
            (e.abs() > eps).then_some(e.signum())
        };
        let first = if let (Some(q_side), Some(e)) = (side(&q_of_p), eye(a)) {
            if q_side == e {
                q
            } else {
                p
            }
        } else if let (Some(p_side), Some(e)) = (side(&p_of_q), eye(b)) {
            if p_side == e {
                p
            } else {
                q
            }
        } else {
            return Relation::Neither;
        };
        Relation::Separable { first }
    }

    /// Takes fragment `next` (drawn position, depth) of a sample whose earlier fragments went
    /// through `window`, in peel order ((depth, id) ascending), and returns the fragment that
    /// leaves the window, if one does: fragments come out in the rule's order. `next` moves up
    /// past the fragments before it that the rule puts after it, at most [`MOVES`] places (the
    /// depth rides along; the rule does not read it); the oldest of a full window can then move no more. The same
    /// order whether a sample's fragments come as one list (a capture) or a layer at a time
    /// (a peel). [`Window::drain`] empties it at the end of the sample.
    pub fn push<T: Copy + Default>(
        &self,
        window: &mut Window<T>,
        next: (u32, T),
    ) -> Option<(u32, T)> {
        push_with(&|q, p| self.precedes(q, p), window, next)
    }

    /// Puts `list` (one sample's fragments in peel order) in the rule's order, in place: the
    /// order [`TieRule::push`] gives them one at a time (an insertion sort in which a fragment
    /// moves up at most [`MOVES`] places), with `id` reading a fragment's drawn position.
    pub fn order<T>(&self, list: &mut [T], id: impl Fn(&T) -> u32) {
        for i in 1..list.len() {
            let window = &mut list[i.saturating_sub(MOVES)..=i];
            bubble_last(window, |q, p| self.precedes(id(q), id(p)));
        }
    }
}

/// [`TieRule::push`] with `precedes` as the rule.
fn push_with<T: Copy + Default>(
    precedes: &impl Fn(u32, u32) -> bool,
    window: &mut Window<T>,
    next: (u32, T),
) -> Option<(u32, T)> {
    let n = window.len as usize;
    let mut all = [(0u32, T::default()); MOVES + 1];
    all[..n].copy_from_slice(&window.items[..n]);
    all[n] = next;
    bubble_last(&mut all[..=n], |q, p| precedes(q.0, p.0));
    if n == MOVES {
        window.items.copy_from_slice(&all[1..]);
        Some(all[0])
    } else {
        window.items[..=n].copy_from_slice(&all[..=n]);
        window.len += 1;
        None
    }
}

/// Moves the last element of `s` up past every element before it that `precedes(last,
/// earlier)` puts after it, stopping at the first that it does not: the one step of the
/// rule's insertion sort that both [`TieRule::order`] and [`TieRule::push`] take.
fn bubble_last<T>(s: &mut [T], precedes: impl Fn(&T, &T) -> bool) {
    let mut j = s.len().saturating_sub(1);
    while j > 0 && precedes(&s[j], &s[j - 1]) {
        s.swap(j - 1, j);
        j -= 1;
    }
}

/// How many places the rule moves a fragment up at most (see [`TieRule::push`]).
pub const MOVES: usize = 3;

/// The fragments of one sample not yet in their final place (see [`TieRule::push`]), each a
/// drawn position with what rides along (`T`: a depth, or a depth and an opacity).
#[derive(Clone, Copy, Debug, Default)]
pub struct Window<T: Copy + Default = f32> {
    items: [(u32, T); MOVES],
    len: u8,
}

impl<T: Copy + Default> Window<T> {
    /// The fragments left, in order; empties the window.
    pub fn drain(&mut self) -> impl Iterator<Item = (u32, T)> {
        let items = self.items;
        let n = self.len as usize;
        self.len = 0;
        (0..n).map(move |k| items[k])
    }
}

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
/// grown peel, `graph_frame` in the crate root), as edges.
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

    fn rule(tris: &[[DVec3; 3]]) -> TieRule {
        TieRule {
            planes: tris
                .iter()
                .map(|&corners| {
                    let normal = (corners[1] - corners[0])
                        .cross(corners[2] - corners[0])
                        .try_normalize()?;
                    Some(Plane {
                        corners,
                        normal,
                        size: 1.0,
                    })
                })
                .collect(),
            moves: None,
        }
    }

    fn tri(z0: f64, z1: f64, z2: f64, x: f64) -> [DVec3; 3] {
        [
            DVec3::new(x, 0.0, z0),
            DVec3::new(x + 1.0, 0.0, z1),
            DVec3::new(x, 1.0, z2),
        ]
    }

    #[test]
    fn separable_pairs_take_the_eyes_side_first() {
        // 0 at z = −2, 1 at z = −3 (farther): 0 comes first whichever the list holds first.
        let r = rule(&[tri(-2.0, -2.0, -2.0, 0.0), tri(-3.0, -3.0, -3.0, 0.0)]);
        assert!(r.precedes(0, 1));
        assert!(!r.precedes(1, 0));
        // Sharing a corner, tilted: 1 leans away from the eye from the shared corner.
        let r = rule(&[tri(-2.0, -2.0, -2.0, 0.0), tri(-2.0, -2.5, -2.5, 0.0)]);
        assert!(r.precedes(0, 1));
        assert!(!r.precedes(1, 0));
    }

    #[test]
    fn coplanar_pairs_take_the_lower_id_first() {
        let r = rule(&[tri(-2.0, -2.0, -2.0, 0.3), tri(-2.0, -2.0, -2.0, 0.0)]);
        assert!(r.precedes(0, 1));
        assert!(!r.precedes(1, 0));
    }

    #[test]
    fn crossing_pairs_keep_the_rasterizers_order() {
        // 1 passes through 0's plane and 0 through 1's.
        let r = rule(&[
            tri(-2.0, -2.0, -2.0, 0.0),
            [
                DVec3::new(0.2, 0.2, -1.0),
                DVec3::new(0.4, 0.2, -3.0),
                DVec3::new(0.2, 0.6, -3.0),
            ],
        ]);
        assert!(!r.precedes(0, 1));
        assert!(!r.precedes(1, 0));
    }

    #[test]
    fn order_moves_up_past_what_the_rule_puts_after_exact_ties_included() {
        let r = rule(&[tri(-2.0, -2.0, -2.0, 0.0), tri(-3.0, -3.0, -3.0, 0.0)]);
        let mut list = [(1u32, 0.5f32), (0, 0.5001)];
        r.order(&mut list, |f| f.0);
        assert_eq!(list, [(0, 0.5001), (1, 0.5)]);
        let mut tie = [(1u32, 0.5f32), (0, 0.5)];
        r.order(&mut tie, |f| f.0);
        assert_eq!(
            tie,
            [(0, 0.5), (1, 0.5)],
            "an exact tie too: the rasterizer's depths decide nothing"
        );
    }

    #[test]
    fn a_list_and_a_stream_come_out_alike() {
        // Four planes at growing distance, listed farthest first at depths that say otherwise:
        // the rule reverses them, each moving up at most MOVES places.
        let tris: Vec<[DVec3; 3]> = (0..6)
            .map(|k| tri(-2.0 - k as f64, -2.0 - k as f64, -2.0 - k as f64, 0.0))
            .collect();
        let r = rule(&tris);
        let input: Vec<(u32, f32)> = (0..6u32).rev().map(|k| (k, 0.1 * (6 - k) as f32)).collect();
        let mut list = input.clone();
        r.order(&mut list, |f| f.0);
        let mut window = Window::default();
        let mut stream: Vec<(u32, f32)> = Vec::new();
        for &f in &input {
            stream.extend(r.push(&mut window, f));
        }
        stream.extend(window.drain());
        assert_eq!(list, stream);
        assert_eq!(list[0].0, 2, "moved up {MOVES} places: {list:?}");
    }

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
