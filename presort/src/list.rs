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
//!   point at that copy; they are handled when the scan reaches them. A plane clear of the
//!   regions by a margin is sought first, then one that may touch them (regions that share a
//!   face and do not overlap, as around nearly coplanar neighbours; see [`TOUCH`]).
//! - if no `f` can be separated at all, `x` moves after `q` anyway and the `f*` inherit the
//!   back edges (paper 000's fall-back).
//!
//! The fall-back can go round a cycle of copies for ever: paper 000 proves that a cycle has
//! a separable pair of edges unless one viewpoint sees the whole cycle, but its separations
//! are of single edges where the scan's are of x's back edges all together, and nearly
//! coplanar slivers of a curved pane make cycles whose regions overlap only by tolerances. A
//! copy that comes back to the scan's position after [`CYCLE_VISITS`] fall-back moves is left
//! where it is, its back edges kept: an *unresolved cycle*, reported
//! ([`ListStats::cycles`]) so that the caller can refuse the list or state the exception.
//!
//! A copy's rendering region E is the partition, its instance's front side and its tests; a
//! copy whose region has no volume is dropped (no viewpoint draws it).

use std::collections::HashMap;
use std::rc::Rc;

use glam::DVec3;

use crate::geom::{occlusion, region, Plane, Tri, INTERIOR};
use crate::lp::{separate, MARGIN, TOUCH};
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
#[derive(Clone, Debug, Default)]
pub struct ListStats {
    /// Copies made by duplication.
    pub duplicated: u64,
    /// Copies moved.
    pub moved: u64,
    /// Moves with no separable `f` (the fall-back).
    pub fallback_moves: u64,
    /// Unresolved cycles: per copy left with back edges, its triangle's scene id and that of
    /// the last copy it still occludes before it in the list.
    pub cycles: Vec<(u32, u32)>,
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
    /// Per instance: the instances that may occlude it ([`Builder::broad_phase`]).
    occluders: Vec<Vec<u32>>,
    /// Per instance: the instances it may occlude.
    occludees: Vec<Vec<u32>>,
    /// Per instance: the stamp of the last [`Builder::mark`] that marked it.
    marks: Vec<u32>,
    stamp: u32,
    next_uid: u32,
    stats: ListStats,
}

impl<'a, P: Planes> Builder<'a, P> {
    fn new(instances: &'a [Instance], partition: &'a Partition, planes: &'a mut P) -> Self {
        Builder {
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
            occluders: Vec::new(),
            occludees: Vec::new(),
            marks: vec![0; instances.len()],
            stamp: 0,
            next_uid: 0,
            stats: ListStats::default(),
        }
    }

    /// Duplicates the copy at `p` with `plane`: it stays, restricted to the plane's positive
    /// side, and a copy restricted to the negative side goes after `last` (either dropped
    /// where its region has no volume).
    fn duplicate(&mut self, list: &mut Vec<ListCopy>, p: usize, last: usize, plane: Plane) {
        self.stats.duplicated += 1;
        let index = self.planes.add(plane);
        let x = &list[p];
        let (instance, mut stay_cuts) = (x.instance, x.cuts.clone());
        let mut go_cuts = stay_cuts.clone();
        stay_cuts.push(Test {
            plane: index,
            flipped: false,
        });
        go_cuts.push(Test {
            plane: index,
            flipped: true,
        });
        if let Some(go) = self.copy(instance, go_cuts) {
            list.insert(last + 1, go);
        }
        match self.copy(instance, stay_cuts) {
            Some(stay) => list[p] = stay,
            None => {
                list.remove(p);
            }
        }
    }

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

    /// Ō(x→y)'s vertices when `x` occludes `y` somewhere both are drawn. The callers ask only
    /// for the pairs the broad phase let through (a copy's region is within its instance's,
    /// so instances that cannot occlude each other cannot as copies either).
    fn occludes(&mut self, x: &ListCopy, y: &ListCopy) -> Option<Rc<[DVec3]>> {
        if let Some(v) = self.cache.get(&(x.uid, y.uid)) {
            return v.clone();
        }
        let v = self.region_of(x, y);
        self.cache.insert((x.uid, y.uid), v.clone());
        v
    }

    /// Marks, with a new stamp, the instances that instance `x` may occlude (`behind`) or
    /// that may occlude it (else), as the broad phase found them.
    fn mark(&mut self, x: u32, behind: bool) -> u32 {
        self.stamp += 1;
        let related = if behind {
            &self.occludees[x as usize]
        } else {
            &self.occluders[x as usize]
        };
        for &y in related {
            self.marks[y as usize] = self.stamp;
        }
        self.stamp
    }

