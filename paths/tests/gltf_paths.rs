//! The `gltf` path on hand-built scenes: channel composition with the rest pose, the three
//! interpolation modes, animated cameras, the fallbacks without animation or camera, errors.

use glam::{DMat4, DQuat, DVec3};
use trisort_paths::{load, PathOptions, Problem, Timeline};
use trisort_scene::{Animation, Channel, Interpolation, Property, Scene, SceneCamera};

use crate::common::{box_scene, eye_forward, problem};

fn quat_values(qs: &[DQuat]) -> Vec<f32> {
    qs.iter()
        .flat_map(|q| [q.x as f32, q.y as f32, q.z as f32, q.w as f32])
        .collect()
}

/// The box scene with a rest scale and translation on the Lid (node 1), and animations.
fn animated(animations: Vec<Animation>) -> Scene {
    let mut s = box_scene();
    s.geometry.nodes[1].rest =
        DMat4::from_scale_rotation_translation(DVec3::splat(2.0), DQuat::IDENTITY, DVec3::Y)
            .to_cols_array();
    s.animations = animations;
    s
}

fn gltf(scene: &Scene, fps: f64) -> Timeline {
    load("gltf", scene, &PathOptions { fps }).unwrap_or_else(|e| panic!("{e}"))
}

fn lid(t: &Timeline, f: usize) -> DMat4 {
    let p = t.frames[f]
        .poses
        .iter()
        .find(|p| p.node == 1)
        .expect("lid pose");
    DMat4::from_cols_array(&p.local)
}

#[test]
fn linear_rotation_replaces_only_the_rotation() {
    let keys = [
        DQuat::IDENTITY,
        DQuat::from_rotation_y(120f64.to_radians()),
        DQuat::from_rotation_y(240f64.to_radians()),
    ];
    let scene = animated(vec![Animation {
        name: "spin".into(),
        channels: vec![Channel {
            node: 1,
            property: Property::Rotation,
            interpolation: Interpolation::Linear,
            times: vec![0.0, 1.0, 2.0],
            values: quat_values(&keys),
        }],
    }]);
    let t = gltf(&scene, 4.0);
    assert_eq!(t.frames.len(), 9, "0 ..= 2 s at 4 fps");
    for f in 1..9 {
        let (scale, q, tr) = lid(&t, f).to_scale_rotation_translation();
        assert!(
            (scale - DVec3::splat(2.0)).length() < 1e-6,
            "rest scale kept"
        );
        assert!((tr - DVec3::Y).length() < 1e-12, "rest translation kept");
        // Slerp at constant speed: 30° per frame about +Y.
        let expected = DQuat::from_rotation_y((30.0 * f as f64).to_radians());
        assert!(q.dot(expected).abs() > 1.0 - 1e-9, "frame {f}: {q:?}");
    }
    // Frame 0 is the rest pose (identity key, same scale and translation): not listed.
    assert!(t.frames[0].poses.is_empty());
    // No camera: the framing camera, the same every frame, looking at the box centre.
    let (eye, fwd) = eye_forward(&t, 0);
    let (lo, hi) = scene.bounds().unwrap();
    let centre = (lo + hi) * 0.5;
    assert!(((centre - eye).normalize() - fwd).length() < 1e-9);
    assert!(t.frames.iter().all(|s| s.camera == t.frames[0].camera));
}

#[test]
fn step_and_cubic_spline_channels() {
    // Translation by STEP, scale by CUBICSPLINE (in-tangent, value, out-tangent per key).
    let scene = animated(vec![
        Animation {
            name: "step".into(),
            channels: vec![Channel {
                node: 1,
                property: Property::Translation,
                interpolation: Interpolation::Step,
                times: vec![0.0, 0.5],
                values: vec![0.0, 1.0, 0.0, 3.0, 1.0, 0.0],
            }],
        },
        Animation {
            name: "cubic".into(),
            channels: vec![Channel {
                node: 1,
                property: Property::Scale,
                interpolation: Interpolation::CubicSpline,
                times: vec![0.0, 1.0],
                values: vec![
                    0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 2.0, 0.0, 0.0, // key 0
                    0.0, 0.0, 0.0, 3.0, 1.0, 1.0, 0.0, 0.0, 0.0, // key 1
                ],
            }],
        },
    ]);
    // The longest animation (1 s) sets the length: 0 ..= 1 s at 4 fps.
    let t = gltf(&scene, 4.0);
    assert_eq!(t.frames.len(), 5);
    let tx = |f: usize| lid(&t, f).w_axis.x;
    assert_eq!(
        [tx(0), tx(1), tx(2), tx(3), tx(4)],
        [0.0, 0.0, 3.0, 3.0, 3.0]
    );
    // Hermite at s = 0.5 over a 1 s interval: 0.5·1 + 0.125·2 + 0.5·3 − 0.125·0 = 2.25.
    let (scale, _, _) = lid(&t, 2).to_scale_rotation_translation();
    assert!((scale.x - 2.25).abs() < 1e-9, "{scale:?}");
    assert!((scale.y - 1.0).abs() < 1e-9);
    let (scale, _, _) = lid(&t, 4).to_scale_rotation_translation();
    assert!((scale.x - 3.0).abs() < 1e-9);
}

