//! Paths over the shared real scenes: CesiumMilkTruck's own animation (`gltf`) and the car
//! tour over CarConcept. Each test skips (printing why) when its scene is missing, unless
//! `TRISORT_REQUIRE_SCENES=1`.

use std::path::Path;

use glam::{DMat4, DQuat, DVec3, Vec3};
use trisort_format::world_transforms;
use trisort_paths::{load, PathOptions, Timeline};
use trisort_scene::Scene;
use trisort_testkit::scene_path;

use crate::common::eye_forward;

fn import(rel: &str) -> Option<Scene> {
    let path = scene_path(rel)?;
    Some(trisort_scene::load(&path).unwrap_or_else(|e| panic!("{e}")))
}

/// A node's local transform at a frame: its pose, or its rest transform.
fn local(scene: &Scene, t: &Timeline, f: usize, node: u32) -> DMat4 {
    let m = t.frames[f]
        .poses
        .iter()
        .find(|p| p.node == node)
        .map_or(scene.geometry.nodes[node as usize].rest, |p| p.local);
    DMat4::from_cols_array(&m)
}

/// Signed rotation angle (radians) from local transform `a` to `b` about the unit `axis`.
fn signed_step(a: DMat4, b: DMat4, axis: DVec3) -> f64 {
    let (_, qa, _) = a.to_scale_rotation_translation();
    let (_, qb, _) = b.to_scale_rotation_translation();
    let d = qb * qa.inverse();
    let (ax, angle) = d.to_axis_angle();
    let angle = if angle > std::f64::consts::PI {
        angle - std::f64::consts::TAU
    } else {
        angle
    };
    angle * ax.dot(axis).signum()
}

#[test]
fn cesium_milk_truck_wheels_turn_and_loop() {
    let Some(scene) = import("CesiumMilkTruck/CesiumMilkTruck.glb") else {
        return;
    };
    let wheels: Vec<u32> = ["Wheels", "Wheels.001"]
        .iter()
        .map(|n| scene.node_by_name(n).expect("wheel node"))
        .collect();
    // 24 fps puts every frame on a key of the 1.25 s, 31-key animation.
    let t = load("gltf", &scene, &PathOptions { fps: 24.0 }).expect("gltf path");
    assert_eq!(t.frames.len(), 31, "0 ..= 1.25 s at 24 fps");
    assert_eq!(t.fps, 24.0);
    // Only the wheels move. (Frame 0 is their rest rotation up to the file's f32 rounding:
    // its key and the node's rest quaternion differ by ~1e-8, so it lists them too.)
    for s in &t.frames {
        let nodes: Vec<u32> = s.poses.iter().map(|p| p.node).collect();
        let mut expected = wheels.clone();
        expected.sort();
        assert_eq!(nodes, expected);
    }
    // No camera in the file: one fixed framing camera for every frame.
    assert!(t.frames.iter().all(|s| s.camera == t.frames[0].camera));
    assert!((t.frames[0].camera.yfov.to_degrees() - 45.0).abs() < 1e-9);

    for &w in &wheels {
        // The wheel turns about its local Y axis (the axle) by a similar nonzero step every
        // frame, keeping its translation and scale.
        let rest = DMat4::from_cols_array(&scene.geometry.nodes[w as usize].rest);
        let axis = DVec3::Y;
        let steps: Vec<f64> = (0..30)
            .map(|f| signed_step(local(&scene, &t, f, w), local(&scene, &t, f + 1, w), axis))
            .collect();
        for (f, s) in steps.iter().enumerate() {
            assert!(
                s.abs() > 5f64.to_radians() && s.abs() < 20f64.to_radians(),
                "wheel {w} frame {f}: step {}°",
                s.to_degrees()
            );
            let m = local(&scene, &t, f + 1, w);
            assert!((m.w_axis - rest.w_axis).length() < 1e-6);
            let (scale, q, _) = m.to_scale_rotation_translation();
            assert!((scale - DVec3::ONE).length() < 1e-6);
            let (ax, angle) = q.to_axis_angle();
            assert!(angle < 1e-6 || ax.cross(axis).length() < 1e-4, "{ax:?}");
        }
        assert!(steps.windows(2).all(|w| w[0].signum() == w[1].signum()));
        // The loop closes: the steps and the wrap from the last frame (t = 1.25 s) back to
        // frame 0 (t = 0, the start of the next loop) add up to exactly one turn, and the wrap
        // is a step like the others, so the wheel repeats every 1.25 s without a jump.
        let wrap = signed_step(local(&scene, &t, 30, w), local(&scene, &t, 0, w), axis);
        let total: f64 = steps.iter().sum::<f64>() + wrap;
        assert!(
            (total.abs() - std::f64::consts::TAU).abs() < 1e-4,
            "{}°",
            total.to_degrees()
        );
        let mean = steps.iter().sum::<f64>() / steps.len() as f64;
        assert!(wrap.signum() == mean.signum() && (wrap / mean - 1.0).abs() < 0.3);
    }
    // Both wheels turn together.
    for f in 0..31 {
        let (_, a, _) = local(&scene, &t, f, wheels[0]).to_scale_rotation_translation();
        let (_, b, _) = local(&scene, &t, f, wheels[1]).to_scale_rotation_translation();
        assert!(a.dot(b).abs() > 1.0 - 1e-9, "frame {f}");
    }
    // Sampling between keys (30 fps: 38 frames) slerps: every frame differs from the next.
    let t30 = load("gltf", &scene, &PathOptions::default()).expect("gltf path");
    assert_eq!(t30.frames.len(), 38);
    for f in 0..37 {
        let a = local(&scene, &t30, f, wheels[0]);
        let b = local(&scene, &t30, f + 1, wheels[0]);
        assert!(
            (a - b).abs().to_cols_array().iter().any(|d| *d > 1e-3),
            "frame {f}"
        );
    }
}

