//! Interpenetration removed before recording: cycles are removed at the source, where the
//! geometry still says how to cut them, not left for the merger.
//!
//! Two triangles that cross each other have no depth order: each is in front of the other
//! somewhere, a cycle the sorted player cannot draw. Splitting both along the line where
//! their planes meet leaves pieces that each lie on one side of the other triangle's plane,
//! which always have an order. This crate finds such pairs and splits them, before recording.
//!
//! # What is compared
//!
//! First the triangles of one *rigid group* ([`rigid_groups`]): nodes whose relative world
//! transform is the same on every frame of the path. A group is compared in one common space:
//! the local space of its first node at frame 0, in f64, so that one-node groups are compared
//! in their exact stored coordinates. Then, on that pass's output, the pairs of triangles of
//! *different* groups, in world space as the path's first frame places them
//! ([`SplitOptions::across_groups`]): their crossings come and go with the animation (a door's
//! inner panel passing through the cabin trim while closed), so one pose is taken, and pieces
//! cut there are still whole surfaces in every other pose. Crossings that only other poses
//! have are left (the recorder's unordered samples report them).
//! Zero-area triangles are skipped.
//!
//! # When a pair crosses
//!
//! Each triangle has corners strictly on both sides of the other's plane and the two chords
//! they cut from the planes' common line overlap. Signs are decided exactly (Shewchuk's
//! adaptive `orient3d`, the `robust` crate). Touching at a point or along an edge, one
//! triangle resting on the other (a T-junction) and coplanar overlap (a tie) are not
//! crossings: each of those has a consistent order.
//!
//! A crossing only counts when it is deeper than what rounding vertices to f32 could make.
//! A point of a node moves by up to `δ = √3 · 2⁻²⁴ · max |local coordinate of the node| ·
//! ‖node → common‖_F` when rounded; moving a triangle's corners by `δ_b` moves its plane, at
//! a point with barycentric coordinates `λ` in it, by up to `δ_b · Σ|λᵢ|` (1 inside it, more
//! away from it: the planes of thin pieces tilt). So a corner of `a` counts as beyond the
//! plane of `b` only when farther than `3 (δ_a + δ_b · Σ|λᵢ|)`; both triangles must have
//! corners beyond on both sides, and the chords must overlap by more than `3 (δ_a + δ_b)`.
//! Shallower crossings are counted in [`SplitReport::pairs_below_precision`] and left alone;
//! in exchange, the rounded pieces of a cut are never found crossing again (that margin covers
//! the cut's own band, the rounding of cut points and the merging of edge points).
//!
//! # How triangles are split
//!
//! Each triangle of a crossing pair is cut along the whole line where the other's plane
//! meets it, by each of its partners in ascending id order, as convex polygons in its own
//! barycentric coordinates (so new positions are interpolations of its stored corners in the
//! node's local space, and normal and uv are interpolated with the same weights, the normal
//! renormalised); the pieces are triangulated and keep the original's winding, material and
//! node. Cutting one of the two triangles already removes the pair's cycle, so by default only
//! one is cut (the one with fewer crossing partners): on CarConcept's car tour that adds 90,575
//! triangles instead of 288,707 for both sides ([`SplitOptions::cut_both_sides`]).
//!
//! Slivers: a cut is skipped for a triangle when a piece it would create cannot be
//! triangulated, after rounding to f32, into triangles that keep the original's orientation
//! and each have at least [`SplitOptions::min_piece_area_fraction`] of its area (default
//! [`DEFAULT_MIN_PIECE_AREA_FRACTION`], 10⁻⁶). A pair stays crossing only when its cut was
//! skipped on both triangles: [`SplitReport::pairs_skipped_sliver`], [`SplitScene::skipped`].
//!
//! T-junctions: a point a cut puts on an edge is also inserted into the other triangles
//! sharing that edge (same node, same corner positions), at the same f32 position, so that no
//! crack can open there ([`SplitOptions::close_t_junctions`]); points of one edge within two
//! roundings of each other are merged first.
//!
//! Rounds: the pieces of a cut triangle have new corners, and the detector looks at corners,
//! so a piece can cross a triangle that the whole one crossed only within precision. After a
//! round of cuts the detector runs again on the pairs involving a changed triangle, and cuts
//! what it finds, for at most 4 rounds ([`SplitReport::rounds`]; 2 for the demo car and
//! CarConcept with the defaults). The output is checked the same way: [`find_intersections`] on it finds only
//! pieces of the pairs in [`SplitScene::skipped`].
//!
//! # Output
//!
//! Triangles keep their order: the pieces of original triangle `t` come, consecutively, where
//! `t` was, so [`SplitScene::origin`] is non-decreasing. Original vertices are kept as they
//! were, new vertices appended (deduplicated by value); untouched triangles keep their
//! indices. Nothing crossing gives the input geometry back, byte for byte. Identical input
//! gives identical output whatever the number of threads.
#![deny(missing_docs)]