#[test]
fn animated_camera_node_views_through_its_world_transform() {
    // Camera on node 3, a child of the Lid; the Lid is translated by an animation and the
    // camera node carries a scale that must not reach the view.
    let mut scene = box_scene();
    scene.geometry.nodes.push(crate::common::node(
        "Cam",
        Some(1),
        DMat4::from_scale_rotation_translation(
            DVec3::splat(3.0),
            DQuat::from_rotation_y(90f64.to_radians()),
            DVec3::new(0.0, 0.0, 5.0),
        ),
    ));
    scene.cameras.push(SceneCamera {
        name: "cam".into(),
        node: 3,
        yfov: 0.8,
        znear: 0.05,
        zfar: None,
        aspect: Some(1.5),
    });
    scene.animations.push(Animation {
        name: "slide".into(),
        channels: vec![Channel {
            node: 1,
            property: Property::Translation,
            interpolation: Interpolation::Linear,
            times: vec![0.0, 1.0],
            values: vec![0.0, 1.0, 0.0, 10.0, 1.0, 0.0],
        }],
    });
    let t = gltf(&scene, 2.0);
    assert_eq!(t.frames.len(), 3);
    for (f, x) in [(0, 0.0), (1, 5.0), (2, 10.0)] {
        let c = t.frames[f].camera;
        assert_eq!((c.yfov, c.znear, c.zfar), (0.8, 0.05, None));
        let (eye, fwd) = eye_forward(&t, f);
        assert!(
            (eye - DVec3::new(x, 1.0, 5.0)).length() < 1e-9,
            "frame {f}: {eye:?}"
        );
        // −Z of a node turned 90° about +Y is −X.
        assert!((fwd - DVec3::NEG_X).length() < 1e-9, "{fwd:?}");
        // No scale in the view: it is a rigid transform.
        let v = c.view_matrix();
        assert!((v.determinant() - 1.0).abs() < 1e-9);
    }
}

#[test]
fn without_animation_one_frame() {
    let mut scene = box_scene();
    let t = gltf(&scene, 30.0);
    assert_eq!(
        t.frames.len(),
        1,
        "neither animation nor camera: one framing frame"
    );
    assert!(t.frames[0].poses.is_empty());
    scene.cameras.push(SceneCamera {
        name: String::new(),
        node: 0,
        yfov: 1.0,
        znear: 0.1,
        zfar: Some(100.0),
        aspect: None,
    });
    let t = gltf(&scene, 30.0);
    assert_eq!(t.frames.len(), 1, "a camera without animation: one frame");
    assert_eq!(t.frames[0].camera.view, DMat4::IDENTITY.to_cols_array());
}

#[test]
fn bad_scenes_and_options() {
    let channel = |node, times: Vec<f32>, values: Vec<f32>| Animation {
        name: "bad".into(),
        channels: vec![Channel {
            node,
            property: Property::Translation,
            interpolation: Interpolation::Linear,
            times,
            values,
        }],
    };
    for (scene, what) in [
        (
            animated(vec![channel(9, vec![0.0], vec![0.0; 3])]),
            "missing node",
        ),
        (
            animated(vec![channel(1, vec![0.0, 1.0], vec![0.0; 3])]),
            "few values",
        ),
        (
            animated(vec![channel(1, vec![1.0, 0.0], vec![0.0; 6])]),
            "descending",
        ),
        (
            animated(vec![channel(1, vec![0.0], vec![f32::NAN; 3])]),
            "NaN value",
        ),
        (
            animated(vec![channel(1, vec![0.0, 1e9], vec![0.0; 6])]),
            "too long",
        ),
    ] {
        let (p, line, msg) = problem(load("gltf", &scene, &PathOptions::default()));
        assert!(matches!(p, Problem::Inconsistent(_)), "{what}: {p:?}");
        assert_eq!(line, None);
        assert!(msg.contains("gltf path of scene"), "{msg}");
    }
    let mut cam = box_scene();
    cam.cameras.push(SceneCamera {
        name: String::new(),
        node: 0,
        yfov: 1.0,
        znear: 0.0,
        zfar: None,
        aspect: None,
    });
    let (p, _, _) = problem(load("gltf", &cam, &PathOptions::default()));
    assert_eq!(
        p,
        Problem::ClipPlanes {
            znear: 0.0,
            zfar: None
        }
    );
    cam.cameras[0].znear = 0.1;
    cam.cameras[0].yfov = std::f64::consts::PI;
    let (p, _, _) = problem(load("gltf", &cam, &PathOptions::default()));
    assert!(matches!(p, Problem::FovOutOfRange { .. }), "{p:?}");
    let (p, _, _) = problem(load("gltf", &box_scene(), &PathOptions { fps: f64::NAN }));
    assert!(matches!(p, Problem::NonFinite { .. }), "{p:?}");
    let (p, _, _) = problem(load("gltf", &box_scene(), &PathOptions { fps: -1.0 }));
    assert!(matches!(p, Problem::BadParameter { .. }), "{p:?}");
    // No camera and no triangles: nothing to frame.
    let (p, _, _) = problem(load("gltf", &Scene::default(), &PathOptions::default()));
    assert_eq!(p, Problem::EmptyScene);
}

