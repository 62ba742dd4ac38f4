//! Rigid groups: nodes that never move relative to each other on a path, and the common space
//! in which the triangles of one group are compared.

use glam::DMat4;
use trisort_format::{world_transforms, FrameState, Geometry, Node};

/// Relative tolerance of [`rigid_groups`]: two nodes are rigidly attached when every entry of
/// their relative world transform (`W_a⁻¹ · W_b`) on every frame differs from frame 0's by at
/// most this times `1 +` the largest absolute entry of frame 0's relative transform.
///
/// Transforms chained in f64 from the same f64 keyframes agree to ~1e-15; 1e-9 accepts that
/// noise and nothing a viewer could see move (a nanometre at a metre).
pub const RIGID_TOLERANCE: f64 = 1e-9;

/// The rigid group of every node, as `groups[node]`: nodes whose relative world transform
/// ([`world_transforms`] of `frame.poses`) is the same on every frame (to [`RIGID_TOLERANCE`])
/// share a group. Group ids are dense and numbered in order of each group's first node, so
/// node 0 is in group 0.
///
/// With no frames the scene is taken at its rest pose, where nothing moves: one group.
///
/// Two nodes below the same animated node (or both below none) are attached exactly, so only
/// the animated nodes' transforms are compared: O(nodes × frames + classes² × frames), where
/// classes is the number of animated nodes plus one. Grouping is greedy in node order (a class
/// joins the first earlier group it is attached to), hence deterministic.
///
/// Requires parents before children and poses that name existing nodes, as
/// [`Geometry::check_structure`] and `trisort_format::check_frame_state` guarantee.
pub fn rigid_groups(geometry: &Geometry, frames: &[FrameState]) -> Vec<u32> {
    let nodes = &geometry.nodes;
    let anchor = anchors(nodes, frames);
    // The animated nodes, in index order; `slot[node]` is a node's place among them.
    let animated: Vec<usize> = (0..nodes.len()).filter(|&i| anchor[i] == Some(i)).collect();
    let mut slot = vec![usize::MAX; nodes.len()];
    for (k, &a) in animated.iter().enumerate() {
        slot[a] = k;
    }
    // World transforms of the animated nodes, [animated node][frame].
    let mut worlds: Vec<Vec<DMat4>> = vec![Vec::with_capacity(frames.len()); animated.len()];
    for frame in frames {
        let world = world_transforms(nodes, &frame.poses);
        for (k, &a) in animated.iter().enumerate() {
            worlds[k].push(world[a]);
        }
    }
    // A class is `None` (no animated ancestor: fixed in the world) or an animated node.
    let transform = |class: Option<usize>, f: usize| match class {
        None => DMat4::IDENTITY,
        Some(a) => worlds[slot[a]][f],
    };
    let attached = |a: Option<usize>, b: Option<usize>| {
        if frames.is_empty() {
            return true;
        }
        let first = transform(a, 0).inverse() * transform(b, 0);
        (1..frames.len()).all(|f| {
            let now = transform(a, f).inverse() * transform(b, f);
            same_transform(&first, &now)
        })
    };
    // Classes in order of their first node; each joins the first group it is attached to.
    let mut group_of_class: Vec<(Option<usize>, u32)> = Vec::new();
    let mut group_reps: Vec<Option<usize>> = Vec::new();
    let mut groups = Vec::with_capacity(nodes.len());
    for &class in &anchor {
        if let Some(&(_, g)) = group_of_class.iter().find(|(c, _)| *c == class) {
            groups.push(g);
            continue;
        }
        let g = match group_reps.iter().position(|&rep| attached(rep, class)) {
            Some(g) => g as u32,
            None => {
                group_reps.push(class);
                (group_reps.len() - 1) as u32
            }
        };
        group_of_class.push((class, g));
        groups.push(g);
    }
    groups
}

/// For every node, its nearest animated ancestor-or-self (a node that has a pose on some
/// frame), or `None` when neither it nor any ancestor is animated.
fn anchors(nodes: &[Node], frames: &[FrameState]) -> Vec<Option<usize>> {
    let mut animated = vec![false; nodes.len()];
    for pose in frames.iter().flat_map(|f| &f.poses) {
        if let Some(a) = animated.get_mut(pose.node as usize) {
            *a = true;
        }
    }
    let mut anchor: Vec<Option<usize>> = Vec::with_capacity(nodes.len());
    for (i, node) in nodes.iter().enumerate() {
        let inherited = node.parent.and_then(|p| anchor[p as usize]);
        anchor.push(if animated[i] { Some(i) } else { inherited });
    }
    anchor
}

/// Whether `now` equals `first` to [`RIGID_TOLERANCE`] (false when either is not finite).
fn same_transform(first: &DMat4, now: &DMat4) -> bool {
    let a = first.to_cols_array();
    let b = now.to_cols_array();
    let scale = 1.0 + a.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(&b)
        .all(|(x, y)| (x - y).abs() <= RIGID_TOLERANCE * scale)
}

/// Where the triangles of each rigid group are compared.
pub(crate) struct CommonSpace {
    /// Rigid group of every node ([`rigid_groups`]).
    pub groups: Vec<u32>,
    /// Number of groups.
    pub group_count: usize,
    /// Per node: its local space → its group's common space.
    pub to_common: Vec<DMat4>,
}

impl CommonSpace {
    /// One space for every node: world space as the path's first frame places it (the rest
    /// pose without frames), every node in group 0; `groups` keeps each node's rigid group,
    /// for the detector to pair only triangles of different groups.
    pub fn first_frame(geometry: &Geometry, frames: &[FrameState]) -> (CommonSpace, Vec<u32>) {
        let rigid = rigid_groups(geometry, frames);
        let poses = frames.first().map_or(&[][..], |f| &f.poses[..]);
        let world = world_transforms(&geometry.nodes, poses);
        let space = CommonSpace {
            groups: vec![0; geometry.nodes.len()],
            group_count: usize::from(!geometry.nodes.is_empty()),
            to_common: world,
        };
        (space, rigid)
    }

    /// The rigid groups of `frames`, and per group the local space of its first node at frame 0
    /// (rest pose without frames) as the common space. The first node's own triangles are
    /// therefore compared in their exact local coordinates, as are those of every node whose
    /// world transform at frame 0 equals the first node's bit for bit (a one-node group, a
    /// child with an identity rest transform). A first node whose world transform is not
    /// invertible makes world space the group's common space.
    pub fn new(geometry: &Geometry, frames: &[FrameState]) -> CommonSpace {
        let groups = rigid_groups(geometry, frames);
        let poses = frames.first().map_or(&[][..], |f| &f.poses[..]);
        let world = world_transforms(&geometry.nodes, poses);
        let group_count = groups.iter().map(|&g| g as usize + 1).max().unwrap_or(0);
        let mut first = vec![usize::MAX; group_count];
        for (node, &g) in groups.iter().enumerate() {
            if first[g as usize] == usize::MAX {
                first[g as usize] = node;
            }
        }
        let inverse: Vec<Option<DMat4>> = first
            .iter()
            .map(|&r| {
                let inv = world[r].inverse();
                let ok = world[r].determinant().abs() > 1e-300 && inv.is_finite();
                ok.then_some(inv)
            })
            .collect();
        let to_common = groups
            .iter()
            .enumerate()
            .map(|(node, &g)| {
                let r = first[g as usize];
                match inverse[g as usize] {
                    _ if world[node] == world[r] => DMat4::IDENTITY,
                    Some(inv) => inv * world[node],
                    None => world[node],
                }
            })
            .collect();
        CommonSpace {
            groups,
            group_count,
            to_common,
        }
    }
}