mod bvh;
mod cut;
mod detect;
mod edges;
mod groups;
mod narrow;
mod split;

use serde::{Deserialize, Serialize};
use trisort_format::{FrameState, Geometry};

use detect::Prepared;
pub use groups::{rigid_groups, RIGID_TOLERANCE};

/// The default [`SplitOptions::min_piece_area_fraction`].
pub const DEFAULT_MIN_PIECE_AREA_FRACTION: f64 = 1e-6;

/// Options of [`split_intersections`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SplitOptions {
    /// Smallest area of an output triangle of a split, as a fraction of the area of the
    /// triangle it comes from (default [`DEFAULT_MIN_PIECE_AREA_FRACTION`]). Cuts that would
    /// create smaller pieces are skipped.
    pub min_piece_area_fraction: f64,
    /// Insert every point a cut puts on an edge into the other triangles sharing that edge
    /// (same node, same corner positions), so that no T-junction is left where a crack could
    /// open (default true). They are split without crossing anything, see
    /// [`SplitReport::neighbours_split`].
    pub close_t_junctions: bool,
    /// Cut both triangles of a crossing pair (default false). Off, only one is cut: the one
    /// with fewer crossing partners, or the other where that cut would make a sliver. One side
    /// is enough to remove the pair's cycle (each piece then lies on one side of the other
    /// triangle's plane) and adds fewer triangles; both sides make the crossing an edge of
    /// both surfaces.
    pub cut_both_sides: bool,
    /// Also split crossing pairs of triangles of *different* rigid groups, as the path's first
    /// frame places them (default true): a door's inner panel through the cabin's trim with
    /// the door closed. Their crossings come and go with the animation, so one pose is taken:
    /// the first frame's; pieces cut there stay valid surfaces in every other pose.
    #[serde(default = "yes")]
    pub across_groups: bool,
}

fn yes() -> bool {
    true
}

impl Default for SplitOptions {
    fn default() -> Self {
        SplitOptions {
            min_piece_area_fraction: DEFAULT_MIN_PIECE_AREA_FRACTION,
            close_t_junctions: true,
            cut_both_sides: false,
            across_groups: true,
        }
    }
}

