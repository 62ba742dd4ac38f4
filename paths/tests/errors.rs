//! Every bad input gets its error, located, and nothing panics.

use trisort_paths::{load, PathError, PathOptions, Problem};
use trisort_scene::Scene;

use crate::common::{box_scene, load_toml, problem};

/// A valid camera section to append keys after.
const GOOD_KEY: &str = "[[camera.key]]\nframe = 0\neye = [0, 1, 8]\ntarget = [0, 0.5, 0]\n";

fn toml_problem(text: &str) -> (Problem, Option<usize>, String) {
    let (r, _f) = load_toml(text, &box_scene());
    problem(r)
}

fn spec_problem(spec: &str) -> (Problem, String) {
    let (p, line, msg) = problem(load(spec, &box_scene(), &PathOptions::default()));
    assert_eq!(line, None);
    assert!(msg.starts_with(spec), "{msg}");
    (p, msg)
}

#[test]
fn syntax_errors_name_file_line_and_column() {
    let (r, f) = load_toml("fps = 30\n[camera\neye = 1\n", &box_scene());
    match r {
        Err(PathError::Syntax {
            path, line, column, ..
        }) => {
            assert_eq!(path, f.path());
            assert_eq!(line, 2);
            assert!(column >= 1);
        }
        other => panic!("{other:?}"),
    }
    let (r, f) = load_toml(&format!("{GOOD_KEY}eyes = [1, 2, 3]\n"), &box_scene());
    let e = r.expect_err("unknown key");
    let msg = e.to_string();
    assert!(
        msg.starts_with(&format!("{}:5:", f.path().display())),
        "{msg}"
    );
    assert!(msg.contains("eyes"), "{msg}");
    // Wrong types and unknown interpolation modes are syntax errors too.
    let (r, _f) = load_toml(&format!("{GOOD_KEY}yfov = \"wide\"\n"), &box_scene());
    assert!(matches!(r, Err(PathError::Syntax { line: 5, .. })), "{r:?}");
    let (r, _f) = load_toml(
        &format!("interpolation = \"cubic\"\n{GOOD_KEY}"),
        &box_scene(),
    );
    assert!(matches!(r, Err(PathError::Syntax { line: 1, .. })), "{r:?}");
}

#[test]
fn missing_file() {
    let r = load(
        "/nonexistent/path/tour.toml",
        &box_scene(),
        &PathOptions::default(),
    );
    match r {
        Err(e @ PathError::Read { .. }) => assert!(e.to_string().contains("tour.toml")),
        other => panic!("{other:?}"),
    }
}

#[test]
fn zero_frames() {
    let (p, line, msg) = toml_problem(&format!("frames = 0\n{GOOD_KEY}"));
    assert_eq!((p, line), (Problem::ZeroFrames, Some(1)));
    assert!(msg.contains(".toml:1:"), "{msg}");
    let (p, line, _) = toml_problem(&format!("frames = -4\n{GOOD_KEY}"));
    assert_eq!((p, line), (Problem::ZeroFrames, Some(1)));
    assert_eq!(spec_problem("orbit:frames=0").0, Problem::ZeroFrames);
    assert_eq!(spec_problem("dolly:frames=0").0, Problem::ZeroFrames);
    // A file without any key has no frame either: it is told that it needs camera keys.
    let (p, _, _) = toml_problem("fps = 30\n");
    assert!(matches!(p, Problem::Inconsistent(_)), "{p:?}");
}

