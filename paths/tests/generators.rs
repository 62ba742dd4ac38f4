//! `orbit:` and `dolly:` around a hand-built scene.

use glam::{DMat4, DVec3};
use trisort_paths::{load, PathOptions, Timeline};
use trisort_scene::Scene;

use crate::common::{eye_forward, node, scene_with_boxes};

/// A 4 × 2 × 6 box centred at (10, 1, −3): radius √14.
fn offset_box() -> Scene {
    scene_with_boxes(
        vec![node(
            "Box",
            None,
            DMat4::from_translation(DVec3::new(10.0, 1.0, -3.0)),
        )],
        &[(0, DVec3::new(-2.0, -1.0, -3.0), DVec3::new(2.0, 1.0, 3.0))],
    )
}

const CENTRE: DVec3 = DVec3::new(10.0, 1.0, -3.0);

fn gen(spec: &str) -> Timeline {
    load(spec, &offset_box(), &PathOptions { fps: 25.0 }).unwrap_or_else(|e| panic!("{e}"))
}

/// The corners of the box, world space.
fn corners() -> Vec<DVec3> {
    (0..8)
        .map(|i| {
            CENTRE
                + DVec3::new(
                    if i & 1 == 0 { -2.0 } else { 2.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -3.0 } else { 3.0 },
                )
        })
        .collect()
}

/// Every corner of the box lies between the clip planes and, with `framed`, inside the
/// vertical field of view of every frame.
fn assert_box_in_view(t: &Timeline, framed: bool) {
    for (f, s) in t.frames.iter().enumerate() {
        let c = &s.camera;
        let far = c.zfar.expect("generated paths have a finite far plane");
        for p in corners() {
            let v = c.view_matrix().transform_point3(p);
            let depth = -v.z;
            assert!(depth > c.znear && depth < far, "frame {f}: {depth}");
            assert!(
                !framed || (v.y / depth).abs() < (c.yfov * 0.5).tan(),
                "frame {f}"
            );
        }
    }
}

#[test]
fn orbit_frames_distance_and_aim() {
    let t = gen("orbit:frames=36,elevation=30,distance=3");
    assert_eq!(t.frames.len(), 36);
    assert_eq!(t.fps, 25.0);
    let radius = 14f64.sqrt();
    for f in 0..36 {
        let (eye, fwd) = eye_forward(&t, f);
        assert!(
            ((eye - CENTRE).length() - 3.0 * radius).abs() < 1e-9,
            "frame {f}"
        );
        // Looks at the centre.
        assert!(
            ((CENTRE - eye).normalize() - fwd).length() < 1e-9,
            "frame {f}"
        );
        // 30° above the centre.
        let elevation = ((eye.y - CENTRE.y) / (eye - CENTRE).length()).asin();
        assert!((elevation.to_degrees() - 30.0).abs() < 1e-9);
        // Upright: the camera's right vector is horizontal.
        let right = t.frames[f].camera.view_matrix().inverse().x_axis.truncate();
        assert!(right.y.abs() < 1e-9);
        assert!(t.frames[f].poses.is_empty());
    }
    assert_box_in_view(&t, true);
    // Default: 48 frames, the box in view.
    let d = gen("orbit");
    assert_eq!(d.frames.len(), 48);
    assert_box_in_view(&d, true);
    assert_eq!(d, gen("orbit:"));
}

#[test]
fn a_full_orbit_turns_the_camera_around() {
    let t = gen("orbit:frames=24,degrees=360,elevation=0");
    let az = |f: usize| {
        let (eye, _) = eye_forward(&t, f);
        (eye.x - CENTRE.x).atan2(eye.z - CENTRE.z)
    };
    // Frame 0 on the +Z side, frame 6 on +X, 12 on −Z, 18 on −X: 15° steps, no repeat of
    // frame 0 at the end.
    for (f, dir) in [
        (0, DVec3::Z),
        (6, DVec3::X),
        (12, DVec3::NEG_Z),
        (18, DVec3::NEG_X),
    ] {
        let (eye, fwd) = eye_forward(&t, f);
        assert!(
            ((eye - CENTRE).normalize() - dir).length() < 1e-9,
            "frame {f}"
        );
        assert!(
            (fwd + dir).length() < 1e-9,
            "frame {f} looks back at the centre"
        );
    }
    let mut total = 0.0;
    for f in 0..24 {
        let mut d = az((f + 1) % 24) - az(f);
        if d < -std::f64::consts::PI {
            d += std::f64::consts::TAU;
        }
        assert!(
            (d.to_degrees() - 15.0).abs() < 1e-9,
            "frame {f}: {}",
            d.to_degrees()
        );
        total += d;
    }
    assert!((total.to_degrees() - 360.0).abs() < 1e-6);
    // The view directions of opposite frames are opposite.
    let (_, a) = eye_forward(&t, 3);
    let (_, b) = eye_forward(&t, 15);
    assert!((a + b).length() < 1e-9);
}

#[test]
fn partial_and_reversed_orbits_end_on_the_sweep() {
    let t = gen("orbit:frames=5,degrees=-90,start=90,elevation=0");
    let (first, _) = eye_forward(&t, 0);
    let (last, _) = eye_forward(&t, 4);
    assert!(((first - CENTRE).normalize() - DVec3::X).length() < 1e-9);
    assert!(((last - CENTRE).normalize() - DVec3::Z).length() < 1e-9);
    let one = gen("orbit:frames=1,degrees=45");
    assert_eq!(one.frames.len(), 1);
}

#[test]
fn dolly_moves_straight_and_looks_at_the_centre() {
    let t = gen("dolly:frames=11,from=10;3;20,to=10:2:5,fov=30");
    assert_eq!(t.frames.len(), 11);
    let from = DVec3::new(10.0, 3.0, 20.0);
    let to = DVec3::new(10.0, 2.0, 5.0);
    for f in 0..11 {
        let (eye, fwd) = eye_forward(&t, f);
        let expected = from.lerp(to, f as f64 / 10.0);
        assert!((eye - expected).length() < 1e-9, "frame {f}: {eye:?}");
        assert!(((CENTRE - eye).normalize() - fwd).length() < 1e-9);
        assert!((t.frames[f].camera.yfov.to_degrees() - 30.0).abs() < 1e-12);
    }
    // Clip planes: the nearest eye (`to`, at z = 5) is 5 from the box's +Z face at z = 0.
    let c = t.frames[0].camera;
    assert!((c.znear - 0.25 * DVec3::new(0.0, 0.0, 5.0).length()).abs() < 1e-9);
    assert!(t.frames.iter().all(|s| s.camera.znear == c.znear));
    // The default dolly ends close in: the box is within the clip planes, not framed.
    assert_box_in_view(&gen("dolly"), false);
}
