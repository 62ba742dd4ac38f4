//! glTF import on small files built by the tests: import semantics (winding under mirroring,
//! strips and fans, node order, instancing, materials, textures, animations, cameras).

use glam::{DMat3, DVec3, Vec3};
use serde_json::json;
use trisort_format::{world_transforms, AlphaMode};
use trisort_scene::{Interpolation, Property, Scene, SceneError};

use crate::gltf_builder::{base64, load_text, tetra_doc, tiny_png, Builder};

fn world_positions(scene: &Scene, t: usize) -> [DVec3; 3] {
    let g = &scene.geometry;
    let world = world_transforms(&g.nodes, &[]);
    g.triangles[t].map(|v| {
        let v = g.vertices[v as usize];
        world[v.node as usize].transform_point3(Vec3::from(v.position).as_dvec3())
    })
}

#[test]
fn mirrored_nodes_keep_outward_faces() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut doc = tetra_doc(&mut b, "tetra", json!({}));
    // Node 0: plain; node 1: mirrored in x; node 2 (mirror in y) with child 3 (mirror in x):
    // the child's world transform has a positive determinant again.
    doc["nodes"] = json!([
        {"mesh": 0, "name": "plain"},
        {"mesh": 0, "name": "mirrored", "translation": [5.0, 0.0, 0.0], "scale": [-1.0, 1.0, 1.0]},
        {"name": "mirror-y", "translation": [0.0, 5.0, 0.0], "scale": [1.0, -1.0, 1.0], "children": [3]},
        {"mesh": 0, "name": "twice", "scale": [-2.0, 1.0, 1.0]}
    ]);
    doc["scenes"] = json!([{"nodes": [0, 1, 2]}]);
    let scene = load_text(dir.path(), "mirror.gltf", &b.gltf(doc)).unwrap();
    let g = &scene.geometry;
    assert_eq!(g.triangles.len(), 12);
    let world = world_transforms(&g.nodes, &[]);
    for t in 0..g.triangles.len() {
        let node = g.triangle_node(t as u32) as usize;
        let centre = world[node].transform_point3(DVec3::ZERO);
        let [a, b2, c] = world_positions(&scene, t);
        let face = (b2 - a).cross(c - a);
        let outward = (a + b2 + c) / 3.0 - centre;
        assert!(
            face.dot(outward) > 0.0,
            "triangle {t} of node {:?} faces inward",
            g.nodes[node].name
        );
        // The flat normal, taken to world space by the normal matrix, agrees with the winding.
        let n = g.vertices[g.triangles[t][0] as usize].normal;
        let normal_matrix = DMat3::from_mat4(world[node]).inverse().transpose();
        let wn = normal_matrix * Vec3::from(n).as_dvec3();
        assert!(
            wn.dot(face) > 0.0,
            "triangle {t}: normal disagrees with winding"
        );
    }
}

#[test]
fn strips_and_fans_become_lists_and_lines_are_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    // A zig-zag strip and a fan in the z = 0 plane, both counter-clockwise seen from +z.
    let strip = b.vec3(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 2.0, 0.0],
    ]);
    let fan = b.vec3(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ]);
    let doc = json!({
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"name": "modes", "primitives": [
            {"attributes": {"POSITION": strip}, "mode": 5},
            {"attributes": {"POSITION": fan}, "mode": 6},
            {"attributes": {"POSITION": strip}, "mode": 1},
            {"attributes": {"POSITION": fan}, "mode": 0}
        ]}]
    });
    let scene = load_text(dir.path(), "modes.gltf", &b.gltf(doc)).unwrap();
    assert_eq!(scene.stats.triangles, 6);
    assert_eq!(scene.stats.primitives, 2);
    for t in 0..6 {
        let [a, b2, c] = world_positions(&scene, t);
        let face = (b2 - a).cross(c - a);
        assert!(face.z > 0.0, "triangle {t} is clockwise: {face:?}");
        // No normals in the file: flat normals, +z.
        let n = scene.geometry.vertices[scene.geometry.triangles[t][0] as usize].normal;
        assert_eq!(n, [0.0, 0.0, 1.0]);
    }
    assert!(
        scene.notes.iter().any(|n| n.contains("lines")),
        "{:?}",
        scene.notes
    );
    assert!(
        scene.notes.iter().any(|n| n.contains("points")),
        "{:?}",
        scene.notes
    );
    // Primitive ids in mesh order: the strip's triangles come first.
    let v = scene.geometry.vertices[scene.geometry.triangles[0][0] as usize];
    assert_eq!(v.position, [0.0, 0.0, 0.0]);
    let [a, _, _] = world_positions(&scene, 3);
    assert_eq!(
        a,
        DVec3::new(1.0, 0.0, 0.0),
        "the fan's first triangle is (v1, v2, v0)"
    );
}

