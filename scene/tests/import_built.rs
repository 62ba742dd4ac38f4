//! glTF import on small files built by the tests: import semantics (winding under mirroring,
//! strips and fans, node order, instancing, materials, textures, animations, cameras) and bad
//! input (truncated, corrupt, NaN, skinned, missing files), which must give errors, never panics.

use std::path::{Path, PathBuf};

use glam::{DMat3, DVec3, Vec3};
use serde_json::{json, Value};
use trisort_format::{world_transforms, AlphaMode};
use trisort_scene::{load, load_slice, Interpolation, Property, Scene, SceneError};
use trisort_testkit::scene_path;

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Builds the binary side of a small glTF: one buffer, tightly packed views and accessors.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    fn view(&mut self, bytes: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.views.push(json!({
            "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()
        }));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    fn floats(&mut self, values: &[f32], kind: &str, count: usize) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let comps = values.len() / count.max(1);
        let finite = |c: usize| {
            values
                .iter()
                .skip(c)
                .step_by(comps)
                .filter(|v| v.is_finite())
        };
        let min: Vec<f32> = (0..comps)
            .map(|c| finite(c).fold(f32::MAX, |a, &b| a.min(b)))
            .collect();
        let max: Vec<f32> = (0..comps)
            .map(|c| finite(c).fold(f32::MIN, |a, &b| a.max(b)))
            .collect();
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5126, "count": count, "type": kind,
            "min": min, "max": max
        }));
        self.accessors.len() - 1
    }

    fn vec3(&mut self, values: &[[f32; 3]]) -> usize {
        self.floats(values.as_flattened(), "VEC3", values.len())
    }

    fn indices(&mut self, values: &[u32]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5125, "count": values.len(), "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }

    /// The document with its buffer embedded as a base64 `data:` URI.
    fn gltf(&self, mut root: Value) -> String {
        root["asset"] = json!({"version": "2.0"});
        root["buffers"] = json!([{
            "byteLength": self.bin.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64(&self.bin))
        }]);
        root["bufferViews"] = json!(self.views);
        root["accessors"] = json!(self.accessors);
        root.to_string()
    }

    /// The document as a GLB with the buffer in the binary chunk.
    fn glb(&self, mut root: Value) -> Vec<u8> {
        root["asset"] = json!({"version": "2.0"});
        root["buffers"] = json!([{"byteLength": self.bin.len()}]);
        root["bufferViews"] = json!(self.views);
        root["accessors"] = json!(self.accessors);
        let mut text = root.to_string().into_bytes();
        text.resize(text.len().next_multiple_of(4), b' ');
        let mut bin = self.bin.clone();
        bin.resize(bin.len().next_multiple_of(4), 0);
        let total = 12 + 8 + text.len() + 8 + bin.len();
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((text.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(text);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
        out
    }
}

/// A regular tetrahedron around the origin, counter-clockwise seen from outside.
fn tetrahedron() -> (Vec<[f32; 3]>, Vec<u32>) {
    let p = vec![
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ];
    let i = vec![0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2];
    (p, i)
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn load_text(dir: &Path, name: &str, text: &str) -> Result<Scene, SceneError> {
    load(&write(dir, name, text))
}

/// A one-mesh document: a tetrahedron named `name` on node 0 of scene 0, with `extra` merged
/// into the primitive.
fn tetra_doc(b: &mut Builder, name: &str, extra: Value) -> Value {
    let (p, i) = tetrahedron();
    let pos = b.vec3(&p);
    let idx = b.indices(&i);
    let mut prim = json!({"attributes": {"POSITION": pos}, "indices": idx});
    for (k, v) in extra.as_object().unwrap() {
        prim[k] = v.clone();
    }
    json!({
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "tetra"}],
        "meshes": [{"name": name, "primitives": [prim]}]
    })
}

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

/// A 2×2 RGBA PNG: red, green / blue, transparent.
fn tiny_png() -> Vec<u8> {
    let img = image::RgbaImage::from_raw(
        2,
        2,
        vec![255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 0, 0, 0, 0],
    )
    .unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
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
        "KHR_materials_clearcoat"
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
    // The texture samples TEXCOORD_1, so that is the vertex uv; the second primitive has
    // the default material and no uv.
    assert_eq!(g.vertices[0].uv, [0.25, 0.5]);
    assert_eq!(g.triangle_material(4), 2);
    assert_eq!(g.vertices[g.triangles[4][0] as usize].uv, [0.0, 0.0]);
    assert!(scene.notes.iter().any(|n| n.contains("TEXCOORD_1")));
    assert!(scene
        .notes
        .iter()
        .any(|n| n.contains("KHR_materials_clearcoat")));
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
fn glb_round_trip_and_every_truncation_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let doc = tetra_doc(&mut b, "tetra", json!({}));
    let glb = b.glb(doc);
    let scene = load(&write(dir.path(), "whole.glb", &glb)).unwrap();
    assert_eq!(scene.stats.triangles, 4);
    assert_eq!(scene.name, "whole");
    for cut in 0..glb.len() {
        let file = Path::new("cut.glb");
        match load_slice(&glb[..cut], file) {
            Ok(_) => panic!("truncated at {cut} of {} bytes but imported", glb.len()),
            Err(e) => assert!(e.to_string().starts_with("cut.glb: "), "{e}"),
        }
    }
}