/// The scene's triangles hit by a ray, nearest first: (distance, triangle id).
fn ray_hits(scene: &Scene, t: &Timeline, f: usize, origin: DVec3, dir: DVec3) -> Vec<(f64, u32)> {
    let g = &scene.geometry;
    let world = world_transforms(&g.nodes, &t.frames[f].poses);
    let p = |v: u32| {
        let v = &g.vertices[v as usize];
        world[v.node as usize].transform_point3(Vec3::from(v.position).as_dvec3())
    };
    let mut hits = Vec::new();
    for (id, tri) in g.triangles.iter().enumerate() {
        let (a, b, c) = (p(tri[0]), p(tri[1]), p(tri[2]));
        // Möller–Trumbore.
        let (e1, e2) = (b - a, c - a);
        let h = dir.cross(e2);
        let det = e1.dot(h);
        if det.abs() < 1e-14 {
            continue;
        }
        let s = origin - a;
        let u = s.dot(h) / det;
        let q = s.cross(e1);
        let v = dir.dot(q) / det;
        let dist = e2.dot(q) / det;
        if (0.0..=1.0).contains(&u) && v >= 0.0 && u + v <= 1.0 && dist > 0.0 {
            hits.push((dist, id as u32));
        }
    }
    hits.sort_by(|a, b| a.0.total_cmp(&b.0));
    hits
}

fn node_name(scene: &Scene, tri: u32) -> &str {
    &scene.geometry.nodes[scene.geometry.triangle_node(tri) as usize].name
}

fn material_name(scene: &Scene, tri: u32) -> &str {
    &scene.geometry.materials[scene.geometry.triangle_material(tri) as usize].name
}

