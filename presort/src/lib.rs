//! Depth-presorted triangle lists (paper 000, Chen, Sander, Nehab et al.): one list of triangle
//! copies per viewpoint partition, each copy with half-space tests, such that for every camera
//! outside a bounding polyhedron (and within its reach) the copies that pass their tests are in
//! back-to-front order on every pixel. Pure CPU; `trisort presort` writes the result as a
//! [`trisort_format::Presorted`] file, and the reference crate's presorted renderer draws it.
//!
//! Scope (stated in README § Free viewpoints): the lists hold the triangles that need an order
//! ([`Geometry::needs_order`]: `BLEND` and transmissive materials); the opaque rest is drawn
//! first with the depth test, as paper 000 suggests for scenes with opaque parts. Steps:
//!
//! 1. The caller splits triangles that pass through each other (`trisort_intersect`), at the
//!    rest pose: presorted geometry is static.
//! 2. Each sorted triangle gives an instance per side it is drawn from: its front, and for a
//!    double-sided material its back too (paper 000's back-face duplicates), each with a test
//!    of its own plane, so one side is drawn.
//! 3. The bounding polyhedron ([`partition`]) has `--partitions` faces around the scene's
//!    bounding sphere; each face's partition gets its own list, built in parallel (rayon).
//! 4. Each list ([`list`]): a preliminary order (a depth sort from a viewpoint in the
//!    partition), then back edges removed by moving copies or duplicating them with cutting
//!    planes found by linear programming ([`lp`]) between the occlusion regions ([`geom`]).
#![deny(missing_docs)]

pub mod geom;
pub mod list;
pub mod lp;
pub mod partition;

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use glam::{DMat4, DVec3};
use rayon::prelude::*;
use trisort_format::{
    world_transforms, Geometry, PlaneTest, Polyhedron, PresortStats, PresortedCopy, Segment,
};

use crate::geom::{Plane, Tri};
use crate::list::{build_list, Instance, NoOrder, Test};

/// How to presort.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PresortOptions {
    /// Faces of the bounding polyhedron, one partition each (4, 6, 8 or 10 to 256).
    pub partitions: u32,
    /// How far cameras may be from the centre, per axis, in scene radii.
    pub reach: f64,
    /// Bound on the scan's steps per partition, in multiples of the partition's instances.
    pub max_steps_per_instance: u64,
    /// Fail on an unresolved cycle ([`list`]) instead of keeping the list and reporting it.
    pub strict: bool,
}

impl Default for PresortOptions {
    fn default() -> Self {
        PresortOptions {
            partitions: 6,
            reach: 100.0,
            max_steps_per_instance: 64,
            strict: false,
        }
    }
}

/// The lists of a presort (everything of a [`trisort_format::Presorted`] but the scene).
#[derive(Clone, Debug)]
pub struct Lists {
    /// The polyhedron (world space).
    pub polyhedron: Polyhedron,
    /// Opaque triangles, ascending.
    pub opaque: Vec<u32>,
    /// Sorted triangles, ascending.
    pub sorted: Vec<u32>,
    /// Per partition, its copies.
    pub segments: Vec<Segment>,
    /// The copies.
    pub copies: Vec<PresortedCopy>,
    /// Their tests.
    pub tests: Vec<PlaneTest>,
    /// The planes, relative to the polyhedron's centre, world units.
    pub planes: Vec<[f32; 4]>,
    /// Figures (`seconds` covers the lists only).
    pub stats: PresortStats,
    /// Unresolved cycles ([`list`]), all partitions: where the lists are not exact.
    pub cycles: Vec<Cycle>,
}

/// An unresolved cycle: a copy left before copies it occludes from some viewpoints of its
/// partition, since the cutting planes could not break the cycle it is in. Frames from
/// those viewpoints may draw these triangles out of order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cycle {
    /// The partition.
    pub partition: usize,
    /// Scene id of the copy's triangle.
    pub triangle: u32,
    /// Scene id of the last triangle it occludes that stays after it.
    pub occluded: u32,
}

/// Why a presort failed.
#[derive(Debug, thiserror::Error)]
pub enum PresortError {
    /// A partition count the polyhedra do not come in.
    #[error("--partitions {0}: use 4, 6, 8 or 10 to 256")]
    Partitions(u32),
    /// Nothing to bound.
    #[error("the scene has no extent (no triangles, or all at one point)")]
    Empty,
    /// A position is not finite.
    #[error("triangle {0} has a corner that is not finite")]
    NotFinite(u32),
    /// An unresolved cycle, with [`PresortOptions::strict`].
    #[error(
        "partition {partition}: triangles {a} and {b} are in an occlusion cycle that no cutting \
         plane breaks ({count} such copies in this partition; without --strict the list keeps \
         them out of order and says so)"
    )]
    Cycle {
        /// The partition.
        partition: usize,
        /// Copies left in a cycle in the partition.
        count: usize,
        /// Scene ids.
        a: u32,
        /// Scene ids.
        b: u32,
    },
    /// A partition's list could not be ordered within the step bound.
    #[error(
        "partition {partition}: no order found after {steps} steps (triangles {a} and {b} \
         keep occluding each other; try more --partitions)"
    )]
    NoOrder {
        /// The partition.
        partition: usize,
        /// Steps taken.
        steps: u64,
        /// Scene ids.
        a: u32,
        /// Scene ids.
        b: u32,
    },
}

