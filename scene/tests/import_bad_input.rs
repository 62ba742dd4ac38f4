//! glTF import on bad input built by the tests (truncated, corrupt, NaN, skinned, missing
//! files, every number and member of a rich document mutated), which must give errors, never
//! panics.

use std::path::Path;

use serde_json::{json, Value};
use trisort_scene::{load, load_slice, SceneError};
use trisort_testkit::scene_path;

use crate::gltf_builder::{load_text, tetra_doc, tetrahedron, tiny_png, write, Builder};

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
