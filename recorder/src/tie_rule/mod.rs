//! The tie rule: one order for fragments the rasterizer's depths
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

mod grown;

use glam::{DMat4, DVec3};
use trisort_format::{world_transforms, FrameState, Geometry};

pub use grown::{GrownList, GrownOrder, LOOK_BACK, REACH_BACK};

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
}