#[test]
fn corrupted_bytes_never_panic() {
    let mut b = Builder::default();
    let doc = tetra_doc(&mut b, "tetra", json!({"material": 0}));
    let mut doc = doc;
    doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    doc["textures"] = json!([{"source": 0}]);
    let png_view = b.view(&tiny_png());
    doc["images"] = json!([{"bufferView": png_view, "mimeType": "image/png"}]);
    let glb = b.glb(doc);
    load_slice(&glb, Path::new("ok.glb")).expect("the uncorrupted file imports");
    let mut errors = 0;
    for at in 0..glb.len() {
        for value in [0x00, 0xff, glb[at] ^ 0x55, b'9', b'-'] {
            let mut bad = glb.clone();
            bad[at] = value;
            // Must return, never panic; most corruptions are errors.
            if load_slice(&bad, Path::new("bad.glb")).is_err() {
                errors += 1;
            }
        }
    }
    assert!(
        errors > glb.len(),
        "only {errors} corruptions were rejected"
    );
}

#[test]
fn truncated_real_glb_is_an_error() {
    let Some(path) = scene_path("CesiumMilkTruck/CesiumMilkTruck.glb") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(path).unwrap();
    let json_end = 20 + u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let n = bytes.len();
    for cut in [
        0,
        3,
        11,
        12,
        19,
        20,
        100,
        json_end - 1,
        json_end,
        json_end + 8,
        n / 2,
        n - 1,
    ] {
        let file = write(dir.path(), &format!("truck-{cut}.glb"), &bytes[..cut]);
        let err = load(&file).expect_err("truncated file imported");
        assert!(
            err.to_string().contains(&format!("truck-{cut}.glb")),
            "{err}"
        );
    }
    // Cut the binary chunk and patch the lengths so that the container is consistent: the
    // buffer is then shorter than declared.
    let mut patched = bytes[..n / 2].to_vec();
    let total = patched.len() as u32;
    patched[8..12].copy_from_slice(&total.to_le_bytes());
    let bin_len = total - json_end as u32 - 8;
    patched[json_end..json_end + 4].copy_from_slice(&bin_len.to_le_bytes());
    let err = load(&write(dir.path(), "patched.glb", &patched)).unwrap_err();
    assert!(matches!(err, SceneError::Buffer { .. }), "{err}");
    assert!(err.to_string().contains("declared"), "{err}");
}

#[test]
fn junk_and_missing_files_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let junk: Vec<u8> = (0..4096)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state as u8
        })
        .collect();
    for name in ["junk.glb", "junk.gltf"] {
        let err = load(&write(dir.path(), name, &junk)).unwrap_err();
        assert!(matches!(err, SceneError::Malformed { .. }), "{err}");
        assert!(err.to_string().contains(name), "{err}");
    }
    let mut fake = b"glTF".to_vec();
    fake.extend(&junk);
    assert!(load(&write(dir.path(), "fake.glb", &fake)).is_err());
    assert!(load(&write(dir.path(), "empty.gltf", b"")).is_err());
    assert!(load(&write(dir.path(), "array.gltf", b"[1, 2]")).is_err());

    let missing = dir.path().join("no-such-scene.glb");
    let err = load(&missing).unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }), "{err}");
    assert!(err.to_string().contains("no-such-scene.glb"), "{err}");
}

#[test]
fn non_finite_positions_name_mesh_and_accessor() {
    let dir = tempfile::tempdir().unwrap();
    for bad in [f32::NAN, f32::INFINITY] {
        let mut b = Builder::default();
        let pos = b.vec3(&[[0.0, 0.0, 0.0], [1.0, bad, 0.0], [0.0, 1.0, 0.0]]);
        let doc = json!({
            "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"name": "Broken", "primitives": [{"attributes": {"POSITION": pos}}]}]
        });
        let err = load_text(dir.path(), "nan.gltf", &b.gltf(doc)).unwrap_err();
        assert!(
            matches!(
                err,
                SceneError::NonFinitePosition {
                    vertex: 1,
                    accessor: 0,
                    ..
                }
            ),
            "{err}"
        );
        let msg = err.to_string();
        assert!(
            msg.contains("nan.gltf") && msg.contains("\"Broken\"") && msg.contains("accessor 0"),
            "{msg}"
        );
    }
}

