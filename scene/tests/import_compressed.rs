//! glTF as real pipelines deliver it: CarConcept packed at test time (never
//! committed) by gltfpack — quantized (`KHR_mesh_quantization`), meshopt-compressed
//! (`EXT_meshopt_compression`, `-c`/`-cc`), with named nodes kept (`-kn`) — and by
//! gltf-pipeline — Draco-compressed (`KHR_draco_mesh_compression`, `-d`) — imports; a file
//! that *requires* an extension trisort lacks is refused naming it.

use std::path::{Path, PathBuf};

use trisort_scene::{load, SceneError};

/// CarConcept's triangles as gltfpack writes them: it welds vertices equal in every
/// attribute and drops the 44 triangles that then repeat an index (all of zero area; 43 of
/// them have two vertices equal in every attribute of the source file already).
const PACKED_TRIANGLES: usize = 213_347 - 44;

/// Runs `tool` (gltfpack or gltf-pipeline, which share `-i IN -o OUT`) on `input` with
/// `options`, writing `dir/name.glb`.
fn pack(tool: &Path, input: &Path, dir: &Path, name: &str, options: &[&str]) -> PathBuf {
    let out = dir.join(format!("{name}.glb"));
    let status = std::process::Command::new(tool)
        .arg("-i")
        .arg(input)
        .arg("-o")
        .arg(&out)
        .args(options)
        .status()
        .unwrap();
    assert!(status.success(), "{} {options:?} failed", tool.display());
    out
}

/// One corner of a triangle as exact bits: its position, uv, material and node.
type Corner = ([u32; 3], [u32; 2], u32, u32);

/// The geometry's triangles as a sorted list of [`Corner`] triples, each in its smallest
/// rotation (the winding is kept): equal for two files that hold the same triangles in any
/// order and rotation.
fn triangle_set(g: &trisort_format::Geometry) -> Vec<[Corner; 3]> {
    let mut out: Vec<[Corner; 3]> = (g.triangles.iter())
        .map(|t| {
            let c = t.map(|i| {
                let v = &g.vertices[i as usize];
                (
                    v.position.map(f32::to_bits),
                    v.uv.map(f32::to_bits),
                    v.material,
                    v.node,
                )
            });
            (0..3)
                .map(|k| [c[k], c[(k + 1) % 3], c[(k + 2) % 3]])
                .min()
                .unwrap()
        })
        .collect();
    out.sort_unstable();
    out
}

#[test]
fn gltfpack_outputs_of_car_concept_import() {
    let Some(car) = trisort_testkit::scene_path("CarConcept/CarConcept.glb") else {
        return;
    };
    let Some(gltfpack) = trisort_testkit::gltfpack() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Unquantized and uncompressed: what the importer read before these extensions.
    let plain = load(&pack(&gltfpack, &car, d, "noq", &["-noq"])).unwrap();
    assert_eq!(plain.geometry.triangles.len(), PACKED_TRIANGLES);
    let quantized = load(&pack(&gltfpack, &car, d, "q", &[])).unwrap();
    assert_eq!(quantized.geometry.triangles.len(), PACKED_TRIANGLES);
    for (name, options, base) in [
        ("c", &["-c"][..], &quantized),
        ("cc", &["-cc"][..], &quantized),
    ] {
        let scene = load(&pack(&gltfpack, &car, d, name, options)).unwrap();
        // Meshopt's codecs are lossless, but gltfpack orders vertices and triangles (and
        // rotates triangles) for them: the triangles are the quantized file's, bit for bit,
        // as a set; normals and tangents, stored with the octahedral filter, may differ.
        let (g, b) = (&scene.geometry, &base.geometry);
        assert_eq!(g.nodes, b.nodes, "{name}");
        assert_eq!(g.materials, b.materials, "{name}");
        assert_eq!(triangle_set(g), triangle_set(b), "{name}");
        for v in &g.vertices {
            let length: f32 = v.normal.iter().map(|x| x * x).sum::<f32>().sqrt();
            assert!((length - 1.0).abs() < 1e-3, "{name}: normal {:?}", v.normal);
        }
    }
    hostile_meshopt_views_are_errors(&std::fs::read(d.join("cc.glb")).unwrap(), d);
    // Named nodes kept: the car's 101 nodes are there again (gltfpack adds nodes of its own
    // for the dequantizing transforms), with the same triangles.
    for (name, options) in [("kn", &["-kn"][..]), ("cckn", &["-cc", "-kn"][..])] {
        let scene = load(&pack(&gltfpack, &car, d, name, options)).unwrap();
        assert_eq!(scene.geometry.triangles.len(), PACKED_TRIANGLES, "{name}");
        let original = load(&car).unwrap();
        for node in original
            .geometry
            .nodes
            .iter()
            .filter(|n| !n.name.is_empty())
        {
            assert!(
                scene.geometry.nodes.iter().any(|m| m.name == node.name),
                "{name}: node {:?} lost",
                node.name
            );
        }
    }
}

