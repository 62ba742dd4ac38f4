//! One partition's depth-presorted list (paper 000, § 4.1): a preliminary back-to-front order,
//! then every back edge removed by moving a copy or duplicating it with a cutting plane.
//!
//! The list is in drawing order, back to front. Copy `x` *occludes* copy `y` when some
//! viewpoint of the partition where both are drawn sees `x` in front of `y` along a ray (their
//! reduced occlusion region Ō(x→y) = O(x→y) ∩ E_x ∩ E_y ∩ P has volume); then `y` must come
//! first. A *back edge* is `x` before a copy it occludes. The scan keeps every copy before
//! position `p` free of back edges; at `p`, copy `x` with back edges to the copies `b*` (the
//! last one at `q`):
//! - if no copy between `x` and `q` occludes `x` (no `f*`), `x` moves to just after `q`;
//! - else a plane is sought that has the back edges' regions (∪ Ō(x→b)) on one side and as
//!   many of the `f*`'s regions (∪ Ō(f→x), greedily, in list order) as possible on the other,
//!   by linear programming. `x` stays where it is, restricted to the `f*` side, and a copy
//!   restricted to the `b*` side goes after `q`. Back edges from the `f*` not separated now
//!   point at that copy; they are handled when the scan reaches them.
//! - if no `f` can be separated at all, `x` moves after `q` anyway and the `f*` inherit the
//!   back edges (paper 000's fall-back; the scan's step bound catches a cycle that no order
//!   resolves).
//!
//! A copy's rendering region E is the partition, its instance's front side and its tests; a
//! copy whose region has no volume is dropped (no viewpoint draws it).

use std::collections::HashMap;
use std::rc::Rc;

use glam::DVec3;

use crate::geom::{occlusion, region, Plane, Tri, INTERIOR};
use crate::lp::separate;
use crate::partition::Partition;

/// An instance of a triangle: the front, or the back of a double-sided one.
#[derive(Clone, Copy, Debug)]
pub struct Instance {
    /// The oriented triangle (normalised space).
    pub tri: Tri,
    /// Test of the instance itself (the triangle's plane, flipped for the back), where the
    /// material is double-sided: one instance per side is drawn.
    pub own: Option<Test>,
}

/// A half-space test: a plane of the partition's list and a side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Test {
    /// Index into the presort's planes.
    pub plane: u32,
    /// Negative side (`< 0`) instead of positive (`≥ 0`).
    pub flipped: bool,
}

/// A copy in a list.
#[derive(Clone, Debug)]
pub struct ListCopy {
    /// Unique id (for the region cache).
    uid: u32,
    /// The instance.
    pub instance: u32,
    /// Cutting-plane tests added by duplication.
    pub cuts: Vec<Test>,
    /// The planes of E (partition, front side, cuts).
    region: Vec<Plane>,
}

/// Figures of one partition's list.
#[derive(Clone, Copy, Debug, Default)]
pub struct ListStats {
    /// Copies made by duplication.
    pub duplicated: u64,
    /// Copies moved.
    pub moved: u64,
    /// Moves with no separable `f` (the fall-back).
    pub fallback_moves: u64,
    /// Occlusion regions computed.
    pub regions: u64,
    /// Linear programs solved.
    pub linear_programs: u64,
}

/// Why a list could not be built.
#[derive(Debug, Clone)]
pub struct NoOrder {
    /// Scene ids of the copy being placed and of one it occludes.
    pub triangles: (u32, u32),
    /// Steps taken.
    pub steps: u64,
}

/// The shared plane list: planes registered by index.
pub trait Planes {
    /// Registers a plane, returns its index.
    fn add(&mut self, plane: Plane) -> u32;
    /// The plane at `index`.
    fn get(&self, index: u32) -> Plane;
}

impl Planes for Vec<Plane> {
    fn add(&mut self, plane: Plane) -> u32 {
        self.push(plane);
        (self.len() - 1) as u32
    }
    fn get(&self, index: u32) -> Plane {
        self[index as usize]
    }
}

fn oriented(planes: &impl Planes, t: Test) -> Plane {
    let p = planes.get(t.plane);
    if t.flipped {
        p.flip()
    } else {
        p
    }
}

struct Builder<'a, P: Planes> {
    instances: &'a [Instance],
    partition: &'a Partition,
    planes: &'a mut P,
    /// Ō(x→y) by copy uids: its vertices when it has volume.
    cache: HashMap<(u32, u32), Option<Rc<[DVec3]>>>,
    /// Per instance: its extent along the partition's face normal (least, most).
    spans: Vec<(f64, f64)>,
    next_uid: u32,
    stats: ListStats,
}