    /// Ō(x→y)'s vertices, computed.
    fn region_of(&mut self, x: &ListCopy, y: &ListCopy) -> Option<Rc<[DVec3]>> {
        let o = self.cheap(x.instance, y.instance)?;
        self.stats.regions += 1;
        // Planes with the whole partition on their positive side bound nothing within it:
        // left out, the vertex enumeration (cubic in the planes) has less to do.
        let cuts = |p: &Plane| {
            !self
                .partition
                .vertices
                .iter()
                .all(|v| p.eval(*v) > INTERIOR)
        };
        let k = self.partition.planes.len();
        let mut planes = self.partition.planes.clone();
        planes.extend(x.region[k..].iter().copied().filter(cuts));
        planes.extend(o.into_iter().filter(cuts));
        // y's region beyond what x's already has: its front side and its cuts.
        planes.extend(y.region[k..].iter().copied().filter(cuts));
        region(&planes).map(Rc::from)
    }

    /// The planes of O(i→j) for instances `i` and `j`, unless a cheap test shows that `i`
    /// occludes `j` from nowhere in the partition.
    fn cheap(&self, i: u32, j: u32) -> Option<Vec<Plane>> {
        // Along the face's normal n, x must reach beyond y: a camera v = q + t(p − q), t ≥ 1,
        // p ∈ x, q ∈ y, has n·v ≤ n·p when n·(p − q) ≤ 0, and n·p is inside the face.
        let (si, sj) = (self.spans[i as usize], self.spans[j as usize]);
        if si.1 <= sj.0 {
            return None;
        }
        let (ti, tj) = (
            &self.instances[i as usize].tri,
            &self.instances[j as usize].tri,
        );
        // The triangles' sides of each other's planes, then a plane of O(i→j) with the whole
        // partition outside it.
        let o = occlusion(ti, tj)?;
        let outside = |p: &Plane| {
            self.partition
                .vertices
                .iter()
                .all(|v| p.eval(*v) < -INTERIOR)
        };
        if o.iter().any(outside) {
            return None;
        }
        Some(o)
    }

    /// The broad phase, over the drawn instances: per instance, the instances that pass the
    /// cheap tests of occluding it ([`Builder::cheap`]). The scan rescans the
    /// copies after a moved one many times; with this it skips the pairs that cannot matter
    /// without testing them again.
    fn broad_phase(&mut self, list: &[ListCopy]) {
        let n = self.instances.len();
        let (mut occluders, mut occludees) = (vec![Vec::new(); n], vec![Vec::new(); n]);
        for x in list {
            for y in list {
                if x.instance != y.instance && self.cheap(x.instance, y.instance).is_some() {
                    occluders[y.instance as usize].push(x.instance);
                    occludees[x.instance as usize].push(y.instance);
                }
            }
        }
        self.occluders = occluders;
        self.occludees = occludees;
    }
}