#[test]
fn skins_and_morph_targets_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut doc = tetra_doc(&mut b, "body", json!({}));
    doc["nodes"] =
        json!([{"mesh": 0, "skin": 0, "name": "skinned", "children": [1]}, {"name": "bone"}]);
    doc["skins"] = json!([{"joints": [1]}]);
    let err = load_text(dir.path(), "skin.gltf", &b.gltf(doc)).unwrap_err();
    assert!(matches!(err, SceneError::Skinned { skin: 0, .. }), "{err}");
    assert!(err.to_string().contains("\"skinned\""), "{err}");

    let mut b = Builder::default();
    let offsets = b.vec3(&[[0.0, 0.0, 1.0]; 4]);
    let doc = tetra_doc(&mut b, "blob", json!({"targets": [{"POSITION": offsets}]}));
    let err = load_text(dir.path(), "morph.gltf", &b.gltf(doc)).unwrap_err();
    assert!(
        matches!(err, SceneError::MorphTargets { primitive: 0, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("\"blob\""), "{err}");
}

#[test]
fn broken_structure_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    type Edit = Box<dyn Fn(&mut Value, &mut Builder)>;
    let cases: Vec<(&str, Edit)> = vec![
        (
            "cycle",
            Box::new(|d, _| d["nodes"] = json!([{"mesh": 0, "children": [1]}, {"children": [0]}])),
        ),
        (
            "two-parents",
            Box::new(|d, _| {
                d["nodes"] = json!([{"mesh": 0}, {"children": [0]}, {"children": [0]}]);
                d["scenes"] = json!([{"nodes": [1, 2]}]);
            }),
        ),
        (
            "index-range",
            Box::new(|d, b| {
                let idx = b.indices(&[0, 1, 7]);
                d["meshes"][0]["primitives"][0]["indices"] = json!(idx);
            }),
        ),
        (
            "accessor-overrun",
            Box::new(|_, b| b.accessors[0]["count"] = json!(1000)),
        ),
        (
            "stride",
            Box::new(|_, b| b.views[0]["byteStride"] = json!(4)),
        ),
        (
            "bad-image",
            Box::new(|d, _| {
                d["meshes"][0]["primitives"][0]["material"] = json!(0);
                d["materials"] =
                    json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
                d["textures"] = json!([{"source": 0}]);
                d["images"] = json!([{"uri": "data:image/png;base64,iVBORw0KGgoAAAA"}]);
            }),
        ),
        (
            "missing-image",
            Box::new(|d, _| {
                d["meshes"][0]["primitives"][0]["material"] = json!(0);
                d["materials"] =
                    json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
                d["textures"] = json!([{"source": 0}]);
                d["images"] = json!([{"uri": "nowhere.png"}]);
            }),
        ),
        (
            "zero-rotation",
            Box::new(|d, _| d["nodes"][0]["rotation"] = json!([0.0, 0.0, 0.0, 0.0])),
        ),
        (
            "dangling-mesh",
            Box::new(|d, _| d["nodes"][0]["mesh"] = json!(5)),
        ),
        (
            "bad-animation",
            Box::new(|d, b| {
                let t = b.floats(&[1.0, 0.0], "SCALAR", 2);
                let v = b.floats(&[0.0; 6], "VEC3", 2);
                d["animations"] = json!([{"samplers": [{"input": t, "output": v}],
                    "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}]);
            }),
        ),
    ];
    for (name, edit) in cases {
        let mut b = Builder::default();
        let mut doc = tetra_doc(&mut b, "tetra", json!({}));
        edit(&mut doc, &mut b);
        let file = format!("{name}.gltf");
        let err = load_text(dir.path(), &file, &b.gltf(doc))
            .err()
            .unwrap_or_else(|| panic!("{name}: imported"));
        assert!(err.to_string().contains(&file), "{name}: {err}");
        eprintln!("{name}: {err}");
    }
}

/// A document that uses every feature the importer reads, for mutation tests.
fn rich_document(b: &mut Builder) -> Value {
    let (p, i) = tetrahedron();
    let pos = b.vec3(&p);
    let idx = b.indices(&i);
    let normals = b.vec3(&p);
    let uv = b.floats(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 1.0], "VEC2", 4);
    let strip = b.indices(&[0, 1, 2, 3]);
    let sparse_idx = b.view(&1u8.to_le_bytes());
    let sparse_val = b.view(&[0.5f32, 0.5, 0.5].map(f32::to_le_bytes).concat());
    b.accessors[pos]["sparse"] = json!({
        "count": 1,
        "indices": {"bufferView": sparse_idx, "componentType": 5121},
        "values": {"bufferView": sparse_val}
    });
    let times = b.floats(&[0.0, 1.0], "SCALAR", 2);
    let rot = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0], "VEC4", 2);
    let png = b.view(&tiny_png());
    json!({
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "root", "children": [1], "scale": [-1.0, 1.0, 1.0]},
            {"name": "part", "mesh": 0, "translation": [0.0, 1.0, 0.0]},
            {"name": "eye", "camera": 0, "rotation": [0.0, 0.0, 0.0, 1.0]}
        ],
        "meshes": [{"name": "m", "primitives": [
            {"attributes": {"POSITION": pos, "NORMAL": normals, "TEXCOORD_0": uv},
             "indices": idx, "material": 0},
            {"attributes": {"POSITION": pos}, "indices": strip, "mode": 5}
        ]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
                       "alphaMode": "MASK"}],
        "textures": [{"source": 0}],
        "images": [{"bufferView": png, "mimeType": "image/png"}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}],
        "animations": [{"samplers": [{"input": times, "output": rot}],
                        "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}]}]
    })
}

