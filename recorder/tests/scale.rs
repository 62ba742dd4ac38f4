//! Scale: CarConcept instanced 24× (≈5.1 M triangles) records one 64×64 frame.

use glam::{DMat4, DVec3};
use trisort_format::{Geometry, Node, Phase, RecordSettings};
use trisort_recorder::{record, RecordJob};
use trisort_testkit::gpu;

/// `copies` copies of `g` on a grid, each under a new root node translated by `spacing`.
fn instanced(g: &Geometry, copies: u32, spacing: f64) -> Geometry {
    let mut out = Geometry {
        materials: g.materials.clone(),
        textures: g.textures.clone(),
        ..Default::default()
    };
    let side = (copies as f64).sqrt().ceil() as u32;
    for c in 0..copies {
        let node_base = out.nodes.len() as u32;
        let offset = DVec3::new(
            (c % side) as f64 * spacing,
            0.0,
            (c / side) as f64 * spacing,
        );
        out.nodes.push(Node {
            name: format!("copy{c}"),
            parent: None,
            rest: DMat4::from_translation(offset).to_cols_array(),
        });
        for n in &g.nodes {
            out.nodes.push(Node {
                name: n.name.clone(),
                parent: Some(n.parent.map_or(node_base, |p| p + node_base + 1)),
                rest: n.rest,
            });
        }
        let vbase = out.vertices.len() as u32;
        out.vertices
            .extend(g.vertices.iter().map(|v| trisort_format::Vertex {
                node: v.node + node_base + 1,
                ..*v
            }));
        out.triangles
            .extend(g.triangles.iter().map(|t| t.map(|i| i + vbase)));
    }
    out
}

#[test]
fn five_million_triangles_record_one_frame() {
    let Some(path) = trisort_testkit::scene_path("CarConcept/CarConcept.glb") else {
        return;
    };
    let Some(gpu) = gpu() else { return };
    let car = trisort_scene::load(&path).unwrap();
    let scene = trisort_scene::Scene {
        geometry: instanced(&car.geometry, 24, 6.0),
        ..car
    };
    assert!(
        scene.geometry.triangles.len() > 5_000_000,
        "{}",
        scene.geometry.triangles.len()
    );
    let timeline = trisort_paths::load(
        "orbit:frames=1,elevation=35,distance=1.2",
        &scene,
        &Default::default(),
    )
    .unwrap();
    let job = RecordJob {
        geometry: &scene.geometry,
        frames: &timeline.frames,
        scene_hash: [0; 32],
        path_hash: timeline.hash(),
        settings: RecordSettings {
            width: 64,
            height: 64,
            samples: 4,
            ..Default::default()
        },
        range: None,
        phase: Phase::Graphs,
        known_visible: None,
        internals: Default::default(),
    };
    let rec = record(&gpu, &job, None, |_| {}).unwrap();
    let f = &rec.frames[0];
    assert!(!f.truncated);
    assert!(f.visible.len() > 1000, "{} visible", f.visible.len());
    assert!(f.edges.len() > 100);
    // Copies far from the camera are visible too: ids from several instances.
    let per_copy = car.geometry.triangles.len() as u32;
    let copies: std::collections::BTreeSet<u32> = f.visible.iter().map(|t| t / per_copy).collect();
    assert!(
        copies.len() > 4,
        "visible triangles from {} copies only",
        copies.len()
    );
}
