//! Conservative visibility by a bound on the opaque envelope (`record --conservative`, phase 1,
//! where the device can capture): the triangles that can be nearest at some point of a
//! sample's tolerance box, with no sample-spacing assumption.
//!
//! One grown capture a frame (`fs_capture_envelope` in `shaders/record/capture_grown.wgsl`)
//! lists, per sample, every triangle that meets the sample's box of ±tolerance pixels, with its
//! plane's nearest and farthest depth over the box. For an opaque triangle it also says which of
//! its edges cross the box, and which of those are *closable*: the triangle across the edge
//! (same two corners, welded by position and node, [`Adjacency`]) lies on the other side of it.
//!
//! The host then bounds, per sample, how far the nearest opaque surface can be anywhere in the
//! box ([`far_bound`]). Opaque triangles join a set in order of their farthest depth; the set
//! covers the whole box once some connected part of it has no open edge in the box: every edge
//! of its triangles that crosses the box is shared with a triangle of the part on the other
//! side. (The number of the part's triangles covering a point changes only across the edges of
//! its triangles; across a closed edge one triangle ends where the other begins. So it is the
//! same everywhere in the box, and at least one there.) The bound is the farthest depth of the
//! last triangle added; where no part closes (the box reaches past a silhouette, a border or a
//! crack), it is 1: nothing is known to occlude. Every triangle of the sample's list whose
//! nearest depth over the box is not behind the bound may be nearest somewhere in the box, and
//! joins V_f.
//!
//! Depths are compared over a larger box than coverage: the sample's pixel grown by the
//! tolerance (a rasterizer may take a sample's depth anywhere in its pixel), for the plane
//! through the corners snapped to 4 to 8 sub-pixel bits (bounded through the snapped
//! triangle's barycentric weights: a sliver's may lie anywhere). A triangle whose facing a
//! 1/32 px snap of its corners could turn is kept either facing and never occludes; one with no
//! area in f32 is kept wherever its grown bounds reach. That is what another rasterizer may do
//! besides moving the samples; all of it was found on SwiftShader, whose holes it cut from 26.5
//! a frame to 0 on CarConcept (see `capture_grown.wgsl`).
//!
//! Rigorous up to rounding for sample patterns moved within the tolerance (depths compare with
//! 1e-6 to spare, the box is tested 1/64 larger for edges): a triangle nearest at some point of
//! a sample's box is kept, however thin the gap it shows through. It keeps more than it must where one bound stands for the whole box (near
//! a silhouette everything behind it in the box is kept), and treats as open what it cannot
//! weld: T-junctions (where triangles were split along intersections), non-manifold edges,
//! mask and blend materials, glass. A triangle reaching behind the camera is taken ungrown at
//! its interpolated depth, never occludes, and is kept where the recorded pattern sees it.

use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering::Relaxed};

use trisort_format::{FrameState, Geometry, Robust};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Gpu;

use crate::capture::{Capture, Fragment, Grow};
use crate::RecordError;

/// Bits of a captured id that hold the id; the flags sit above (the shader's own constant).
const ID_BITS: u32 = trisort_gpu::ENVELOPE_ID_BITS;
const ID_MASK: u32 = (1 << ID_BITS) - 1;
/// Flag: the triangle occludes (opaque material, plane valid).
const OCCLUDES: u32 = 1;
/// No vertex or neighbour.
const NONE: u32 = u32::MAX;

/// Edge neighbours of a list of triangles: for edge k (corner k to corner k + 1) of each, the
/// one other triangle of the list with the same two corners (equal positions and node), if
/// exactly one has them.
pub(crate) struct Adjacency {
    /// Per triangle: the opposite vertex (an index into the geometry's vertices) of the
    /// neighbour across each edge, or `u32::MAX`; the fourth word is padding.
    pub opposite: Vec<[u32; 4]>,
    /// Per triangle: the neighbour's position in the list across each edge, or `u32::MAX`.
    pub neighbour: Vec<[u32; 3]>,
}

impl Adjacency {
    /// The adjacency of `triangles` (indices into `geometry.triangles`).
    pub fn new(geometry: &Geometry, triangles: &[u32]) -> Adjacency {
        // Corners welded by position bits and node.
        let mut welded: HashMap<([u32; 3], u32), u32> = HashMap::new();
        let mut weld = |v: u32| {
            let vertex = &geometry.vertices[v as usize];
            let key = (vertex.position.map(f32::to_bits), vertex.node);
            let next = welded.len() as u32;
            *welded.entry(key).or_insert(next)
        };
        let corners: Vec<[u32; 3]> = triangles
            .iter()
            .map(|&t| geometry.triangles[t as usize].map(&mut weld))
            .collect();
        // Each welded edge: the (triangle, edge) pairs on it, up to a third (then non-manifold).
        let mut edges: HashMap<(u32, u32), Vec<(u32, u8)>> = HashMap::new();
        for (i, c) in corners.iter().enumerate() {
            if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                let on = edges.entry((a.min(b), a.max(b))).or_default();
                if on.len() < 3 {
                    on.push((i as u32, k as u8));
                }
            }
        }
        let mut opposite = vec![[NONE; 4]; triangles.len()];
        let mut neighbour = vec![[NONE; 3]; triangles.len()];
        for on in edges.values() {
            if let [(a, ka), (b, kb)] = on[..] {
                let vertex =
                    |t: u32, k: u8| geometry.triangles[triangles[t as usize] as usize][k as usize];
                opposite[a as usize][ka as usize] = vertex(b, (kb + 2) % 3);
                opposite[b as usize][kb as usize] = vertex(a, (ka + 2) % 3);
                neighbour[a as usize][ka as usize] = b;
                neighbour[b as usize][kb as usize] = a;
            }
        }
        Adjacency {
            opposite,
            neighbour,
        }
    }
}