#[test]
fn nan_and_infinite_values() {
    for (text, line) in [
        (format!("{GOOD_KEY}[[camera.key]]\nframe = 3\neye = [nan, 0, 0]\n"), 7),
        (format!("{GOOD_KEY}[[camera.key]]\nframe = 3\ntarget = [0, inf, 0]\n"), 7),
        (format!("{GOOD_KEY}[[camera.key]]\nframe = 3\nyfov = nan\n"), 7),
        (format!("{GOOD_KEY}[[camera.key]]\nframe = inf\nyfov = 30\n"), 6),
        (format!("{GOOD_KEY}[[camera.key]]\ntime = -inf\nyfov = 30\n"), 6),
        (format!("fps = inf\n{GOOD_KEY}"), 1),
        (format!("[camera]\nznear = nan\n{GOOD_KEY}"), 2),
        (format!("[camera]\nzfar = inf\n{GOOD_KEY}"), 2),
        (format!("[camera]\nup = [0, -inf, 0]\n{GOOD_KEY}"), 2),
        (
            format!("{GOOD_KEY}[[node]]\nname = \"Lid\"\naxis = [1, 0, 0]\nkey = [{{ frame = 1, angle = nan }}]\n"),
            8,
        ),
        (
            format!("{GOOD_KEY}[[node]]\nname = \"Lid\"\npivot = [0, nan, 0]\nkey = [{{ frame = 1, translation = [0, 1, 0] }}]\n"),
            7,
        ),
    ] {
        let (p, l, msg) = toml_problem(&text);
        assert!(matches!(p, Problem::NonFinite { .. }), "{text}: {p:?}");
        assert_eq!(l, Some(line), "{text}: {msg}");
    }
    for spec in [
        "orbit:distance=inf",
        "orbit:degrees=NaN",
        "orbit:elevation=-inf",
        "dolly:from=0;nan;5",
        "dolly:to=1:2:infinity",
    ] {
        assert!(
            matches!(spec_problem(spec).0, Problem::NonFinite { .. }),
            "{spec}"
        );
    }
}

#[test]
fn up_parallel_to_the_view_direction() {
    // Looking straight down with the default +Y up: at the key's line.
    let (p, line, msg) =
        toml_problem("[camera]\n[[camera.key]]\nframe = 0\neye = [0, 9, 0]\ntarget = [0, 0, 0]\n");
    assert_eq!(p, Problem::UpParallel { frame: 0 });
    assert_eq!(line, Some(2), "{msg}");
    // An explicit up along the view direction, and a zero up.
    let (p, _, _) = toml_problem(&format!("{GOOD_KEY}up = [0, -0.5, -8]\n"));
    assert_eq!(p, Problem::UpParallel { frame: 0 });
    let (p, _, _) = toml_problem(&format!("{GOOD_KEY}up = [0, 0, 0]\n"));
    assert_eq!(p, Problem::UpParallel { frame: 0 });
    // Between keys: the eye passes over the target; the error names the frame, no line.
    let (p, line, msg) = toml_problem(
        "[camera]\nkey = [{ frame = 0, eye = [-4, 5, 0], target = [0, 0, 0] }, { frame = 8, eye = [4, 5, 0] }]\n",
    );
    assert_eq!((p, line), (Problem::UpParallel { frame: 4 }, None), "{msg}");
    assert!(msg.contains("frame 4"), "{msg}");
    // Generators: an orbit at ±90° elevation, a dolly from straight above.
    assert!(matches!(
        spec_problem("orbit:elevation=90").0,
        Problem::BadParameter { .. }
    ));
    assert!(matches!(
        spec_problem("orbit:elevation=-95").0,
        Problem::BadParameter { .. }
    ));
    assert_eq!(
        spec_problem("dolly:frames=3,from=0;9;0,to=0;9;5").0,
        Problem::UpParallel { frame: 0 }
    );
}

#[test]
fn field_of_view_outside_0_180() {
    for (fov, bad) in [("0", 0.0), ("180", 180.0), ("200.5", 200.5), ("-10", -10.0)] {
        let (p, line, _) = toml_problem(&format!("{GOOD_KEY}yfov = {fov}\n"));
        assert_eq!(p, Problem::FovOutOfRange { degrees: bad }, "{fov}");
        assert_eq!(line, Some(5));
        let (p, line, _) = toml_problem(&format!("[camera]\nyfov = {fov}\n{GOOD_KEY}"));
        assert_eq!(p, Problem::FovOutOfRange { degrees: bad }, "{fov}");
        assert_eq!(line, Some(2));
        assert_eq!(
            spec_problem(&format!("orbit:fov={fov}")).0,
            Problem::FovOutOfRange { degrees: bad }
        );
        assert_eq!(
            spec_problem(&format!("dolly:fov={fov}")).0,
            Problem::FovOutOfRange { degrees: bad }
        );
    }
    // 179.9 is fine.
    let (r, _f) = load_toml(&format!("{GOOD_KEY}yfov = 179.9\n"), &box_scene());
    assert!(r.is_ok());
}