/// The list of `partition` over `instances` (those drawn from it), new cutting planes added to
/// `planes`. `max_steps` bounds the scan; `advanced(placed, length)` is called each time the
/// scan moves on past a copy (for progress), with the copies passed and the list's length.
pub fn build_list<P: Planes>(
    instances: &[Instance],
    partition: &Partition,
    planes: &mut P,
    max_steps: u64,
    advanced: &mut dyn FnMut(usize, usize),
) -> Result<(Vec<ListCopy>, ListStats), NoOrder> {
    let mut b = Builder::new(instances, partition, planes);
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
    b.broad_phase(&list);
    let mut p = 0usize;
    let mut steps = 0u64;
    // Fall-back moves per copy (by uid) since the scan last moved on.
    let mut visits: HashMap<u32, u32> = HashMap::new();
    while p < list.len() {
        steps += 1;
        let x = list[p].clone();
        let mut backs: Vec<(usize, Rc<[DVec3]>)> = Vec::new();
        let stamp = b.mark(x.instance, true);
        for (q, y) in list.iter().enumerate().skip(p + 1) {
            if b.marks[y.instance as usize] == stamp {
                if let Some(v) = b.occludes(&x, y) {
                    backs.push((q, v));
                }
            }
        }
        let Some(&(last, _)) = backs.last() else {
            p += 1;
            visits.clear();
            advanced(p, list.len());
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
        let stamp = b.mark(x.instance, false);
        for f in &list[p + 1..=last] {
            if b.marks[f.instance as usize] == stamp {
                if let Some(v) = b.occludes(f, &x) {
                    fronts.push(v);
                }
            }
        }
        let cut = if fronts.is_empty() {
            None
        } else {
            let rb: Vec<DVec3> = backs.iter().flat_map(|(_, v)| v.iter().copied()).collect();
            let lps = &mut b.stats.linear_programs;
            // Else regions that only touch: a plane through their common face.
            cutting_plane(&rb, &fronts, MARGIN, lps)
                .or_else(|| cutting_plane(&rb, &fronts, -TOUCH, lps))
        };
        match cut {
            None => {
                // Nothing in the way (or nothing separable): move x after its last back edge.
                if fronts.is_empty() {
                    b.stats.moved += 1;
                } else {
                    let seen = visits.entry(x.uid).or_insert(0);
                    *seen += 1;
                    if *seen > CYCLE_VISITS {
                        // Round a cycle again: x stays, with its back edges.
                        b.stats.cycles.push((
                            instances[x.instance as usize].tri.id,
                            instances[list[last].instance as usize].tri.id,
                        ));
                        p += 1;
                        visits.clear();
                        advanced(p, list.len());
                        continue;
                    }
                    b.stats.fallback_moves += 1;
                }
                let c = list.remove(p);
                list.insert(last, c);
            }
            Some(plane) => b.duplicate(&mut list, p, last, plane),
        }
    }
    Ok((list, b.stats))
}

/// Fall-back moves of one copy from the scan's position after which it is taken to be in a
/// cycle (a copy comes back to the position only when every copy moved past it has moved
/// again: more than a few times, the same moves repeat).
pub const CYCLE_VISITS: u32 = 8;

/// Linear programs [`cutting_plane`] tries one front at a time, after the one over all fronts.
const MAX_GREEDY_PROGRAMS: u32 = 16;

/// The cutting plane of a duplication: the plane with the back edges' regions (`rb`) on its
/// negative side and, on its positive side, as many of the `fronts`' regions as can be added
/// greedily in order (at most [`MAX_GREEDY_PROGRAMS`] tried by a program of their own), with
/// the widest margin (the linear program over the greedy set), each region more than
/// `margin` from it ([`separate`]); `None` when not even the first front can be separated.
/// `linear_programs` counts those solved.
///
/// The greedy set is found with few programs: when all fronts separate at once it is all of
/// them; else a front the current plane already separates (by more than the margin) joins
/// without a program, since the set with it is separable too. The plane is then the program
/// over the final set, as if each front had been tried with a program of its own.
fn cutting_plane(
    rb: &[DVec3],
    fronts: &[Rc<[DVec3]>],
    margin: f64,
    linear_programs: &mut u64,
) -> Option<Plane> {
    // The regions share many vertices (the partition's corners, common planes): one
    // constraint each is enough.
    let rb = distinct(rb.iter().copied());
    let rb = rb.as_slice();
    let fronts: Vec<Vec<DVec3>> = fronts.iter().map(|v| distinct(v.iter().copied())).collect();
    let all = distinct(fronts.iter().flatten().copied());
    *linear_programs += 1;
    if let Some(plane) = separate(rb, &all, margin) {
        return Some(plane);
    }
    let mut rf: Vec<DVec3> = Vec::new();
    let mut plane: Option<Plane> = None;
    // The current plane is not the program over `rf` (a front joined without one).
    let mut stale = false;
    // Programs tried one front at a time; past the bound the rest stay unseparated, which is
    // correct (their back edges are handled when the scan reaches them) but may duplicate
    // more.
    let mut budget = MAX_GREEDY_PROGRAMS;
    for v in &fronts {
        if let Some(p) = plane {
            if v.iter().all(|q| p.eval(*q) > margin) {
                rf.extend_from_slice(v);
                stale = true;
                continue;
            }
        }
        if budget == 0 {
            break;
        }
        budget -= 1;
        let mut candidate = rf.clone();
        candidate.extend_from_slice(v);
        let candidate = distinct(candidate.into_iter());
        *linear_programs += 1;
        if let Some(p) = separate(rb, &candidate, margin) {
            rf = candidate;
            plane = Some(p);
            stale = false;
        }
    }
    if stale {
        let rf = distinct(rf.into_iter());
        *linear_programs += 1;
        // The current plane separates the set; the program only widens the margin.
        plane = separate(rb, &rf, margin).or(plane);
    }
    plane
}

/// `points` without repeats: one of each group closer than 1e-9 per coordinate (a plane with
/// a margin of [`MARGIN`] on one has nearly that margin on the others), in first-seen order.
fn distinct(points: impl Iterator<Item = DVec3>) -> Vec<DVec3> {
    let mut seen = std::collections::HashSet::new();
    points
        .filter(|p| seen.insert((*p * 1e9).round().to_array().map(|x| x as i64)))
        .collect()
}
