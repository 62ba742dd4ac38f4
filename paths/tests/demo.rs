//! The demo car's default path: an orbit while the driver door opens outward and closes.

use glam::{DMat4, DVec3, Vec3};
use trisort_format::world_transforms;
use trisort_paths::{demo_default, Timeline};
use trisort_scene::demo_car::{demo_car, DOOR_NODE};
use trisort_scene::Scene;

use crate::common::{eye_forward, node, scene_with_boxes};

/// World-space centroid of the vertices of `node` at a frame.
fn centroid(scene: &Scene, t: &Timeline, f: usize, node: u32) -> DVec3 {
    let g = &scene.geometry;
    let world = world_transforms(&g.nodes, &t.frames[f].poses);
    let (mut sum, mut n) = (DVec3::ZERO, 0);
    for v in g.vertices.iter().filter(|v| v.node == node) {
        sum += world[node as usize].transform_point3(Vec3::from(v.position).as_dvec3());
        n += 1;
    }
    sum / n as f64
}

/// Checks the demo path over a scene whose door is `door`; returns the door's outward
/// horizontal displacement when fully open.
fn check(scene: &Scene, door: u32) -> f64 {
    let t = demo_default(scene);
    assert_eq!(t.frames.len(), 48);
    assert_eq!(t.fps, 30.0);
    let (lo, hi) = scene.bounds().unwrap();
    let centre = (lo + hi) * 0.5;
    // An orbit: constant distance to the centre, looking at it, slightly above it.
    let d0 = (eye_forward(&t, 0).0 - centre).length();
    for f in 0..48 {
        let (eye, fwd) = eye_forward(&t, f);
        assert!(((eye - centre).length() - d0).abs() < 1e-9);
        assert!(((centre - eye).normalize() - fwd).length() < 1e-9);
        assert!(eye.y > centre.y);
    }
    // The door: closed at the start and the end, open 60° in the middle.
    let door_pose = |f: usize| t.frames[f].poses.iter().find(|p| p.node == door);
    assert!(door_pose(0).is_none() && door_pose(8).is_none() && door_pose(47).is_none());
    assert!((9..40).all(|f| door_pose(f).is_some()));
    let open = DMat4::from_cols_array(&door_pose(24).unwrap().local);
    let rest = DMat4::from_cols_array(&scene.geometry.nodes[door as usize].rest);
    let rotation = rest.inverse() * open;
    let angle = rotation.x_axis.truncate().angle_between(DVec3::X);
    assert!(
        (angle.to_degrees() - 60.0).abs() < 1e-9,
        "{}",
        angle.to_degrees()
    );
    assert!(
        rotation.w_axis.truncate().length() < 1e-12,
        "about the node's origin"
    );
    // Swinging outward: away from the centre, horizontally.
    let closed = centroid(scene, &t, 0, door);
    let opened = centroid(scene, &t, 24, door);
    let outward = ((closed - centre) * DVec3::new(1.0, 0.0, 1.0)).normalize();
    // The camera faces the door's side while it is open.
    let (eye, _) = eye_forward(&t, 24);
    assert!((eye - centre).dot(outward) > 0.0);
    (opened - closed).dot(outward)
}

#[test]
fn hand_built_doors_on_either_side_open_outward() {
    // A body and a door hinged at its front edge (+Z), extending 1 m towards −Z, on the −X
    // side, and the same car mirrored to +X. A positive turn about +Y swings the −X door's
    // rear edge (local −Z) towards −X: outward. On the +X side the sign must flip.
    for side in [-1.0, 1.0] {
        let scene = scene_with_boxes(
            vec![
                node("Body", None, DMat4::IDENTITY),
                node(
                    "DriverDoor",
                    Some(0),
                    DMat4::from_translation(DVec3::new(side * 1.0, 0.5, 0.5)),
                ),
            ],
            &[
                (0, DVec3::new(-0.95, 0.0, -2.0), DVec3::new(0.95, 1.2, 2.0)),
                (1, DVec3::new(-0.02, -0.3, -1.0), DVec3::new(0.02, 0.3, 0.0)),
            ],
        );
        let moved = check(&scene, 1);
        assert!(moved > 0.3, "side {side}: {moved}");
    }
}

#[test]
fn without_a_door_just_an_orbit() {
    let scene = crate::common::box_scene();
    let t = demo_default(&scene);
    assert_eq!(t.frames.len(), 48);
    assert!(t.frames.iter().all(|s| s.poses.is_empty()));
    // An empty scene still gets a path (around a unit box).
    assert_eq!(demo_default(&Scene::default()).frames.len(), 48);
}

#[test]
fn demo_car_door_opens_outward() {
    let scene = demo_car(10_000);
    let door = scene.node_by_name(DOOR_NODE).expect("door");
    let moved = check(&scene, door);
    assert!(moved > 0.3, "{moved}");
    // The demo car documents a positive angle about local +Y as opening: check the pose
    // agrees.
    let t = demo_default(&scene);
    let p = t.frames[24].poses.iter().find(|p| p.node == door).unwrap();
    let rest = DMat4::from_cols_array(&scene.geometry.nodes[door as usize].rest);
    let r = rest.inverse() * DMat4::from_cols_array(&p.local);
    // x axis after a positive turn about +Y: (cos, 0, −sin).
    assert!(r.x_axis.z < 0.0, "{:?}", r.x_axis);
}