/// Every number of the JSON (document, views and accessors), replaced in turn by values that
/// break indices, counts, offsets and strides: the import returns, with or without an error.
#[test]
fn every_json_number_mutated_never_panics() {
    let mut b = Builder::default();
    let doc = rich_document(&mut b);
    let mut whole = serde_json::from_str::<Value>(&b.gltf(doc)).unwrap();
    let scene = load_slice(whole.to_string().as_bytes(), Path::new("rich.gltf")).unwrap();
    assert_eq!(scene.stats.triangles, 6);
    assert_eq!(scene.animations.len(), 1);
    assert_eq!(scene.cameras.len(), 1);
    fn numbers(v: &Value, path: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
        match v {
            Value::Number(_) => out.push(path.clone()),
            Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    path.push(i.to_string());
                    numbers(x, path, out);
                    path.pop();
                }
            }
            Value::Object(o) => {
                for (k, x) in o {
                    path.push(k.clone());
                    numbers(x, path, out);
                    path.pop();
                }
            }
            _ => {}
        }
    }
    let mut paths = Vec::new();
    numbers(&whole, &mut Vec::new(), &mut paths);
    assert!(paths.len() > 60, "{} numbers", paths.len());
    let mut rejected = 0;
    for path in &paths {
        let pointer = format!("/{}", path.join("/"));
        let original = whole.pointer(&pointer).unwrap().clone();
        for value in [
            json!(0),
            json!(1),
            json!(3),
            json!(13),
            json!(1000),
            json!(4294967295u64),
            json!(-1),
            json!(0.5),
        ] {
            *whole.pointer_mut(&pointer).unwrap() = value;
            if load_slice(whole.to_string().as_bytes(), Path::new("m.gltf")).is_err() {
                rejected += 1;
            }
        }
        *whole.pointer_mut(&pointer).unwrap() = original;
    }
    assert!(
        rejected > paths.len(),
        "only {rejected} mutations were rejected"
    );
}

/// Every member of every JSON object removed in turn, or replaced by a value of another type.
#[test]
fn every_json_member_removed_or_retyped_never_panics() {
    let mut b = Builder::default();
    let doc = rich_document(&mut b);
    let whole = serde_json::from_str::<Value>(&b.gltf(doc)).unwrap();
    fn members(v: &Value, path: &str, out: &mut Vec<(String, String)>) {
        match v {
            Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    members(x, &format!("{path}/{i}"), out);
                }
            }
            Value::Object(o) => {
                for (k, x) in o {
                    out.push((path.to_string(), k.clone()));
                    members(x, &format!("{path}/{k}"), out);
                }
            }
            _ => {}
        }
    }
    let mut list = Vec::new();
    members(&whole, "", &mut list);
    assert!(list.len() > 50, "{} members", list.len());
    let mut rejected = 0;
    for (parent, key) in &list {
        let replacements = [json!(null), json!("x"), json!([]), json!({}), json!(true)];
        for edit in 0..=replacements.len() {
            let mut doc = whole.clone();
            let object = doc.pointer_mut(parent).unwrap().as_object_mut().unwrap();
            match replacements.get(edit) {
                Some(value) => object.insert(key.clone(), value.clone()),
                None => object.remove(key),
            };
            if load_slice(doc.to_string().as_bytes(), Path::new("m.gltf")).is_err() {
                rejected += 1;
            }
        }
    }
    assert!(rejected > list.len(), "only {rejected} edits were rejected");
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
