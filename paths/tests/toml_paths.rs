//! TOML keyframe paths that load: key values, interpolation modes, pivots, frame counts,
//! clip planes.

use glam::{DMat4, DVec3};
use trisort_paths::Timeline;

use crate::common::{box_scene, eye_forward, load_toml};

fn path(mode: &str) -> String {
    format!(
        r#"
fps = 30
interpolation = "{mode}"

[camera]
[[camera.key]]
frame = 0
eye = [0.3, 1.0, 10.0]
target = [0.0, 0.25, 0.0]
yfov = 40
[[camera.key]]
frame = 10
eye = [10.0, 2.0, 0.1]
target = [0.1, 0.5, 0.0]
yfov = 60
[[camera.key]]
time = 0.8333333333333334  # frame 25
eye = [0.7, 3.0, -10.0]
target = [0.0, 0.7, 0.2]
yfov = 50.5

[[node]]
name = "Lid"
axis = [1, 0, 0]
pivot = [0, 0.05, -0.5]
key = [
  {{ frame = 0, angle = 0 }},
  {{ frame = 10, angle = 70 }},
  {{ frame = 25, angle = 20 }},
]
"#
    )
}

fn load_mode(mode: &str) -> Timeline {
    let (t, _file) = load_toml(&path(mode), &box_scene());
    t.unwrap_or_else(|e| panic!("{mode}: {e}"))
}

/// A key's values: (frame, eye, target, yfov degrees, lid angle degrees).
type Key = (usize, [f64; 3], [f64; 3], f64, f64);

const KEYS: [Key; 3] = [
    (0, [0.3, 1.0, 10.0], [0.0, 0.25, 0.0], 40.0, 0.0),
    (10, [10.0, 2.0, 0.1], [0.1, 0.5, 0.0], 60.0, 70.0),
    (25, [0.7, 3.0, -10.0], [0.0, 0.7, 0.2], 50.5, 20.0),
];

/// The Lid's local transform for an angle, built independently of the crate: rotate about
/// the X axis through the pivot (0, 0.05, −0.5), then apply rest (a +1 Y translation).
fn lid_local(angle_degrees: f64, p: DVec3) -> DVec3 {
    let pivot = DVec3::new(0.0, 0.05, -0.5);
    let r = DMat4::from_rotation_x(angle_degrees.to_radians());
    pivot + r.transform_vector3(p - pivot) + DVec3::new(0.0, 1.0, 0.0)
}

#[test]
fn every_mode_hits_the_key_values_exactly() {
    for mode in ["linear", "catmull-rom", "ease-in-out", "step"] {
        let t = load_mode(mode);
        assert_eq!(t.frames.len(), 26, "{mode}: frames 0..=25");
        assert_eq!(t.fps, 30.0);
        for (f, eye, target, yfov, _) in KEYS {
            let cam = &t.frames[f].camera;
            let expected =
                DMat4::look_at_rh(DVec3::from(eye), DVec3::from(target), DVec3::Y).to_cols_array();
            assert_eq!(cam.view, expected, "{mode} frame {f}");
            assert_eq!(cam.yfov, yfov.to_radians(), "{mode} frame {f}");
        }
    }
}