#[test]
fn clip_planes() {
    for (planes, znear, zfar) in [
        ("znear = 0\nzfar = 10", 0.0, Some(10.0)),
        ("znear = -0.5", -0.5, None),
        ("znear = 2\nzfar = 1", 2.0, Some(1.0)),
        ("znear = 1\nzfar = 1", 1.0, Some(1.0)),
        ("znear = -1\nzfar = \"infinite\"", -1.0, None),
    ] {
        let (p, line, msg) = toml_problem(&format!("[camera]\n{planes}\n{GOOD_KEY}"));
        match p {
            Problem::ClipPlanes { znear: n, zfar: f } => {
                assert_eq!(n, znear, "{planes}");
                if zfar.is_some() {
                    assert_eq!(f, zfar, "{planes}");
                }
            }
            other => panic!("{planes}: {other:?}"),
        }
        assert_eq!(line, Some(2), "{msg}");
    }
    // zfar below the derived znear.
    let (p, _, _) = toml_problem(&format!("[camera]\nzfar = 0.001\n{GOOD_KEY}"));
    assert!(matches!(p, Problem::ClipPlanes { .. }), "{p:?}");
    let (p, _, _) = toml_problem(&format!("[camera]\nzfar = \"far\"\n{GOOD_KEY}"));
    assert!(matches!(p, Problem::Inconsistent(_)), "{p:?}");
}

#[test]
fn unknown_node_names_suggest_close_ones() {
    let text = format!(
        "{GOOD_KEY}[[node]]\nname = \"BodyDoorLColour1\"\naxis = [0, 1, 0]\nkey = [{{ frame = 1, angle = 30 }}]\n"
    );
    let (p, line, msg) = toml_problem(&text);
    assert_eq!(
        p,
        Problem::UnknownNode {
            name: "BodyDoorLColour1".into(),
            similar: vec!["BodyDoorLColor1".into()],
        }
    );
    assert_eq!(line, Some(6));
    assert!(
        msg.contains("\"BodyDoorLColour1\"") && msg.contains("similar names: \"BodyDoorLColor1\""),
        "{msg}"
    );
    let (p, _, _) = toml_problem(&text.replace("BodyDoorLColour1", "lid"));
    assert_eq!(
        p,
        Problem::UnknownNode {
            name: "lid".into(),
            similar: vec!["Lid".into()],
        }
    );
}

#[test]
fn eye_at_target() {
    let (p, line, _) =
        toml_problem("[camera]\n[[camera.key]]\nframe = 0\neye = [1, 2, 3]\ntarget = [1, 2, 3]\n");
    assert_eq!((p, line), (Problem::EyeAtTarget { frame: 0 }, Some(2)));
    // Passing through the target between keys.
    let (p, line, _) = toml_problem(
        "[camera]\nkey = [{ frame = 0, eye = [-5, 0, 0], target = [0, 0, 0] }, { frame = 10, eye = [5, 0, 0] }]\n",
    );
    assert_eq!((p, line), (Problem::EyeAtTarget { frame: 5 }, None));
    // A dolly through the centre of a cube around the origin.
    let cube = crate::common::scene_with_boxes(
        vec![crate::common::node("Cube", None, glam::DMat4::IDENTITY)],
        &[(0, glam::DVec3::splat(-1.0), glam::DVec3::splat(1.0))],
    );
    let spec = "dolly:from=0;0;5,to=0;0;-5,frames=3";
    let (p, line, msg) = problem(load(spec, &cube, &PathOptions::default()));
    assert_eq!((p, line), (Problem::EyeAtTarget { frame: 1 }, None));
    assert!(msg.starts_with(spec), "{msg}");
}