/// Centroid of the vertices of `node` and its descendants at a frame, world space.
fn subtree_centroid(scene: &Scene, t: &Timeline, f: usize, node: u32) -> DVec3 {
    let g = &scene.geometry;
    let mut inside = vec![false; g.nodes.len()];
    for (i, n) in g.nodes.iter().enumerate() {
        inside[i] = i == node as usize || n.parent.is_some_and(|p| inside[p as usize]);
    }
    let world = world_transforms(&g.nodes, &t.frames[f].poses);
    let (mut sum, mut n) = (DVec3::ZERO, 0);
    for v in g.vertices.iter().filter(|v| inside[v.node as usize]) {
        sum += world[v.node as usize].transform_point3(Vec3::from(v.position).as_dvec3());
        n += 1;
    }
    assert!(n > 0);
    sum / n as f64
}

/// The car tour's orbit (frames 0..120) keeps its distance to the car's vertical axis (within
/// 4 cm; the last 5 frames already bend towards the zoom) and turns once.
fn assert_the_tour_orbits_once(t: &Timeline) {
    let axis_point = DVec3::new(0.0, 0.0, 0.23);
    let mut turned = 0.0;
    let mut prev: Option<f64> = None;
    for f in 0..=120 {
        let (eye, _) = eye_forward(t, f);
        let r = ((eye - axis_point) * DVec3::new(1.0, 0.0, 1.0)).length();
        let tolerance = if f <= 115 { 0.04 } else { 0.1 };
        assert!((r - 7.0).abs() < tolerance, "frame {f}: {r}");
        let az = (eye.x - axis_point.x).atan2(eye.z - axis_point.z);
        if let Some(p) = prev {
            let mut d = az - p;
            if d > std::f64::consts::PI {
                d -= std::f64::consts::TAU;
            } else if d < -std::f64::consts::PI {
                d += std::f64::consts::TAU;
            }
            turned += d;
        }
        prev = Some(az);
    }
    assert!((turned - std::f64::consts::TAU).abs() < 1e-3, "{turned}");
}

