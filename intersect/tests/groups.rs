//! Rigid groups from the frames' poses.

use glam::{DMat4, DQuat, DVec3};
use trisort_intersect::rigid_groups;

use crate::common::{frame, geometry, node, pose};

/// root; door (child of root, animated); window (child of door); wheel (child of root);
/// hood (child of root).
fn car() -> trisort_format::Geometry {
    geometry(vec![
        node(
            "root",
            None,
            DMat4::from_translation(DVec3::new(0.0, 0.3, 0.0)),
        ),
        node("door", Some(0), DMat4::from_translation(DVec3::X)),
        node("window", Some(1), DMat4::IDENTITY),
        node("wheel", Some(0), DMat4::from_translation(DVec3::Z)),
        node("hood", Some(0), DMat4::from_translation(DVec3::Y)),
    ])
}

fn door_open(degrees: f64) -> DMat4 {
    DMat4::from_translation(DVec3::X) * DMat4::from_rotation_y(degrees.to_radians())
}

#[test]
fn nothing_moves_one_group() {
    let g = car();
    assert_eq!(rigid_groups(&g, &[]), vec![0; 5]);
    assert_eq!(
        rigid_groups(&g, &[frame(vec![]), frame(vec![])]),
        vec![0; 5]
    );
}

#[test]
fn a_moving_node_carries_its_children() {
    let g = car();
    let frames = [
        frame(vec![]),
        frame(vec![pose(1, door_open(30.0))]),
        frame(vec![pose(1, door_open(60.0))]),
    ];
    assert_eq!(rigid_groups(&g, &frames), vec![0, 1, 1, 0, 0]);
}

#[test]
fn nodes_moving_together_share_a_group() {
    let g = car();
    // The hood moves exactly as the door does, relative to it fixed.
    let hood =
        |deg: f64| DMat4::from_translation(DVec3::Y) * DMat4::from_rotation_y(deg.to_radians());
    let frames = [
        frame(vec![pose(1, door_open(0.0)), pose(4, hood(0.0))]),
        frame(vec![pose(1, door_open(40.0)), pose(4, hood(40.0))]),
    ];
    // Door and hood rotate about parallel axes through different points: their relative
    // transform changes (a rotation about one axis seen from the other moves), so not one
    // group ...
    assert_eq!(rigid_groups(&g, &frames), vec![0, 1, 1, 0, 2]);
    // ... but two nodes with the same motion about the same point are.
    let frames = [
        frame(vec![pose(1, door_open(0.0)), pose(4, door_open(0.0))]),
        frame(vec![pose(1, door_open(40.0)), pose(4, door_open(40.0))]),
    ];
    assert_eq!(rigid_groups(&g, &frames), vec![0, 1, 1, 0, 1]);
}

#[test]
fn a_pose_held_on_every_frame_does_not_move() {
    let g = car();
    let held = DMat4::from_rotation_translation(DQuat::from_rotation_x(0.3), DVec3::Z);
    let frames = [frame(vec![pose(3, held)]), frame(vec![pose(3, held)])];
    assert_eq!(rigid_groups(&g, &frames), vec![0; 5]);
}

#[test]
fn motion_below_the_tolerance_is_not_motion() {
    let g = car();
    let group_of_door = |epsilon: f64| {
        let frames = [
            frame(vec![]),
            frame(vec![pose(
                1,
                DMat4::from_translation(DVec3::new(1.0 + epsilon, 0.0, 0.0)),
            )]),
        ];
        rigid_groups(&g, &frames)[1]
    };
    assert_eq!(group_of_door(1e-12), 0);
    assert_eq!(group_of_door(1e-6), 1);
}
