//! Finding the crossing pairs of a scene: triangles in their group's common space, each
//! group's BVH, the narrow phase on every overlapping pair of boxes.

use glam::{DMat4, DVec3};
use rayon::prelude::*;
use robust::{orient2d, Coord};
use trisort_format::{FrameState, Geometry};

use crate::bvh::{Aabb, Bvh};
use crate::groups::CommonSpace;
use crate::narrow::{contact, Contact, Tri};

/// The scene prepared for the tests: every triangle in its group's common space.
pub(crate) struct Prepared {
    /// Per triangle: its corners in the common space, `None` for zero-area triangles.
    pub tris: Vec<Option<Tri>>,
    /// Per triangle: its node.
    pub node: Vec<u32>,
    /// Per node: its rigid group.
    pub groups: Vec<u32>,
    /// Number of rigid groups.
    pub group_count: usize,
    /// Across groups ([`Prepared::across_groups`]): per node, its rigid group; only triangles
    /// of different ones are paired.
    pub rigid: Option<Vec<u32>>,
}

/// What the detector found.
pub(crate) struct Found {
    /// Crossing pairs `[a, b]`, `a < b`, ascending.
    pub pairs: Vec<[u32; 2]>,
    /// Pairs crossing by no more than their precision.
    pub below_precision: u64,
    /// Pairs of one group whose boxes overlap.
    pub candidates: u64,
}

impl Prepared {
    /// Prepares `geometry` for the rigid groups of `frames`.
    pub fn new(geometry: &Geometry, frames: &[FrameState]) -> Prepared {
        Prepared::in_space(geometry, CommonSpace::new(geometry, frames), None)
    }

    /// Prepares `geometry` for pairing triangles of *different* rigid groups of `frames`, all
    /// compared in world space as the first frame places them.
    pub fn across_groups(geometry: &Geometry, frames: &[FrameState]) -> Prepared {
        let (space, rigid) = CommonSpace::first_frame(geometry, frames);
        Prepared::in_space(geometry, space, Some(rigid))
    }

    fn in_space(geometry: &Geometry, space: CommonSpace, rigid: Option<Vec<u32>>) -> Prepared {
        let common: Vec<DVec3> = geometry
            .vertices
            .par_iter()
            .map(|v| space.to_common[v.node as usize].transform_point3(local(v.position)))
            .collect();
        let delta = node_delta(geometry, &space.to_common, &common);
        let node: Vec<u32> = geometry
            .triangles
            .iter()
            .map(|t| geometry.vertices[t[0] as usize].node)
            .collect();
        let tris = geometry
            .triangles
            .par_iter()
            .map(|t| {
                let corners = t.map(|v| geometry.vertices[v as usize].position);
                if collinear(&corners) {
                    return None;
                }
                let node = geometry.vertices[t[0] as usize].node as usize;
                let tri = Tri::new(t.map(|v| common[v as usize]), delta[node]);
                (tri.normal_len > 0.0 && tri.normal_len.is_finite()).then_some(tri)
            })
            .collect();
        Prepared {
            tris,
            node,
            groups: space.groups,
            group_count: space.group_count,
            rigid,
        }
    }

    /// The triangles of each group (non-degenerate only), ascending.
    fn members(&self) -> Vec<Vec<u32>> {
        let mut members = vec![Vec::new(); self.group_count];
        for (t, tri) in self.tris.iter().enumerate() {
            if tri.is_some() {
                members[self.groups[self.node[t] as usize] as usize].push(t as u32);
            }
        }
        members
    }