/// Reused per run of samples by [`far_bound`].
#[derive(Default)]
pub(crate) struct Scratch {
    /// The sample's occluders: farthest depth, position in the drawn list, flags.
    occluders: Vec<(f32, u32, u32)>,
    parent: Vec<usize>,
    open: Vec<i64>,
}

fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

fn join(parent: &mut [usize], open: &mut [i64], a: usize, b: usize) {
    let (ra, rb) = (root(parent, a), root(parent, b));
    if ra != rb {
        parent[rb] = ra;
        open[ra] += open[rb];
    }
}

/// A depth that the nearest opaque surface is not behind anywhere in the sample's box, from
/// the sample's envelope fragments (any order): the farthest depth of the occluder whose
/// joining first gave a part of the occluders with no open edge in the box, else 1 (see the
/// module documentation). `neighbour` is [`Adjacency::neighbour`] of the drawn list.
pub(crate) fn far_bound(list: &[Fragment], neighbour: &[[u32; 3]], s: &mut Scratch) -> f32 {
    s.occluders.clear();
    for f in list {
        let flags = f.id >> ID_BITS;
        if flags & OCCLUDES != 0 {
            s.occluders.push((f.alpha, (f.id & ID_MASK) - 1, flags));
        }
    }
    s.occluders
        .sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    s.parent.clear();
    s.open.clear();
    let crossing = |flags: u32, k: usize| flags & (2 << k) != 0;
    let closable = |flags: u32, k: usize| flags & (16 << k) != 0;
    for i in 0..s.occluders.len() {
        let (far, t, flags) = s.occluders[i];
        s.parent.push(i);
        s.open.push(0);
        // This triangle's edges in the box: closed by a neighbour already in, else open.
        for (k, &n) in neighbour[t as usize].iter().enumerate() {
            if !crossing(flags, k) {
                continue;
            }
            let member = (closable(flags, k) && n != NONE)
                .then(|| s.occluders[..i].iter().position(|o| o.1 == n))
                .flatten();
            match member {
                Some(j) => join(&mut s.parent, &mut s.open, i, j),
                None => s.open[i] += 1,
            }
        }
        // Edges of those already in that this triangle closes.
        for j in 0..i {
            let (_, m, mflags) = s.occluders[j];
            for (k, &n) in neighbour[m as usize].iter().enumerate() {
                if crossing(mflags, k) && closable(mflags, k) && n == t {
                    let r = root(&mut s.parent, j);
                    s.open[r] -= 1;
                    join(&mut s.parent, &mut s.open, i, j);
                }
            }
        }
        let r = root(&mut s.parent, i);
        if s.open[r] == 0 {
            return far;
        }
    }
    1.0
}

/// Phase 1 of `record --conservative` by the envelope bound, for one scene at one view.
pub(crate) struct Envelope<'g> {
    capture: RefCell<Capture<'g>>,
    neighbour: Vec<[u32; 3]>,
}