#[test]
fn nodes_are_reordered_parents_first_and_instances_expanded() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut doc = tetra_doc(&mut b, "tetra", json!({}));
    // File order: a child before its parent, a root outside the scene, an instance.
    doc["nodes"] = json!([
        {"mesh": 0, "name": "child", "translation": [0.0, 1.0, 0.0]},
        {"name": "parent", "translation": [10.0, 0.0, 0.0], "children": [0, 3]},
        {"mesh": 0, "name": "outside"},
        {"mesh": 0, "name": "instance"}
    ]);
    doc["scenes"] = json!([{"nodes": [1]}, {"nodes": [2]}]);
    let scene = load_text(dir.path(), "order.gltf", &b.gltf(doc)).unwrap();
    let g = &scene.geometry;
    let names: Vec<&str> = g.nodes.iter().map(|n| n.name.as_str()).collect();
    assert_eq!(names, ["parent", "child", "instance", "outside"]);
    assert_eq!(g.nodes[1].parent, Some(0));
    assert_eq!(g.nodes[2].parent, Some(0));
    assert_eq!(g.nodes[3].parent, None);
    // Two instances of the tetrahedron, child first; the node outside the scene adds nothing.
    assert_eq!(g.triangles.len(), 8);
    assert!((0..4).all(|t| g.triangle_node(t) == 1));
    assert!((4..8).all(|t| g.triangle_node(t) == 2));
    // Positions stay local; the world transform goes through the parent.
    let [a, _, _] = world_positions(&scene, 0);
    assert_eq!(a, DVec3::new(11.0, 2.0, 1.0));
    assert_eq!(scene.stats.nodes, 4);
    assert!(scene.notes.iter().any(|n| n.contains("2 scenes")));
}

#[test]
fn zero_area_triangles_are_kept_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let pos = b.vec3(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 0.0, 0.0],
    ]);
    let idx = b.indices(&[0, 1, 2, 0, 0, 1, 0, 1, 3]);
    let normals = b.vec3(&[[0.0, 0.0, 2.0]; 4]);
    let doc = json!({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "NORMAL": normals}, "indices": idx}]}]
    });
    let scene = load_text(dir.path(), "zero.gltf", &b.gltf(doc)).unwrap();
    assert_eq!(scene.stats.triangles, 3);
    assert_eq!(scene.stats.zero_area_triangles, 2);
    // File normals are kept (renormalised) and vertices shared.
    assert_eq!(scene.geometry.vertices.len(), 4);
    assert_eq!(scene.geometry.vertices[0].normal, [0.0, 0.0, 1.0]);
}