impl<P: Planes> Builder<'_, P> {
    fn copy(&mut self, instance: u32, cuts: Vec<Test>) -> Option<ListCopy> {
        let inst = &self.instances[instance as usize];
        let mut region_planes = self.partition.planes.clone();
        region_planes.extend(inst.tri.plane);
        for t in &cuts {
            region_planes.push(oriented(self.planes, *t));
        }
        // Drawn from somewhere in the partition?
        region(&region_planes)?;
        self.next_uid += 1;
        Some(ListCopy {
            uid: self.next_uid,
            instance,
            cuts,
            region: region_planes,
        })
    }

    /// Ō(x→y)'s vertices when `x` occludes `y` somewhere both are drawn.
    fn occludes(&mut self, x: &ListCopy, y: &ListCopy) -> Option<Rc<[DVec3]>> {
        if let Some(v) = self.cache.get(&(x.uid, y.uid)) {
            return v.clone();
        }
        // Along the face's normal n, x must reach beyond y: a camera v = q + t(p − q), t ≥ 1,
        // p ∈ x, q ∈ y, has n·v ≤ n·p when n·(p − q) ≤ 0, and n·p is inside the face.
        let (sx, sy) = (
            self.spans[x.instance as usize],
            self.spans[y.instance as usize],
        );
        if sx.1 <= sy.0 {
            return None;
        }
        let (tx, ty) = (
            &self.instances[x.instance as usize].tri,
            &self.instances[y.instance as usize].tri,
        );
        // Cheap rejections first, not cached (they cost less than a lookup's memory): the
        // triangles' sides of each other's planes, then a plane of O(x→y) with the whole
        // partition outside it.
        let o = occlusion(tx, ty)?;
        let outside = |p: &Plane| {
            self.partition
                .vertices
                .iter()
                .all(|v| p.eval(*v) < -INTERIOR)
        };
        if o.iter().any(outside) {
            return None;
        }
        self.stats.regions += 1;
        let mut planes = x.region.clone();
        planes.extend(o);
        // y's region beyond what x's already has: its front side and its cuts.
        planes.extend_from_slice(&y.region[self.partition.planes.len()..]);
        let v: Option<Rc<[DVec3]>> = region(&planes).map(Rc::from);
        self.cache.insert((x.uid, y.uid), v.clone());
        v
    }
}

/// The list of `partition` over `instances` (those drawn from it), new cutting planes added to
/// `planes`. `max_steps` bounds the scan; `advanced` is called each time the scan moves on
/// past a copy (for progress).
pub fn build_list<P: Planes>(
    instances: &[Instance],
    partition: &Partition,
    planes: &mut P,
    max_steps: u64,
    advanced: &mut dyn FnMut(),
) -> Result<(Vec<ListCopy>, ListStats), NoOrder> {
    let mut b = Builder {
        instances,
        partition,
        planes,
        cache: HashMap::new(),
        spans: instances
            .iter()
            .map(|i| {
                i.tri
                    .v
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                        let d = partition.normal.dot(*v);
                        (lo.min(d), hi.max(d))
                    })
            })
            .collect(),
        next_uid: 0,
        stats: ListStats::default(),
    };
    // Preliminary order: back to front from the partition's viewpoint (centroid distance,
    // farthest first), of the instances drawn from somewhere in the partition.
    let eye = partition.viewpoint;
    let mut order: Vec<(f64, u32)> = (0..instances.len() as u32)
        .map(|k| (instances[k as usize].tri.centroid().distance(eye), k))
        .collect();
    order.sort_by(|a, c| c.0.total_cmp(&a.0).then(a.1.cmp(&c.1)));
    let mut list: Vec<ListCopy> = order
        .into_iter()
        .filter_map(|(_, k)| b.copy(k, Vec::new()))
        .collect();
    let mut p = 0usize;
    let mut steps = 0u64;
    while p < list.len() {
        steps += 1;
        let x = list[p].clone();
        let mut backs: Vec<(usize, Rc<[DVec3]>)> = Vec::new();
        for (q, y) in list.iter().enumerate().skip(p + 1) {
            if let Some(v) = b.occludes(&x, y) {
                backs.push((q, v));
            }
        }
        let Some(&(last, _)) = backs.last() else {
            p += 1;
            advanced();
            continue;
        };
        if steps > max_steps {
            let y = &list[last];
            return Err(NoOrder {
                triangles: (
                    instances[x.instance as usize].tri.id,
                    instances[y.instance as usize].tri.id,
                ),
                steps,
            });
        }
        let mut fronts: Vec<Rc<[DVec3]>> = Vec::new();
        for f in &list[p + 1..=last] {
            if let Some(v) = b.occludes(f, &x) {
                fronts.push(v);
            }
        }
        let mut cut: Option<Plane> = None;
        if !fronts.is_empty() {
            let rb: Vec<DVec3> = backs.iter().flat_map(|(_, v)| v.iter().copied()).collect();
            let mut rf: Vec<DVec3> = Vec::new();
            for v in &fronts {
                let mut candidate = rf.clone();
                candidate.extend_from_slice(v);
                b.stats.linear_programs += 1;
                if let Some(plane) = separate(&rb, &candidate) {
                    rf = candidate;
                    cut = Some(plane);
                }
            }
        }
        match cut {
            None => {
                // Nothing in the way (or nothing separable): move x after its last back edge.
                if fronts.is_empty() {
                    b.stats.moved += 1;
                } else {
                    b.stats.fallback_moves += 1;
                }
                let c = list.remove(p);
                list.insert(last, c);
            }
            Some(plane) => {
                b.stats.duplicated += 1;
                let index = b.planes.add(plane);
                let mut stay_cuts = x.cuts.clone();
                stay_cuts.push(Test {
                    plane: index,
                    flipped: false,
                });
                let mut go_cuts = x.cuts.clone();
                go_cuts.push(Test {
                    plane: index,
                    flipped: true,
                });
                let go = b.copy(x.instance, go_cuts);
                if let Some(go) = go {
                    list.insert(last + 1, go);
                }
                match b.copy(x.instance, stay_cuts) {
                    Some(stay) => list[p] = stay,
                    None => {
                        list.remove(p);
                    }
                }
            }
        }
    }
    Ok((list, b.stats))
}