/// Replaces the JSON chunk of GLB `bytes` with `json` (padded with spaces).
fn with_json(bytes: &[u8], json: &str) -> Vec<u8> {
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let rest = &bytes[20 + word(12)..];
    let mut json = json.as_bytes().to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + json.len() + rest.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend(rest);
    out
}

#[test]
fn required_extensions_trisort_lacks_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("tri.gltf");
    let gltf = |required: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":[{required}],"extensionsRequired":[{required}],
            "scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}}],
            "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}}]}}"#
        )
    };
    for (required, hint) in [
        (
            "\"KHR_draco_mesh_compression\",\"KHR_texture_basisu\"",
            "does not implement it",
        ),
        ("\"KHR_texture_basisu\"", "does not implement it"),
        ("\"EXT_whatever\"", "does not implement it"),
        (
            "\"KHR_mesh_quantization\",\"EXT_lights_image_based\"",
            "does not implement it",
        ),
    ] {
        std::fs::write(&file, gltf(required)).unwrap();
        let err = load(&file).unwrap_err();
        let text = err.to_string();
        assert!(
            matches!(err, SceneError::UnsupportedExtension { .. }),
            "{required}: {text}"
        );
        let name = required.rsplit('"').nth(1).unwrap();
        assert!(text.contains("tri.gltf"), "{text}");
        assert!(
            text.contains(&format!("unsupported extension {name}")),
            "{text}"
        );
        assert!(text.contains(hint), "{text}");
        assert!(!text.contains("malformed"), "{text}");
    }
    // Required and handled: imports.
    for required in [
        "\"KHR_mesh_quantization\"",
        "\"EXT_meshopt_compression\"",
        "\"KHR_draco_mesh_compression\"",
    ] {
        std::fs::write(&file, gltf(required)).unwrap();
        let scene = load(&file).unwrap();
        assert_eq!(scene.geometry.triangles.len(), 1, "{required}");
    }
}

/// Every lie in a meshopt view's extension object is an error naming the file and the view,
/// never a panic, an abort in meshoptimizer's decoders or a huge allocation.
fn hostile_meshopt_views_are_errors(glb: &[u8], dir: &Path) {
    let n = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&glb[20..20 + n]).unwrap();
    let views = json["bufferViews"].as_array().unwrap();
    let first = |mode: &str| {
        (views.iter())
            .position(|v| v["extensions"]["EXT_meshopt_compression"]["mode"] == mode)
            .unwrap()
    };
    let (attributes, triangles) = (first("ATTRIBUTES"), first("TRIANGLES"));
    type Lie = fn(&mut serde_json::Value);
    let cases: [(usize, Lie, &str); 9] = [
        (
            attributes,
            |e| e["count"] = (1u64 << 40).into(),
            "cannot come from",
        ),
        (
            attributes,
            |e| e["byteStride"] = 3.into(),
            "not a multiple of 4",
        ),
        (
            attributes,
            |e| e["byteStride"] = 260.into(),
            "not a multiple of 4",
        ),
        (attributes, |e| e["mode"] = "FOO".into(), "unknown mode"),
        (attributes, |e| e["buffer"] = 9.into(), "the file has 2"),
        (
            attributes,
            |e| e["byteOffset"] = (1u64 << 40).into(),
            "exceed buffer",
        ),
        (
            triangles,
            |e| e["filter"] = "OCTAHEDRAL".into(),
            "does not apply",
        ),
        (triangles, |e| e["count"] = 4.into(), "not a multiple of 3"),
        (
            attributes,
            |e| {
                let half = e["byteLength"].as_u64().unwrap() / 2;
                e["byteLength"] = half.into();
            },
            "does not decode",
        ),
    ];
    for (view, lie, problem) in cases {
        let mut json = json.clone();
        lie(&mut json["bufferViews"][view]["extensions"]["EXT_meshopt_compression"]);
        let file = dir.join("lie.glb");
        std::fs::write(&file, with_json(glb, &json.to_string())).unwrap();
        let err = load(&file).unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, SceneError::Malformed { .. }), "{text}");
        assert!(text.contains("lie.glb"), "{text}");
        assert!(text.contains(&format!("buffer view {view}")), "{text}");
        assert!(text.contains(problem), "{problem}: {text}");
    }
}