#[test]
fn materials_textures_and_default_material() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut doc = tetra_doc(&mut b, "tetra", json!({"material": 0}));
    let uv0 = b.floats(&[0.0; 8], "VEC2", 4);
    let uv1 = b.floats(&[0.25, 0.5, 1.0, 0.0, 0.0, 1.0, 1.0, 1.0], "VEC2", 4);
    let pos = doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"].clone();
    let idx = doc["meshes"][0]["primitives"][0]["indices"].clone();
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(uv0);
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = json!(uv1);
    // A second primitive without a material.
    doc["meshes"][0]["primitives"]
        .as_array_mut()
        .unwrap()
        .push(json!({"attributes": {"POSITION": pos}, "indices": idx}));
    doc["extensionsUsed"] = json!([
        "KHR_materials_emissive_strength",
        "KHR_materials_transmission",
        "KHR_materials_sheen"
    ]);
    doc["materials"] = json!([{
        "name": "glassy",
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.5, 0.25, 1.0, 0.75],
            "baseColorTexture": {"index": 0, "texCoord": 1}
        },
        "alphaMode": "BLEND",
        "doubleSided": true,
        "emissiveFactor": [1.0, 0.5, 0.0],
        "extensions": {
            "KHR_materials_emissive_strength": {"emissiveStrength": 4.0},
            "KHR_materials_transmission": {"transmissionFactor": 0.8}
        }
    }, {
        "name": "cut", "alphaMode": "MASK", "alphaCutoff": 0.3,
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}
    }]);
    let png = format!("data:image/png;base64,{}", base64(&tiny_png()));
    doc["images"] = json!([{"uri": png, "name": "tiny"}]);
    doc["textures"] = json!([{"source": 0}, {"source": 0}]);
    let scene = load_text(dir.path(), "materials.gltf", &b.gltf(doc)).unwrap();
    let g = &scene.geometry;
    assert_eq!(g.materials.len(), 3, "two from the file and the default");
    assert_eq!(scene.stats.materials, 2);
    let m = &g.materials[0];
    assert_eq!(m.base_color, [0.5, 0.25, 1.0, 0.75]);
    assert_eq!(m.alpha_mode, AlphaMode::Blend);
    assert!(m.double_sided);
    assert_eq!(m.emissive, [4.0, 2.0, 0.0]);
    assert_eq!(m.transmission, 0.8);
    assert_eq!(g.materials[1].alpha_mode, AlphaMode::Mask);
    assert_eq!(g.materials[1].alpha_cutoff, 0.3);
    assert_eq!(g.materials[2].base_color_texture, None);
    // Both materials use the one image: one texture.
    assert_eq!(m.base_color_texture, Some(0));
    assert_eq!(g.materials[1].base_color_texture, Some(0));
    assert_eq!(g.textures.len(), 1);
    let t = &g.textures[0];
    assert_eq!((t.width, t.height, t.name.as_str()), (2, 2, "tiny"));
    assert_eq!(&t.rgba8[..8], &[255, 0, 0, 255, 0, 255, 0, 255]);
    assert_eq!(t.rgba8[15], 0);
    // The first material samples TEXCOORD_1 (vertex uv1), the second TEXCOORD_0 (vertex uv);
    // the second primitive has the default material and no texture coordinates.
    assert_eq!(
        (m.base_color_tex_coord, g.materials[1].base_color_tex_coord),
        (1, 0)
    );
    assert_eq!(g.vertices[0].uv1, [0.25, 0.5]);
    assert_eq!(g.vertices[0].uv, [0.0, 0.0]);
    assert_eq!(g.triangle_material(4), 2);
    assert_eq!(g.vertices[g.triangles[4][0] as usize].uv1, [0.0, 0.0]);
    assert!(!scene.notes.iter().any(|n| n.contains("TEXCOORD_1")));
    assert!(scene
        .notes
        .iter()
        .any(|n| n.contains("KHR_materials_sheen")));
    assert_eq!(
        scene
            .notes
            .iter()
            .filter(|n| n.contains("extension"))
            .count(),
        1
    );
}

#[test]
fn animations_and_cameras() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut doc = tetra_doc(&mut b, "tetra", json!({}));
    let times = b.floats(&[0.0, 1.0], "SCALAR", 2);
    let rot = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0], "VEC4", 2);
    let cubic = b.floats(&[0.0; 18], "VEC3", 6);
    let weights = b.floats(&[0.0, 1.0], "SCALAR", 2);
    doc["nodes"] = json!([
        {"name": "cam", "camera": 0, "children": [2]},
        {"name": "ortho", "camera": 1},
        {"name": "spin", "mesh": 0}
    ]);
    doc["scenes"] = json!([{"nodes": [0, 1]}]);
    doc["cameras"] = json!([
        {"type": "perspective", "name": "main",
         "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}},
        {"type": "orthographic", "orthographic": {"xmag": 1.0, "ymag": 1.0, "znear": 0.1, "zfar": 10.0}}
    ]);
    doc["animations"] = json!([{
        "name": "go",
        "samplers": [
            {"input": times, "output": rot},
            {"input": times, "output": cubic, "interpolation": "CUBICSPLINE"},
            {"input": times, "output": weights, "interpolation": "STEP"}
        ],
        "channels": [
            {"sampler": 0, "target": {"node": 2, "path": "rotation"}},
            {"sampler": 1, "target": {"node": 0, "path": "translation"}},
            {"sampler": 2, "target": {"node": 2, "path": "weights"}}
        ]
    }]);
    let scene = load_text(dir.path(), "anim.gltf", &b.gltf(doc)).unwrap();
    assert_eq!(scene.stats.animations, 1);
    let channels = &scene.animations[0].channels;
    assert_eq!(channels.len(), 2, "the morph-weight channel is skipped");
    let spin = scene.node_by_name("spin").unwrap();
    assert_eq!(channels[0].node, spin);
    assert_eq!(channels[0].property, Property::Rotation);
    assert_eq!(channels[0].interpolation, Interpolation::Linear);
    assert_eq!(channels[0].times, [0.0, 1.0]);
    assert_eq!(channels[0].values[4..], [0.0, 1.0, 0.0, 0.0]);
    assert_eq!(channels[1].interpolation, Interpolation::CubicSpline);
    assert_eq!(channels[1].values.len(), 18);
    assert_eq!(channels[1].node, scene.node_by_name("cam").unwrap());
    assert!(scene.notes.iter().any(|n| n.contains("morph-weight")));
    assert_eq!(scene.cameras.len(), 1);
    let cam = &scene.cameras[0];
    assert_eq!(cam.name, "main");
    assert_eq!(cam.node, scene.node_by_name("cam").unwrap());
    assert!((cam.yfov - 0.8).abs() < 1e-6 && cam.zfar.is_none());
    assert_eq!(cam.aspect, Some(1.5));
    assert!(scene.notes.iter().any(|n| n.contains("orthographic")));
}

