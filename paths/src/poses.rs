//! Node poses: the pivot rotation of the TOML format and the "differs from rest" filter.

use glam::{DMat4, DVec3};
use trisort_format::NodePose;

/// The local transform of a node rotated by `angle` radians about the unit `axis` through
/// `pivot` and then moved by `translation`, all in the node's own frame (the space its
/// mesh's vertices are in): `rest · T(translation) · T(pivot) · R(axis, angle) · T(−pivot)`.
pub(crate) fn pivot_pose(
    rest: DMat4,
    translation: DVec3,
    pivot: DVec3,
    axis: DVec3,
    angle: f64,
) -> DMat4 {
    rest * DMat4::from_translation(translation)
        * DMat4::from_translation(pivot)
        * DMat4::from_axis_angle(axis, angle)
        * DMat4::from_translation(-pivot)
}

/// `Some(pose)` when `local` differs from the node's rest transform by more than 1e-12
/// relative to the largest rest element; `None` when it is the rest transform up to rounding
/// (frames list only the nodes that moved).
pub(crate) fn pose_if_moved(node: u32, rest: &[f64; 16], local: DMat4) -> Option<NodePose> {
    let local = local.to_cols_array();
    let scale = rest.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    let moved = local
        .iter()
        .zip(rest)
        .any(|(a, b)| (a - b).is_nan() || (a - b).abs() > 1e-12 * scale);
    moved.then_some(NodePose { node, local })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pivot_rotation_moves_points_about_the_pivot() {
        let rest = DMat4::from_translation(DVec3::new(10.0, 0.0, 0.0));
        let pivot = DVec3::new(1.0, 0.0, 0.0);
        let m = pivot_pose(rest, DVec3::ZERO, pivot, DVec3::Y, 90f64.to_radians());
        // The pivot stays; a point 1 along +X from the pivot swings to −Z of it (right-handed
        // rotation about +Y), then rest moves it by +10 X.
        let p = m.transform_point3(pivot);
        assert!((p - DVec3::new(11.0, 0.0, 0.0)).length() < 1e-12, "{p:?}");
        let q = m.transform_point3(DVec3::new(2.0, 0.0, 0.0));
        assert!((q - DVec3::new(11.0, 0.0, -1.0)).length() < 1e-12, "{q:?}");
        let t = pivot_pose(rest, DVec3::new(0.0, 2.0, 0.0), pivot, DVec3::Y, 0.0);
        assert_eq!(t.transform_point3(DVec3::ZERO), DVec3::new(10.0, 2.0, 0.0));
    }

    #[test]
    fn rest_pose_is_filtered() {
        let rest = DMat4::from_translation(DVec3::new(3.0, 0.0, 0.0));
        let same = pivot_pose(rest, DVec3::ZERO, DVec3::new(0.5, 0.2, 0.1), DVec3::X, 0.0);
        assert_eq!(pose_if_moved(4, &rest.to_cols_array(), same), None);
        let moved = pivot_pose(rest, DVec3::ZERO, DVec3::ZERO, DVec3::X, 1e-3);
        let pose = pose_if_moved(4, &rest.to_cols_array(), moved).expect("moved");
        assert_eq!(pose.node, 4);
        assert_eq!(pose.local, moved.to_cols_array());
    }
}