#[test]
fn pivot_rotation_moves_points_about_the_pivot() {
    let t = load_mode("linear");
    let lid = 1u32;
    // Frame 0: angle 0, the rest pose: no pose listed.
    assert!(t.frames[0].poses.is_empty(), "{:?}", t.frames[0].poses);
    for (f, _, _, _, angle) in KEYS.into_iter().skip(1) {
        let poses = &t.frames[f].poses;
        assert_eq!(poses.len(), 1, "frame {f}");
        assert_eq!(poses[0].node, lid);
        let m = DMat4::from_cols_array(&poses[0].local);
        for p in [
            DVec3::new(0.0, 0.05, -0.5), // on the axis: only rest moves it
            DVec3::new(0.5, 0.1, 0.5),
            DVec3::new(-0.5, 0.0, 0.5),
        ] {
            let got = m.transform_point3(p);
            let want = lid_local(angle, p);
            assert!(
                (got - want).length() < 1e-12,
                "frame {f}: {got:?} vs {want:?}"
            );
        }
    }
    // The sense, spelled out: a right-handed 70° turn about +X sends the point 1 along +Z of
    // the pivot to (0, −sin 70°, cos 70°) of it, then rest lifts it by 1.
    let m = DMat4::from_cols_array(&t.frames[10].poses[0].local);
    let far_edge = m.transform_point3(DVec3::new(0.0, 0.05, 0.5));
    let (s, c) = 70f64.to_radians().sin_cos();
    let want = DVec3::new(0.0, 0.05 - s + 1.0, -0.5 + c);
    assert!((far_edge - want).length() < 1e-12, "{far_edge:?}");
}

#[test]
fn modes_differ_between_keys() {
    let eye = |mode: &str, f: usize| eye_forward(&load_mode(mode), f).0;
    let lin = eye("linear", 3);
    let ease = eye("ease-in-out", 3);
    let step = eye("step", 9);
    let cr = eye("catmull-rom", 3);
    let expected_lin = DVec3::new(0.3, 1.0, 10.0).lerp(DVec3::new(10.0, 2.0, 0.1), 0.3);
    assert!((lin - expected_lin).length() < 1e-9, "{lin:?}");
    // smoothstep(0.3) = 0.216
    let expected_ease = DVec3::new(0.3, 1.0, 10.0).lerp(DVec3::new(10.0, 2.0, 0.1), 0.216);
    assert!((ease - expected_ease).length() < 1e-9, "{ease:?}");
    assert!(
        (step - DVec3::new(0.3, 1.0, 10.0)).length() < 1e-9,
        "{step:?}"
    );
    assert!(
        (cr - lin).length() > 1e-3 && (cr - ease).length() > 1e-3,
        "{cr:?}"
    );
}

#[test]
fn per_track_modes_and_partial_keys() {
    // A pan: the eye is fixed, only the target moves (eased); yfov zooms linearly.
    let text = r#"
interpolation = "step"
[camera]
yfov = 50
up = [0, 1, 0]
interpolation = "ease-in-out"
key = [
  { frame = 0, eye = [0, 1, 8], target = [-2, 0.5, 0] },
  { frame = 4, target = [2, 0.5, 0] },
  { frame = 2, yfov = 30 },
]
"#;
    let (t, _f) = load_toml(text, &box_scene());
    let t = t.expect("loads");
    assert_eq!(t.frames.len(), 5);
    for f in 0..5 {
        let (eye, _) = eye_forward(&t, f);
        assert!(
            (eye - DVec3::new(0.0, 1.0, 8.0)).length() < 1e-9,
            "frame {f}"
        );
    }
    // yfov has one key (30° at frame 2), which its track holds everywhere; the [camera] yfov
    // applies only to a path with no yfov key.
    assert!(t.frames.iter().all(|s| s.camera.yfov == 30f64.to_radians()));
    // Target at frame 2 is halfway (smoothstep(0.5) = 0.5): looking straight at x = 0.
    let (eye, fwd) = eye_forward(&t, 2);
    let hit = eye + fwd * (eye.z / -fwd.z);
    assert!(hit.x.abs() < 1e-9, "{hit:?}");
}