/// World-space corners of every triangle at the rest pose.
fn world_triangles(geometry: &Geometry) -> Vec<[DVec3; 3]> {
    let world: Vec<DMat4> = world_transforms(&geometry.nodes, &[]);
    geometry
        .triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                let vx = &geometry.vertices[v as usize];
                let m = world
                    .get(vx.node as usize)
                    .copied()
                    .unwrap_or(DMat4::IDENTITY);
                m.transform_point3(DVec3::from(vx.position.map(f64::from)))
            })
        })
        .collect()
}

/// Shared progress of the partitions' scans: per partition, the copies the scan has placed
/// and the copies in its list so far (duplicates lengthen it).
struct Counter<'a> {
    placed: &'a [AtomicUsize],
    lengths: &'a [AtomicUsize],
    progress: &'a (dyn Fn(usize, usize) + Sync),
}

impl Counter<'_> {
    fn set(&self, k: usize, placed: usize, length: usize) {
        self.placed[k].store(placed, Ordering::Relaxed);
        self.lengths[k].store(length, Ordering::Relaxed);
        let sum = |v: &[AtomicUsize]| v.iter().map(|a| a.load(Ordering::Relaxed)).sum();
        (self.progress)(sum(self.placed), sum(self.lengths));
    }
}

/// Partition `k`'s list (its copies, figures and planes: the shared `own_planes` then its
/// cutting planes), or why there is none.
fn one_list(
    k: usize,
    part: &partition::Partition,
    instances: &[Instance],
    own_planes: &[Plane],
    options: PresortOptions,
    c: Counter,
) -> Result<(Vec<list::ListCopy>, list::ListStats, Vec<Plane>), PresortError> {
    let mut planes: Vec<Plane> = own_planes.to_vec();
    let max_steps = options.max_steps_per_instance * (instances.len() as u64 + 16);
    let mut advanced = |placed: usize, length: usize| c.set(k, placed, length);
    let r = build_list(instances, part, &mut planes, max_steps, &mut advanced).map_err(
        |NoOrder { triangles, steps }| PresortError::NoOrder {
            partition: k,
            steps,
            a: triangles.0,
            b: triangles.1,
        },
    );
    if let Ok((list, _)) = &r {
        c.set(k, list.len(), list.len());
    }
    match r {
        Ok((_, stats)) if options.strict && !stats.cycles.is_empty() => {
            let (a, b) = stats.cycles[0];
            Err(PresortError::Cycle {
                partition: k,
                count: stats.cycles.len(),
                a,
                b,
            })
        }
        r => r.map(|(list, stats)| (list, stats, planes)),
    }
}