impl<'g> Envelope<'g> {
    /// The envelope capture of every triangle of `geometry` for the path's `frames` at `view`
    /// within `robust`'s tolerance and raster profile. Errors where the device cannot capture, or the
    /// scene has 2^24 triangles or more (the flags share the captured id's word).
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
        robust: &Robust,
        internals: &crate::Internals,
    ) -> Result<Envelope<'g>, RecordError> {
        if !Envelope::fits(geometry) {
            return Err(RecordError::Unsupported(format!(
                "--conservative records at most {} triangles; the scene has {}",
                ID_MASK - 1,
                geometry.triangles.len()
            )));
        }
        let all: Vec<u32> = (0..geometry.triangles.len() as u32).collect();
        let adjacency = Adjacency::new(geometry, &all);
        let grow = Grow::Envelope(robust, &adjacency.opposite);
        let capture = Capture::grown(gpu, geometry, &all, frames, view, grow, internals)?;
        Ok(Envelope {
            capture: RefCell::new(capture),
            neighbour: adjacency.neighbour,
        })
    }

    /// Whether `geometry` has few enough triangles for the envelope capture (below 2^24 − 1:
    /// the flags share the captured id's word).
    pub fn fits(geometry: &Geometry) -> bool {
        (geometry.triangles.len() as u64) < ID_MASK as u64
    }

    /// The triangles (indices into the geometry) that may be nearest at some point of a
    /// sample's tolerance box in frame `frame`, ascending.
    pub fn visible(&self, frame: u32) -> Result<Vec<u32>, RecordError> {
        let mut capture = self.capture.borrow_mut();
        let neighbour = &self.neighbour;
        let kept: Vec<AtomicBool> = (0..capture.triangles())
            .map(|_| AtomicBool::new(false))
            .collect();
        capture.frame(frame, |band| {
            band.walk(Scratch::default, |scratch, _, list| {
                let bound = far_bound(list, neighbour, scratch);
                for f in list {
                    // A little slack for rounding, as the conservative passes allow.
                    if f.depth <= bound + 1e-6 {
                        kept[((f.id & ID_MASK) - 1) as usize].store(true, Relaxed);
                    }
                }
            });
            Ok(())
        })?;
        Ok(kept
            .iter()
            .enumerate()
            .filter(|(_, k)| k.load(Relaxed))
            .map(|(t, _)| t as u32)
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fragment(t: u32, far: f32, flags: u32) -> Fragment {
        Fragment {
            depth: far - 0.1,
            id: (t + 1) | (flags << ID_BITS),
            alpha: far,
        }
    }

    /// Crossing bits for edges `ks`, closable too where `close`.
    fn flags(ks: &[usize], close: bool) -> u32 {
        let mut f = OCCLUDES;
        for &k in ks {
            f |= 2 << k;
            if close {
                f |= 16 << k;
            }
        }
        f
    }

    #[test]
    fn a_triangle_over_the_whole_box_bounds_it_alone() {
        let neighbour = vec![[NONE; 3]];
        let mut s = Scratch::default();
        let list = [fragment(0, 0.4, flags(&[], false))];
        assert_eq!(far_bound(&list, &neighbour, &mut s), 0.4);
    }

    #[test]
    fn two_neighbours_close_the_box_only_together() {
        // Triangles 0 and 1 share their edge 0 (0's) and 2 (1's), both crossing the box.
        let neighbour = vec![[1, NONE, NONE], [NONE, NONE, 0]];
        let mut s = Scratch::default();
        let list = [
            fragment(0, 0.3, flags(&[0], true)),
            fragment(1, 0.5, flags(&[2], true)),
        ];
        assert_eq!(far_bound(&list, &neighbour, &mut s), 0.5);
        // Alone, each leaves its edge open: nothing bounds the box.
        assert_eq!(far_bound(&list[..1], &neighbour, &mut s), 1.0);
        // A fold (not closable) never closes, whatever lies across.
        let folded = [
            fragment(0, 0.3, flags(&[0], false)),
            fragment(1, 0.5, flags(&[2], false)),
        ];
        assert_eq!(far_bound(&folded, &neighbour, &mut s), 1.0);
    }

    #[test]
    fn a_closed_surface_behind_a_border_bounds_the_box() {
        // Triangle 0 ends in the box (a border: no neighbour); 1 and 2 close behind it.
        let neighbour = vec![[NONE; 3], [2, NONE, NONE], [NONE, 1, NONE]];
        let mut s = Scratch::default();
        let list = [
            fragment(0, 0.2, flags(&[1], false)),
            fragment(2, 0.8, flags(&[1], true)),
            fragment(1, 0.7, flags(&[0], true)),
        ];
        assert_eq!(far_bound(&list, &neighbour, &mut s), 0.8);
    }

    #[test]
    fn only_occluders_take_part() {
        let neighbour = vec![[NONE; 3]; 2];
        let mut s = Scratch::default();
        // Triangle 0 covers the box but does not occlude (glass, mask, blend).
        let list = [fragment(0, 0.1, 0), fragment(1, 0.6, flags(&[], false))];
        assert_eq!(far_bound(&list, &neighbour, &mut s), 0.6);
    }

    #[test]
    fn adjacency_welds_corners_by_position_and_node() {
        use trisort_format::Vertex;
        let v = |x: f32, y: f32, node: u32| Vertex {
            position: [x, y, 0.0],
            node,
            ..bytemuck::Zeroable::zeroed()
        };
        // Two triangles on a square's diagonal with their own vertices; a third on another
        // node at the same positions.
        let geometry = Geometry {
            vertices: vec![
                v(0.0, 0.0, 0),
                v(1.0, 0.0, 0),
                v(1.0, 1.0, 0),
                v(0.0, 0.0, 0),
                v(1.0, 1.0, 0),
                v(0.0, 1.0, 0),
                v(0.0, 0.0, 1),
                v(1.0, 1.0, 1),
                v(0.0, 1.0, 1),
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]],
            ..Default::default()
        };
        let a = Adjacency::new(&geometry, &[0, 1, 2]);
        // Triangle 0's edge 2 (corner 2 to 0) is triangle 1's edge 0 (corner 0 to 1).
        assert_eq!(a.neighbour[0], [NONE, NONE, 1]);
        assert_eq!(a.neighbour[1], [0, NONE, NONE]);
        assert_eq!(a.opposite[0][2], 5);
        assert_eq!(a.opposite[1][0], 1);
        assert_eq!(a.neighbour[2], [NONE; 3]);
    }
}