#[test]
fn frame_count_time_keys_and_clip_planes() {
    let text = r#"
fps = 24
frames = 40
[camera]
zfar = "infinite"
[[camera.key]]
time = 0.5
eye = [0, 2, 9]
target = [0, 0.5, 0]
[[node]]
name = "Lid"
key = [{ time = 1.0, translation = [0, 0.5, 0] }, { frame = 0, translation = [0, 0, 0] }]
"#;
    let (t, _f) = load_toml(text, &box_scene());
    let t = t.expect("loads");
    assert_eq!(
        t.frames.len(),
        40,
        "`frames` overrides the last key (frame 24)"
    );
    assert_eq!(t.fps, 24.0);
    let c = t.frames[0].camera;
    assert_eq!(c.zfar, None);
    // Derived znear: a quarter of the eye's distance to the box (eye at z = 9, box to z = 2;
    // eye at y = 2, the lid's top at y = 1.1).
    let d = DVec3::new(0.0, 0.9, 7.0).length();
    assert!((c.znear - 0.25 * d).abs() < 1e-6, "{}", c.znear);
    // Translation: keys out of order are sorted; frame 12 is halfway; frames past 24 hold.
    let lid_y = |f: usize| {
        t.frames[f]
            .poses
            .first()
            .map_or(1.0, |p| DMat4::from_cols_array(&p.local).w_axis.y)
    };
    assert_eq!(lid_y(0), 1.0);
    assert!(t.frames[0].poses.is_empty());
    assert!((lid_y(12) - 1.25).abs() < 1e-12);
    assert_eq!(lid_y(24), 1.5);
    assert_eq!(lid_y(39), 1.5);
    // Derived zfar when not given: beyond the farthest corner.
    let (t2, _f2) = load_toml(&text.replace("zfar = \"infinite\"", ""), &box_scene());
    let far = t2.expect("loads").frames[0].camera.zfar.expect("finite");
    assert!(far > DVec3::new(1.0, 2.0, 11.0).length(), "{far}");
}

#[test]
fn explicit_clip_planes_and_hash() {
    let text = r#"
[camera]
znear = 0.1
zfar = 50
key = [{ frame = 0, eye = [0, 0, 5], target = [0, 0, 0] }, { frame = 3, eye = [1, 0, 5] }]
"#;
    let (a, _fa) = load_toml(text, &box_scene());
    let a = a.expect("loads");
    assert_eq!(a.frames.len(), 4);
    assert!(a
        .frames
        .iter()
        .all(|s| s.camera.znear == 0.1 && s.camera.zfar == Some(50.0)));
    let (b, _fb) = load_toml(text, &box_scene());
    assert_eq!(a.hash(), b.expect("loads").hash());
    let (c, _fc) = load_toml(&text.replace("zfar = 50", "zfar = 51"), &box_scene());
    assert_ne!(a.hash(), c.expect("loads").hash());
}

#[test]
fn inline_and_table_arrays_are_the_same_path() {
    let tables = r#"
[camera]
[[camera.key]]
frame = 0
eye = [0, 1, 6]
target = [0, 0, 0]
[[camera.key]]
frame = 2
eye = [1, 1, 6]
"#;
    let inline = r#"
camera = { key = [{ frame = 0, eye = [0, 1, 6], target = [0, 0, 0] }, { frame = 2, eye = [1, 1, 6] }] }
"#;
    let (a, _fa) = load_toml(tables, &box_scene());
    let (b, _fb) = load_toml(inline, &box_scene());
    assert_eq!(a.expect("tables"), b.expect("inline"));
}

#[test]
fn the_documented_example_loads() {
    // The TOML example of the crate documentation, as written there.
    let lib = include_str!("../src/lib.rs");
    let mut lines = lib.lines().map(|l| l.strip_prefix("//!").unwrap_or(l));
    lines
        .find(|l| l.trim() == "```toml")
        .expect("a TOML example");
    let example: Vec<&str> = lines
        .take_while(|l| l.trim() != "```")
        .map(|l| l.strip_prefix(' ').unwrap_or(l))
        .collect();
    let (t, _f) = load_toml(&example.join("\n"), &box_scene());
    let t = t.unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(t.frames.len(), 121, "frames 0..=120 (the last door key)");
    assert_eq!(t.frames[0].camera.znear, 0.05);
    assert_eq!(t.frames[0].camera.zfar, Some(100.0));
    assert!(t.frames[90].poses.iter().any(|p| p.node == 2));
}