/// Presorts `geometry` (already split, static). `progress(placed, total)` is called as the
/// partitions' scans move on (from worker threads): `total` is the copies in all lists so far
/// (the sorted instances times the partitions at first; duplicates add to it), `placed` those
/// the scans have passed.
pub fn presort(
    geometry: &Geometry,
    options: PresortOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Lists, PresortError> {
    let t0 = Instant::now();
    if !partition::valid_partitions(options.partitions) {
        return Err(PresortError::Partitions(options.partitions));
    }
    let world = world_triangles(geometry);
    if let Some(t) = world.iter().position(|t| t.iter().any(|v| !v.is_finite())) {
        return Err(PresortError::NotFinite(t as u32));
    }
    let (centre, radius) = bounds(&world)?;
    let norm = |v: DVec3| (v - centre) / radius;
    let faces = faces(options.partitions, &world, norm);
    let parts = partition::partitions(&faces, options.reach).ok_or(PresortError::Empty)?;
    let (sorted, opaque): (Vec<u32>, Vec<u32>) =
        (0..geometry.triangles.len() as u32).partition(|&t| geometry.needs_order(t));
    let (own_planes, instances) = instances(geometry, &sorted, &world, norm);
    let placed: Vec<AtomicUsize> = parts.iter().map(|_| AtomicUsize::new(0)).collect();
    let lengths: Vec<AtomicUsize> = parts
        .iter()
        .map(|_| AtomicUsize::new(instances.len()))
        .collect();
    progress(0, parts.len() * instances.len());
    let built: Vec<Result<_, PresortError>> = parts
        .par_iter()
        .enumerate()
        .map(|(k, part)| {
            let counter = Counter {
                placed: &placed,
                lengths: &lengths,
                progress,
            };
            one_list(k, part, &instances, &own_planes, options, counter)
        })
        .collect();
    let mut out = Lists {
        polyhedron: Polyhedron {
            centre: centre.to_array(),
            faces: faces
                .iter()
                .map(|(n, h)| [n.x, n.y, n.z, h * radius])
                .collect(),
            reach: options.reach * radius,
        },
        opaque,
        sorted: sorted.clone(),
        segments: Vec::new(),
        copies: Vec::new(),
        tests: Vec::new(),
        planes: Vec::new(),
        stats: PresortStats {
            triangles: geometry.triangles.len() as u64,
            sorted_triangles: sorted.len() as u64,
            ..PresortStats::default()
        },
        cycles: Vec::new(),
    };
    let to_f32 = |p: &Plane| {
        [
            p.n.x as f32,
            p.n.y as f32,
            p.n.z as f32,
            (p.d * radius) as f32,
        ]
    };
    out.planes.extend(own_planes.iter().map(to_f32));
    for (partition, r) in built.into_iter().enumerate() {
        let (list, stats, planes) = r?;
        out.cycles
            .extend(stats.cycles.iter().map(|&(triangle, occluded)| Cycle {
                partition,
                triangle,
                occluded,
            }));
        // This list's cutting planes follow the shared ones.
        let base = out.planes.len() as u32 - own_planes.len() as u32;
        out.planes
            .extend(planes[own_planes.len()..].iter().map(to_f32));
        let global = |t: Test| PlaneTest {
            plane: if (t.plane as usize) < own_planes.len() {
                t.plane
            } else {
                t.plane + base
            },
            flipped: t.flipped,
        };
        out.segments.push(Segment {
            first: out.copies.len() as u32,
            count: list.len() as u32,
        });
        for c in &list {
            let inst = &instances[c.instance as usize];
            let first_test = out.tests.len() as u32;
            out.tests.extend(inst.own.into_iter().map(global));
            out.tests.extend(c.cuts.iter().map(|t| global(*t)));
            out.copies.push(PresortedCopy {
                triangle: inst.tri.id,
                first_test,
                tests: out.tests.len() as u32 - first_test,
            });
        }
        out.stats.duplicated += stats.duplicated;
        out.stats.moved += stats.moved + stats.fallback_moves;
        out.stats.regions += stats.regions;
        out.stats.linear_programs += stats.linear_programs;
    }
    out.stats.list_triangles = out.copies.len() as u64;
    out.stats.seconds = t0.elapsed().as_secs_f64();
    Ok(out)
}

impl Lists {
    /// The presorted file of these lists over `geometry` (the scene they were made from).
    pub fn into_presorted(
        self,
        geometry: Geometry,
        environment: trisort_format::Environment,
        glass_opacity: f32,
        scene_hash: trisort_format::Hash,
    ) -> trisort_format::Presorted {
        trisort_format::Presorted {
            tool_version: trisort_format::TOOL_VERSION.to_string(),
            scene_hash,
            geometry,
            environment,
            glass_opacity,
            polyhedron: self.polyhedron,
            opaque: self.opaque,
            sorted: self.sorted,
            segments: self.segments,
            copies: self.copies,
            tests: self.tests,
            planes: self.planes,
            stats: self.stats,
        }
    }
}

/// The centre of the scene's bounding box and the largest distance of a corner from it.
fn bounds(world: &[[DVec3; 3]]) -> Result<(DVec3, f64), PresortError> {
    let (lo, hi) = world.iter().flatten().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), v| (lo.min(*v), hi.max(*v)),
    );
    let centre = (lo + hi) * 0.5;
    let radius = world
        .iter()
        .flatten()
        .map(|v| v.distance(centre))
        .fold(0.0, f64::max);
    if !(radius > 0.0 && radius.is_finite()) {
        return Err(PresortError::Empty);
    }
    Ok((centre, radius))
}

/// The instances of the `sorted` triangles (normalised by `norm`): the front of each, and the
/// back of a double-sided one too, each double-sided instance tested against its triangle's
/// plane (returned first: shared by every partition's list).
fn instances(
    geometry: &Geometry,
    sorted: &[u32],
    world: &[[DVec3; 3]],
    norm: impl Fn(DVec3) -> DVec3,
) -> (Vec<Plane>, Vec<Instance>) {
    let mut own_planes: Vec<Plane> = Vec::new();
    let mut instances: Vec<Instance> = Vec::new();
    for &t in sorted {
        let tri = Tri::new(world[t as usize].map(&norm), t);
        let material = &geometry.materials[geometry.triangle_material(t) as usize];
        match (material.double_sided, tri.plane) {
            (true, Some(plane)) => {
                own_planes.push(plane);
                let index = (own_planes.len() - 1) as u32;
                for (tri, flipped) in [(tri, false), (tri.reversed(), true)] {
                    instances.push(Instance {
                        tri,
                        own: Some(Test {
                            plane: index,
                            flipped,
                        }),
                    });
                }
            }
            _ => instances.push(Instance { tri, own: None }),
        }
    }
    (own_planes, instances)
}

/// The polyhedron's faces (unit normal, distance), normalised: each face just outside the
/// scene's support in its direction.
fn faces(
    partitions: u32,
    world: &[[DVec3; 3]],
    norm: impl Fn(DVec3) -> DVec3,
) -> Vec<(DVec3, f64)> {
    partition::face_normals(partitions)
        .into_iter()
        .map(|n| {
            let h = world
                .iter()
                .flatten()
                .map(|v| n.dot(norm(*v)))
                .fold(f64::NEG_INFINITY, f64::max);
            (n, h.max(0.0) + 0.01)
        })
        .collect()
}