#[test]
fn sparse_accessors_and_external_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let doc = tetra_doc(&mut b, "tetra", json!({}));
    // Replace vertex 2 with (3, 3, 3) through a sparse substitution.
    let sparse_idx = b.view(&2u16.to_le_bytes());
    let sparse_val = b.view(&[3.0f32, 3.0, 3.0].map(f32::to_le_bytes).concat());
    let pos = doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .unwrap();
    b.accessors[pos as usize]["sparse"] = json!({
        "count": 1,
        "indices": {"bufferView": sparse_idx, "componentType": 5123},
        "values": {"bufferView": sparse_val}
    });
    // The buffer lives in an external file whose name needs %-escaping.
    std::fs::write(dir.path().join("my mesh.bin"), &b.bin).unwrap();
    let mut root = doc;
    root["asset"] = json!({"version": "2.0"});
    root["buffers"] = json!([{"byteLength": b.bin.len(), "uri": "my%20mesh.bin"}]);
    root["bufferViews"] = json!(b.views);
    root["accessors"] = json!(b.accessors);
    let scene = load_text(dir.path(), "external.gltf", &root.to_string()).unwrap();
    assert_eq!(
        scene
            .geometry
            .vertices
            .iter()
            .filter(|v| v.position == [3.0; 3])
            .count(),
        3
    );

    // The same without the .bin file: an error naming it.
    std::fs::remove_file(dir.path().join("my mesh.bin")).unwrap();
    let err = load_text(dir.path(), "external.gltf", &root.to_string()).unwrap_err();
    assert!(matches!(err, SceneError::Buffer { buffer: 0, .. }), "{err}");
    let msg = err.to_string();
    assert!(
        msg.contains("external.gltf") && msg.contains("my mesh.bin"),
        "{msg}"
    );
}

#[test]
fn external_image_is_decoded_and_skipped_primitives_are_noted_once() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("maps")).unwrap();
    std::fs::write(dir.path().join("maps/base colour.png"), tiny_png()).unwrap();
    let mut b = Builder::default();
    let mut doc = tetra_doc(&mut b, "tetra", json!({"material": 0}));
    let pos = doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"].clone();
    doc["meshes"][0]["primitives"]
        .as_array_mut()
        .unwrap()
        .push(json!({"attributes": {"POSITION": pos}, "mode": 1}));
    // Two instances of the mesh: the line primitive is noted once.
    doc["nodes"] = json!([{"mesh": 0}, {"mesh": 0, "translation": [3.0, 0.0, 0.0]}]);
    doc["scenes"] = json!([{"nodes": [0, 1]}]);
    doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    doc["textures"] = json!([{"source": 0}]);
    doc["images"] = json!([{"uri": "maps/base%20colour.png"}]);
    let scene = load_text(dir.path(), "external-image.gltf", &b.gltf(doc)).unwrap();
    assert_eq!(scene.stats.triangles, 8);
    let t = &scene.geometry.textures[0];
    assert_eq!((t.width, t.height), (2, 2));
    assert_eq!(t.name, "maps/base%20colour.png");
    let line_notes: Vec<&String> = scene.notes.iter().filter(|n| n.contains("lines")).collect();
    assert_eq!(line_notes.len(), 1, "{:?}", scene.notes);
    assert!(
        line_notes[0].contains("skipped 1 lines"),
        "{}",
        line_notes[0]
    );
}