/// What [`split_intersections`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SplitReport {
    /// Crossing pairs resolved: at least one of the two triangles was cut along the other's
    /// plane (usually both).
    pub pairs_split: u64,
    /// Output triangles minus input triangles.
    pub triangles_added: u64,
    /// Crossing pairs left crossing because the cut would have made a sliver on both
    /// triangles ([`SplitScene::skipped`] lists them).
    pub pairs_skipped_sliver: u64,
    /// Pairs crossing no deeper than their position precision: treated as touching.
    pub pairs_below_precision: u64,
    /// Original triangles replaced by pieces.
    pub triangles_split: u64,
    /// Pairs of triangles of one group whose bounding boxes overlap (the narrow phase's work).
    pub candidate_pairs: u64,
    /// Rigid groups ([`rigid_groups`]).
    pub groups: usize,
    /// Rounds of cutting done (0 when nothing crossed; see the crate documentation).
    pub rounds: u32,
    /// Triangles split only to take the points cuts put on their edges (included in
    /// `triangles_split`; see [`SplitOptions::close_t_junctions`]).
    pub neighbours_split: u64,
    /// Points on an edge that a triangle sharing the edge could not take without a sliver:
    /// T-junctions left.
    pub t_junctions_left: u64,
    /// Crossing pairs of triangles of different rigid groups resolved
    /// at the first frame's pose ([`SplitOptions::across_groups`]), not counted in
    /// `pairs_split`.
    #[serde(default)]
    pub pairs_split_across_groups: u64,
}

/// The scene with its crossing pairs split.
#[derive(Clone, Debug, PartialEq)]
pub struct SplitScene {
    /// The split geometry: materials, textures and nodes as in the input.
    pub geometry: Geometry,
    /// Per output triangle, the input (scene) triangle it comes from; non-decreasing.
    pub origin: Vec<u32>,
    /// The crossing pairs left crossing (input ids `[a, b]`, `a < b`, ascending): counted in
    /// [`SplitReport::pairs_skipped_sliver`].
    pub skipped: Vec<[u32; 2]>,
    /// The figures.
    pub report: SplitReport,
}

/// The crossing pairs of a scene, as [`find_intersections`] finds them.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Intersections {
    /// Crossing pairs `[a, b]` (triangle ids, `a < b`), ascending.
    pub pairs: Vec<[u32; 2]>,
    /// Pairs crossing no deeper than their position precision (not in `pairs`).
    pub pairs_below_precision: u64,
    /// Pairs of one group whose bounding boxes overlap.
    pub candidate_pairs: u64,
    /// Rigid groups.
    pub groups: usize,
}

/// Finds the pairs of triangles of one rigid group of `frames` that cross (see the
/// [crate documentation](crate)). Frame 0 (the rest pose without frames) places the groups'
/// nodes. Requires a geometry that passes [`Geometry::check_structure`].
///
/// A broad phase of one bounding volume hierarchy per group, then the exact narrow phase on
/// every pair of overlapping boxes, in parallel; O(n log n + candidates) for n triangles.
pub fn find_intersections(geometry: &Geometry, frames: &[FrameState]) -> Intersections {
    let prepared = Prepared::new(geometry, frames);
    let found = prepared.find(None);
    Intersections {
        pairs: found.pairs,
        pairs_below_precision: found.below_precision,
        candidate_pairs: found.candidates,
        groups: prepared.group_count,
    }
}

/// Splits every crossing pair of triangles of one rigid group of `frames` along the line
/// where their planes meet (see the [crate documentation](crate) for what crosses, the
/// precision and sliver rules, and the output's order). Frame 0 (the rest pose without
/// frames) places the groups' nodes. Requires a geometry that passes
/// [`Geometry::check_structure`].
pub fn split_intersections(
    geometry: &Geometry,
    frames: &[FrameState],
    options: &SplitOptions,
) -> SplitScene {
    split::split(geometry, frames, options)
}

/// The geometry a recording with `settings` is made of: `geometry` with its crossing pairs
/// split ([`split_intersections`] with the default options) when
/// `settings.split_intersections`, else `None` (record `geometry` as it is). Every stage that
/// needs the recorded scene (record, bake, bench, and `verify --scene`'s exact reference) goes
/// through this, so they all see the same triangles.
pub fn working_geometry(
    geometry: &Geometry,
    frames: &[FrameState],
    settings: &trisort_format::RecordSettings,
) -> Option<SplitScene> {
    settings
        .split_intersections
        .then(|| split_intersections(geometry, frames, &SplitOptions::default()))
}