#[test]
fn bad_generator_parameters() {
    for spec in [
        "orbit:frames=-3",
        "orbit:frames=2.5",
        "orbit:frames=many",
        "orbit:distance=0",
        "orbit:distance=-2",
        "orbit:wobble=3",
        "orbit:degrees=abc",
        "orbit:frames=3,frames=4",
        "orbit:frames",
        "orbit:frames=99999999",
        "dolly:from=1;2",
        "dolly:to=1;2;3;4",
        "dolly:from=1,2,3",
        "dolly:degrees=30",
    ] {
        let (p, msg) = spec_problem(spec);
        assert!(matches!(p, Problem::BadParameter { .. }), "{spec}: {p:?}");
        assert!(msg.contains("parameter"), "{msg}");
    }
    let (p, _) = spec_problem("spiral:frames=3");
    assert_eq!(
        p,
        Problem::UnknownGenerator {
            name: "spiral".into()
        }
    );
    // A scene without triangles has nothing to orbit.
    let (p, _, _) = problem(load("orbit:", &Scene::default(), &PathOptions::default()));
    assert_eq!(p, Problem::EmptyScene);
    // fps must be positive and finite.
    let (p, _, _) = problem(load("orbit", &box_scene(), &PathOptions { fps: 0.0 }));
    assert!(matches!(p, Problem::BadParameter { .. }), "{p:?}");
}

#[test]
fn inconsistent_keys_and_tracks() {
    let cases = [
        // Both frame and time; neither.
        ("[camera]\n[[camera.key]]\nframe = 0\ntime = 0.0\neye = [0, 1, 8]\ntarget = [0, 0, 0]\n", 2),
        ("[camera]\n[[camera.key]]\neye = [0, 1, 8]\ntarget = [0, 0, 0]\n", 2),
        // Negative frame.
        ("[camera]\n[[camera.key]]\nframe = -1\neye = [0, 1, 8]\ntarget = [0, 0, 0]\n", 3),
        // Beyond the frame limit.
        ("[camera]\n[[camera.key]]\ntime = 1e9\neye = [0, 1, 8]\ntarget = [0, 0, 0]\n", 3),
        // Two eye keys at one frame (time 0 is frame 0).
        ("[camera]\nkey = [{ frame = 0, eye = [0, 1, 8], target = [0, 0, 0] },\n { time = 0.0, eye = [1, 1, 8] }]\n", 3),
        // A key that sets nothing.
        ("[camera]\nkey = [{ frame = 0, eye = [0, 1, 8], target = [0, 0, 0] }, { frame = 2 }]\n", 2),
        // No target at all: at the first key.
        ("[camera]\nkey = [{ frame = 0, eye = [0, 1, 8] }]\n", 2),
        // fps zero.
        ("fps = 0\n[camera]\nkey = [{ frame = 0, eye = [0, 1, 8], target = [0, 0, 0] }]\n", 1),
    ];
    for (text, line) in cases {
        let (p, l, msg) = toml_problem(text);
        assert!(matches!(p, Problem::Inconsistent(_)), "{text}: {p:?}");
        assert_eq!(l, Some(line), "{text}: {msg}");
    }
    let node_cases = [
        // Angle without axis; zero axis; no keys; a key with neither angle nor translation;
        // two tracks for one node.
        "[[node]]\nname = \"Lid\"\nkey = [{ frame = 1, angle = 30 }]\n",
        "[[node]]\nname = \"Lid\"\naxis = [0, 0, 0]\nkey = [{ frame = 1, angle = 30 }]\n",
        "[[node]]\nname = \"Lid\"\naxis = [0, 1, 0]\n",
        "[[node]]\nname = \"Lid\"\naxis = [0, 1, 0]\nkey = [{ frame = 1 }]\n",
        "[[node]]\nname = \"Lid\"\nkey = [{ frame = 1, translation = [0, 1, 0] }]\n[[node]]\nname = \"Lid\"\nkey = [{ frame = 2, translation = [0, 1, 0] }]\n",
    ];
    for nodes in node_cases {
        let text = format!("{GOOD_KEY}{nodes}");
        let (p, l, msg) = toml_problem(&text);
        assert!(matches!(p, Problem::Inconsistent(_)), "{text}: {p:?}");
        assert!(l.is_some_and(|l| l >= 5), "{text}: {msg}");
    }
    // No [camera] section.
    let (p, l, _) =
        toml_problem("[[node]]\nname = \"Lid\"\nkey = [{ frame = 1, translation = [0, 1, 0] }]\n");
    assert!(matches!(p, Problem::Inconsistent(_)));
    assert_eq!(l, None);
}