    /// Every crossing pair within a rigid group; with `query`, only the pairs with at least one
    /// triangle `t` where `query[t]`. Deterministic: the per-triangle results are collected in
    /// triangle order whatever the number of threads.
    pub fn find(&self, query: Option<&[bool]>) -> Found {
        let mut found = Found {
            pairs: Vec::new(),
            below_precision: 0,
            candidates: 0,
        };
        for members in self.members() {
            let boxes: Vec<Aabb> = members
                .iter()
                .map(|&t| Aabb::around(&self.tri(t).p))
                .collect();
            let bvh = Bvh::build(&boxes);
            let asked = |t: u32| query.is_none_or(|q| q[t as usize]);
            let per_triangle: Vec<(Vec<u32>, u64, u64)> = (0..members.len())
                .into_par_iter()
                .map(|i| match asked(members[i]) {
                    true => self.partners(&members, &boxes, &bvh, i, &asked),
                    false => (Vec::new(), 0, 0),
                })
                .collect();
            for (i, (partners, candidates, below)) in per_triangle.into_iter().enumerate() {
                found.candidates += candidates;
                found.below_precision += below;
                let a = members[i];
                found
                    .pairs
                    .extend(partners.into_iter().map(|b| [a.min(b), a.max(b)]));
            }
        }
        found.pairs.sort_unstable();
        found
    }

    /// Triangle `t`, which must have an area.
    pub fn tri(&self, t: u32) -> &Tri {
        self.tris[t as usize]
            .as_ref()
            .expect("only non-degenerate triangles are grouped")
    }

    /// The crossing partners of `members[i]` (ascending) that the pair is reported from: the
    /// later one if both are `asked`, else the asked one; the number of those whose boxes
    /// overlap its box, and of those crossing below precision.
    fn partners(
        &self,
        members: &[u32],
        boxes: &[Aabb],
        bvh: &Bvh,
        i: usize,
        asked: &(impl Fn(u32) -> bool + Sync),
    ) -> (Vec<u32>, u64, u64) {
        let a = members[i];
        let tri_a = self.tri(a);
        let mut partners = Vec::new();
        let (mut candidates, mut below) = (0, 0);
        bvh.for_each_overlap(boxes, &boxes[i], |j| {
            let b = members[j as usize];
            if b == a || (b < a && asked(b)) {
                return;
            }
            if let Some(rigid) = &self.rigid {
                let group = |t: u32| rigid[self.node[t as usize] as usize];
                if group(a) == group(b) {
                    return;
                }
            }
            candidates += 1;
            match contact(tri_a, self.tri(b)) {
                Contact::Apart => {}
                Contact::BelowPrecision => below += 1,
                Contact::Crossing => partners.push(b),
            }
        });
        partners.sort_unstable();
        (partners, candidates, below)
    }
}

fn local(p: [f32; 3]) -> DVec3 {
    DVec3::from(p.map(f64::from))
}

/// Whether three stored points are collinear (or coincide), decided exactly.
fn collinear(p: &[[f32; 3]; 3]) -> bool {
    let projections = [(0, 1), (1, 2), (2, 0)];
    projections.iter().all(|&(x, y)| {
        let c = |q: &[f32; 3]| Coord {
            x: f64::from(q[x]),
            y: f64::from(q[y]),
        };
        orient2d(c(&p[0]), c(&p[1]), c(&p[2])) == 0.0
    })
}

/// Per node, how far rounding a point to f32 in its local space can move it in its group's
/// common space: `√3 · 2⁻²⁴ · max |local coordinate| · ‖linear part of node → common‖_F`,
/// plus the f64 rounding of the transform (`2⁻⁵⁰ · max |common coordinate|`).
fn node_delta(geometry: &Geometry, to_common: &[DMat4], common: &[DVec3]) -> Vec<f64> {
    let mut max_local = vec![0.0f64; geometry.nodes.len()];
    let mut max_common = vec![0.0f64; geometry.nodes.len()];
    for (v, c) in geometry.vertices.iter().zip(common) {
        let n = v.node as usize;
        max_local[n] = v
            .position
            .iter()
            .fold(max_local[n], |m, x| m.max(x.abs() as f64));
        max_common[n] = max_common[n].max(c.abs().max_element());
    }
    (0..geometry.nodes.len())
        .map(|n| {
            let m = to_common[n];
            let linear = (m.x_axis.truncate().length_squared()
                + m.y_axis.truncate().length_squared()
                + m.z_axis.truncate().length_squared())
            .sqrt();
            3f64.sqrt() * 2f64.powi(-24) * max_local[n] * linear + 2f64.powi(-50) * max_common[n]
        })
        .collect()
}
