//! Hand-built scenes and helpers shared by the integration tests.

use std::io::Write;

use glam::{DMat4, DVec3};
use trisort_format::{Geometry, Material, Node, Vertex};
use trisort_paths::{load, PathError, PathOptions, Problem, Timeline};
use trisort_scene::Scene;

/// A node with a rest transform.
pub fn node(name: &str, parent: Option<u32>, rest: DMat4) -> Node {
    Node {
        name: name.into(),
        parent,
        rest: rest.to_cols_array(),
    }
}

/// A scene of the given nodes with one axis-aligned box (12 triangles) per `(node, min, max)`,
/// in that node's local space.
pub fn scene_with_boxes(nodes: Vec<Node>, boxes: &[(u32, DVec3, DVec3)]) -> Scene {
    let mut g = Geometry {
        materials: vec![Material::default()],
        nodes,
        ..Geometry::default()
    };
    for &(node, lo, hi) in boxes {
        let base = g.vertices.len() as u32;
        for i in 0..8 {
            let p = DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            g.vertices.push(Vertex {
                position: p.as_vec3().to_array(),
                normal: [0.0; 3],
                uv: [0.0; 2],
                material: 0,
                node,
                tangent: [0.0; 4],
                uv1: [0.0; 2],
            });
        }
        for [a, b, c] in [
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ] {
            g.triangles.push([base + a, base + b, base + c]);
        }
    }
    Scene {
        name: "test scene".into(),
        geometry: g,
        ..Scene::default()
    }
}

/// A 2 × 1 × 4 box "Body" centred at (0, 0.5, 0) and a "Lid" node at (0, 1, 0) with a
/// 1 × 0.1 × 1 box, plus a "BodyDoorLColor1" node (no geometry) for name suggestions.
pub fn box_scene() -> Scene {
    scene_with_boxes(
        vec![
            node("Body", None, DMat4::IDENTITY),
            node(
                "Lid",
                Some(0),
                DMat4::from_translation(DVec3::new(0.0, 1.0, 0.0)),
            ),
            node("BodyDoorLColor1", Some(0), DMat4::IDENTITY),
        ],
        &[
            (0, DVec3::new(-1.0, 0.0, -2.0), DVec3::new(1.0, 1.0, 2.0)),
            (1, DVec3::new(-0.5, 0.0, -0.5), DVec3::new(0.5, 0.1, 0.5)),
        ],
    )
}

/// Writes `text` to a temporary `.toml` file and loads it as a path.
pub fn load_toml(
    text: &str,
    scene: &Scene,
) -> (Result<Timeline, PathError>, tempfile::NamedTempFile) {
    let mut f = tempfile::Builder::new()
        .suffix(".toml")
        .tempfile()
        .expect("temp file");
    f.write_all(text.as_bytes()).expect("write");
    let spec = f.path().to_str().expect("utf-8 temp path").to_string();
    (load(&spec, scene, &PathOptions::default()), f)
}

/// The problem of an `Invalid` error, with its line; panics with the error otherwise.
pub fn problem(result: Result<Timeline, PathError>) -> (Problem, Option<usize>, String) {
    match result {
        Err(e @ PathError::Invalid { .. }) => {
            let message = e.to_string();
            let PathError::Invalid { at, problem } = e else {
                unreachable!()
            };
            (problem, at.line, message)
        }
        Err(e) => panic!("expected an Invalid error, got {e}"),
        Ok(t) => panic!("expected an error, got {} frames", t.frames.len()),
    }
}

/// World-space eye position and unit forward (view direction) of a frame's camera.
pub fn eye_forward(t: &Timeline, f: usize) -> (DVec3, DVec3) {
    let inv = t.frames[f].camera.view_matrix().inverse();
    (inv.w_axis.truncate(), -inv.z_axis.truncate().normalize())
}