#[test]
fn draco_compressed_car_concept_imports() {
    let Some(car) = trisort_testkit::scene_path("CarConcept/CarConcept.glb") else {
        return;
    };
    let Some(pipeline) = trisort_testkit::gltf_pipeline() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let original = load(&car).unwrap();
    let file = pack(&pipeline, &car, d, "draco", &["-d"]);
    let scene = load(&file).unwrap();
    // Draco's encoder drops the triangles with two corners at one position (66 in
    // CarConcept); every other triangle is there, in the same nodes.
    let g = &original.geometry;
    let collapsed = (g.triangles.iter())
        .filter(|t| {
            let p = t.map(|i| g.vertices[i as usize].position);
            p[0] == p[1] || p[1] == p[2] || p[0] == p[2]
        })
        .count();
    assert_eq!(collapsed, 66);
    assert_eq!(scene.geometry.triangles.len(), 213_347 - collapsed);
    assert_eq!(scene.geometry.nodes, original.geometry.nodes);
    // gltf-pipeline drops the 6 materials only KHR_materials_variants uses; the others keep
    // what decides visibility (it rewrites the JSON, so other factors may differ in their
    // last bits).
    let visibility = |m: &trisort_format::Material| {
        (
            m.alpha_mode,
            m.alpha_cutoff,
            m.double_sided,
            m.transmission > 0.0,
        )
    };
    assert_eq!(scene.geometry.materials.len(), 23);
    for m in &scene.geometry.materials {
        let o = (original.geometry.materials.iter())
            .find(|o| o.name == m.name)
            .unwrap();
        assert_eq!(visibility(m), visibility(o), "{}", m.name);
    }
    // Positions are quantized (gltf-pipeline's default: 11 bits per mesh): the car's bounds
    // stay within 1/1000 of its size.
    let (lo, hi) = original.bounds().unwrap();
    let (dlo, dhi) = scene.bounds().unwrap();
    let tolerance = (hi - lo).length() / 1000.0;
    assert!(
        (dlo - lo).length() < tolerance && (dhi - hi).length() < tolerance,
        "{lo} {hi} vs {dlo} {dhi}"
    );
    hostile_draco_primitives_are_errors(&std::fs::read(&file).unwrap(), d);
}

/// A Draco primitive whose bitstream is cut or corrupt, or whose extension object or
/// accessors disagree with it, is an error naming the file and the primitive, never a panic.
fn hostile_draco_primitives_are_errors(glb: &[u8], dir: &Path) {
    let n = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&glb[20..20 + n]).unwrap();
    let prim = &json["meshes"][0]["primitives"][0];
    let ext = &prim["extensions"]["KHR_draco_mesh_compression"];
    let view = ext["bufferView"].as_u64().unwrap() as usize;
    let position = prim["attributes"]["POSITION"].as_u64().unwrap() as usize;
    type Lie = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(Lie, &str)> = vec![
        (
            Box::new(move |j| {
                let half = j["bufferViews"][view]["byteLength"].as_u64().unwrap() / 2;
                j["bufferViews"][view]["byteLength"] = half.into();
            }),
            "does not decode",
        ),
        (
            Box::new(move |j| j["bufferViews"][view]["byteLength"] = 7.into()),
            "does not decode",
        ),
        (
            Box::new(|j| {
                j["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]
                    ["attributes"]["POSITION"] = 99.into()
            }),
            "no attribute with id 99",
        ),
        (
            Box::new(move |j| {
                let count = j["accessors"][position]["count"].as_u64().unwrap();
                j["accessors"][position]["count"] = (count + 1).into();
            }),
            "points",
        ),
        (
            Box::new(|j| {
                j["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]
                    ["bufferView"] = "x".into()
            }),
            "bufferView is missing or not an index",
        ),
    ];
    for (lie, problem) in cases {
        let mut json = json.clone();
        lie(&mut json);
        let file = dir.join("lie.glb");
        std::fs::write(&file, with_json(glb, &json.to_string())).unwrap();
        let err = load(&file).unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, SceneError::Malformed { .. }), "{text}");
        assert!(text.contains("lie.glb"), "{text}");
        assert!(text.contains("primitive 0"), "{text}");
        assert!(text.contains(problem), "{problem}: {text}");
    }
    // Bytes of the bitstream overwritten: an error or (where Draco cannot tell) other
    // geometry, never a panic.
    let at = 20
        + n
        + 8
        + json["bufferViews"][view]["byteOffset"]
            .as_u64()
            .unwrap_or(0) as usize;
    for offset in [4, 16, 64, 256] {
        let mut bytes = glb.to_vec();
        bytes[at + offset..at + offset + 8].fill(0xA5);
        let file = dir.join("flipped.glb");
        std::fs::write(&file, bytes).unwrap();
        if let Err(err) = load(&file) {
            assert!(err.to_string().contains("flipped.glb"), "{err}");
        }
    }
}

/// `KHR_materials_variants`: the variants' names, in file order (`""` for an unnamed one),
/// for `inspect`; none without the extension.
#[test]
fn material_variant_names_are_listed() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("v.gltf");
    let gltf = |extension: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},{extension}"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}}],
            "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}}]}}"#
        )
    };
    std::fs::write(
        &file,
        gltf(
            r#""extensionsUsed":["KHR_materials_variants"],"extensions":{"KHR_materials_variants":
            {"variants":[{"name":"Red"},{},{"name":"Blue"}]}},"#,
        ),
    )
    .unwrap();
    assert_eq!(load(&file).unwrap().variants, ["Red", "", "Blue"]);
    std::fs::write(&file, gltf("")).unwrap();
    assert!(load(&file).unwrap().variants.is_empty());
    if let Some(car) = trisort_testkit::scene_path("CarConcept/CarConcept.glb") {
        let names = load(&car).unwrap().variants;
        assert_eq!(
            names,
            ["Carmine Candy", "Pearly Swirly", "Torched Graphite"]
        );
    }
}