#[test]
fn zero_scale_rest_node_can_be_animated() {
    // A node hidden by a zero rest scale (a common glTF idiom) that an animation moves: its
    // rest rotation cannot be recovered, which must not turn into NaN.
    let mut scene = animated(vec![Animation {
        name: "move".into(),
        channels: vec![Channel {
            node: 1,
            property: Property::Translation,
            interpolation: Interpolation::Linear,
            times: vec![0.0, 1.0],
            values: vec![0.0, 1.0, 0.0, 0.0, 2.0, 0.0],
        }],
    }]);
    scene.geometry.nodes[1].rest = DMat4::from_scale(DVec3::ZERO).to_cols_array();
    let t = gltf(&scene, 2.0);
    let m = lid(&t, 2);
    assert!(m.to_cols_array().iter().all(|x| x.is_finite()));
    assert_eq!(m.w_axis.truncate(), DVec3::new(0.0, 2.0, 0.0));
    assert_eq!(m.transform_vector3(DVec3::ONE), DVec3::ZERO, "still hidden");
}

/// `gltf:animation=NAME,camera=NAME`: one animation plays (others keep
/// their nodes at rest) and its length decides the frames; the named camera views; unknown
/// names and parameters are errors listing what the scene has.
#[test]
fn gltf_path_selects_an_animation_and_a_camera_by_name() {
    let slide = |name: &str, node, to: f32, seconds: f32| Animation {
        name: name.into(),
        channels: vec![Channel {
            node,
            property: Property::Translation,
            interpolation: Interpolation::Linear,
            times: vec![0.0, seconds],
            values: vec![0.0, 1.0, 0.0, to, 1.0, 0.0],
        }],
    };
    let mut scene = animated(vec![
        slide("short", 1, 10.0, 1.0),
        slide("long", 2, -4.0, 3.0),
    ]);
    for (name, node, z) in [("front", 0, 5.0), ("back", 0, -5.0)] {
        scene.geometry.nodes.push(crate::common::node(
            name,
            Some(node),
            DMat4::from_rotation_translation(
                DQuat::from_rotation_y(if z > 0.0 { 0.0 } else { 180f64.to_radians() }),
                DVec3::new(0.0, 0.0, z),
            ),
        ));
        scene.cameras.push(SceneCamera {
            name: name.into(),
            node: scene.geometry.nodes.len() as u32 - 1,
            yfov: 0.8,
            znear: 0.05,
            zfar: None,
            aspect: None,
        });
    }
    let opts = PathOptions { fps: 2.0 };
    let all = load("gltf", &scene, &opts).unwrap();
    assert_eq!(all.frames.len(), 7, "both animations: the longer one's 3 s");
    assert!(all.frames[6].poses.iter().any(|p| p.node == 1));
    assert!(all.frames[6].poses.iter().any(|p| p.node == 2));

    let short = load("gltf:animation=short", &scene, &opts).unwrap();
    assert_eq!(short.frames.len(), 3, "1 s at 2 fps");
    assert!(short
        .frames
        .iter()
        .all(|f| f.poses.iter().all(|p| p.node == 1)));
    assert_eq!(lid(&short, 2).w_axis.x, 10.0);
    // The first camera by default, the named one when asked for.
    assert_eq!(eye_forward(&short, 0).0.z, 5.0);
    let back = load("gltf:camera=back,animation=long", &scene, &opts).unwrap();
    assert_eq!(back.frames.len(), 7);
    let (eye, forward) = eye_forward(&back, 0);
    assert!((eye.z + 5.0).abs() < 1e-9 && (forward - DVec3::Z).length() < 1e-9);
    assert!(back
        .frames
        .iter()
        .all(|f| f.poses.iter().all(|p| p.node == 2)));

    for (spec, says) in [
        (
            "gltf:animation=drive",
            "no animation named \"drive\" (its animations: \"short\", \"long\")",
        ),
        (
            "gltf:camera=top",
            "no camera named \"top\" (its cameras: \"front\", \"back\")",
        ),
        (
            "gltf:speed=3",
            "unknown parameter (known: animation, camera)",
        ),
        ("gltf:camera=front,camera=back", "given twice"),
        ("gltf:animation=", "empty name"),
    ] {
        let (p, _, text) = problem(load(spec, &scene, &opts));
        assert!(matches!(p, Problem::BadParameter { .. }), "{spec}: {text}");
        assert!(text.contains(says), "{spec}: {text}");
    }
    let (_, _, text) = problem(load("gltf:camera=x", &box_scene(), &opts));
    assert!(text.contains("(its cameras: none)"), "{text}");
}