#[test]
fn car_tour_over_car_concept() {
    let Some(scene) = import("CarConcept/CarConcept.glb") else {
        return;
    };
    let tour = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/car-tour.toml");
    let t = load(
        tour.to_str().expect("utf-8"),
        &scene,
        &PathOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(t.frames.len(), 301, "10 s at 30 fps");
    assert_eq!(t.fps, 30.0);
    let (lo, hi) = scene.bounds().expect("bounds");
    let centre = (lo + hi) * 0.5;

    // The door: its origin is the hinge. In its local frame the door's own panel lies behind
    // the hinge (local +Y, the car's rear in the Z-up authoring frame) and inside its outer
    // skin (local x ≤ ~0), from below to above the hinge height.
    let door = scene.node_by_name("BodyDoorLColor1").expect("door node");
    let g = &scene.geometry;
    let (mut dlo, mut dhi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for v in g.vertices.iter().filter(|v| v.node == door) {
        dlo = dlo.min(Vec3::from(v.position));
        dhi = dhi.max(Vec3::from(v.position));
    }
    assert!(dlo.y > -0.01 && dhi.y > 1.5, "{dlo:?} {dhi:?}");
    assert!(dhi.x < 0.05 && dlo.x > -0.3, "{dlo:?} {dhi:?}");
    assert!(dlo.z < -0.3 && dhi.z > 0.2, "{dlo:?} {dhi:?}");
    // Local −Z (the rotation axis) is world −Y: the hinge is vertical.
    let door_world = world_transforms(&g.nodes, &[])[door as usize];
    let axis = door_world.transform_vector3(DVec3::NEG_Z).normalize();
    assert!((axis - DVec3::NEG_Y).length() < 1e-6, "{axis:?}");

    // It opens and closes: closed (no pose) outside frames 215..285, moving inside, and open
    // it swings away from the car (its centroid moves outward, towards +X here).
    let door_pose = |f: usize| t.frames[f].poses.iter().find(|p| p.node == door);
    assert!(door_pose(0).is_none() && door_pose(215).is_none() && door_pose(285).is_none());
    assert!(door_pose(300).is_none());
    assert!((216..285).all(|f| door_pose(f).is_some()));
    assert_ne!(door_pose(230).unwrap().local, door_pose(245).unwrap().local);
    let closed = subtree_centroid(&scene, &t, 0, door);
    let open = subtree_centroid(&scene, &t, 250, door);
    let outward = (closed - centre) * DVec3::new(1.0, 0.0, 1.0);
    assert!(closed.x > 0.5, "the driver door is on +X: {closed:?}");
    assert!(
        (open - closed).dot(outward.normalize()) > 0.3,
        "{closed:?} → {open:?}"
    );
    // Open at 60°: the local transform is rest · R(−Z, 60°).
    let rest = DMat4::from_cols_array(&g.nodes[door as usize].rest);
    let expected =
        rest * DMat4::from_quat(DQuat::from_axis_angle(DVec3::NEG_Z, 60f64.to_radians()));
    let got = DMat4::from_cols_array(&door_pose(250).unwrap().local);
    assert!((got - expected)
        .abs()
        .to_cols_array()
        .iter()
        .all(|d| *d < 1e-12));
    // The camera sees the open door: its centroid projects inside the view (square image).
    let cam = &t.frames[250].camera;
    let ndc = (cam.projection(1.0) * cam.view_matrix()).project_point3(open);
    assert!(
        ndc.x.abs() < 0.8 && ndc.y.abs() < 0.8 && (0.0..1.0).contains(&ndc.z),
        "{ndc:?}"
    );
    // Nothing else moves.
    assert!(t
        .frames
        .iter()
        .all(|s| s.poses.iter().all(|p| p.node == door)));

    assert_the_tour_orbits_once(&t);

    // The zoom ends looking at the dashboard through the windscreen: the view's centre ray
    // crosses the glass, then meets the interior's dashboard.
    let (eye, fwd) = eye_forward(&t, 180);
    let hits = ray_hits(&scene, &t, 180, eye, fwd);
    let names: Vec<String> = hits
        .iter()
        .take(6)
        .map(|&(d, tri)| {
            format!(
                "{d:.3} {} ({})",
                node_name(&scene, tri),
                material_name(&scene, tri)
            )
        })
        .collect();
    let first_opaque = hits
        .iter()
        .find(|&&(_, tri)| g.materials[g.triangle_material(tri) as usize].transmission == 0.0)
        .expect("the ray hits the car");
    println!("frame 180, centre ray: {names:?}");
    assert!(
        material_name(&scene, hits[0].1) == "Glass",
        "first hit is the windscreen: {names:?}"
    );
    assert!(
        node_name(&scene, first_opaque.1).starts_with("InteriorDash")
            || node_name(&scene, first_opaque.1).starts_with("InteriorSteering"),
        "{names:?}"
    );
    // The yfov narrows for the zoom.
    assert!(t.frames[180].camera.yfov < t.frames[120].camera.yfov);

    // The pan (frames 255..300): the eye stays, the view turns towards the rear.
    let (e255, f255) = eye_forward(&t, 255);
    let (e300, f300) = eye_forward(&t, 300);
    assert!((e255 - e300).length() < 1e-9);
    assert!(f255.angle_between(f300) > 25f64.to_radians());
    assert!(f300.z < f255.z);

    // Derived clip planes: every eye is outside the car's box, farther from it than znear,
    // so the near plane cuts nothing of the car at rest.
    let znear = t.frames[0].camera.znear;
    assert!(znear > 0.0 && znear < 0.5, "{znear}");
    for (f, s) in t.frames.iter().enumerate() {
        assert_eq!(s.camera.znear, znear);
        let (eye, _) = eye_forward(&t, f);
        let outside = (lo - eye).max(eye - hi).max(DVec3::ZERO).length();
        assert!(outside >= znear, "frame {f}: {outside} < {znear}");
    }
}
