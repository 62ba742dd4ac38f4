//! glTF as real pipelines deliver it: CarConcept packed at test time (never
//! committed) by gltfpack — quantized (`KHR_mesh_quantization`), meshopt-compressed
//! (`EXT_meshopt_compression`, `-c`/`-cc`), with named nodes kept (`-kn`) — and by
//! gltf-pipeline — Draco-compressed (`KHR_draco_mesh_compression`, `-d`) — and with its
//! textures as KTX2 Basis Universal images (`KHR_texture_basisu`, ETC1S and UASTC, made by
//! Basis Universal's `basisu`: gltfpack's npm build cannot `-tc`) and as WebP images
//! (`EXT_texture_webp`, glTF Transform's `webp`) imports; a file that *requires* an extension
//! trisort lacks is refused naming it.

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
            "\"KHR_draco_mesh_compression\",\"MSFT_texture_dds\"",
            "does not implement it",
        ),
        ("\"MSFT_texture_dds\"", "does not implement it"),
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
        "\"KHR_texture_basisu\"",
        "\"EXT_texture_webp\"",
        "\"KHR_texture_basisu\",\"EXT_texture_webp\"",
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

/// The peak signal-to-noise ratio of `b` against `a` (RGBA8 texels of one size), in dB;
/// infinite where they are equal.
fn psnr(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len());
    let sum: f64 = (a.iter().zip(b))
        .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
        .sum();
    let mse = sum / a.len() as f64;
    10.0 * (255.0f64 * 255.0 / mse).log10()
}

/// Checks that `scene`, a copy of `plain` whose images another encoder re-encoded, has the
/// same triangles, materials and texture sizes, and texels within `min_psnr` dB of the plain
/// copy's, in every texture, a bound that red and blue swapped would not pass in some
/// texture; returns the lowest PSNR and whether some texture differs from the plain copy's.
fn same_but_texels(
    plain: &trisort_scene::Scene,
    scene: &trisort_scene::Scene,
    name: &str,
    min_psnr: f64,
) -> (f64, bool) {
    let (g, p) = (&scene.geometry, &plain.geometry);
    assert_eq!(triangle_set(g), triangle_set(p), "{name}");
    assert_eq!(g.materials, p.materials, "{name}");
    assert_eq!(g.textures.len(), p.textures.len(), "{name}");
    let mut lowest = f64::INFINITY;
    let mut differs = false;
    let mut swap_fails = false;
    for (t, (a, b)) in p.textures.iter().zip(&g.textures).enumerate() {
        let size = |t: &trisort_format::Texture| (t.width, t.height, t.srgb, t.mips.len());
        assert_eq!(size(a), size(b), "{name}: texture {t}");
        let db = psnr(&a.rgba8, &b.rgba8);
        let swapped: Vec<u8> = (b.rgba8.chunks(4))
            .flat_map(|c| [c[2], c[1], c[0], c[3]])
            .collect();
        let swapped_db = psnr(&a.rgba8, &swapped);
        eprintln!(
            "{name}: texture {t} {}x{}: PSNR {db:.1} dB (red and blue swapped: {swapped_db:.1} dB)",
            a.width, a.height
        );
        assert!(db >= min_psnr, "{name}: texture {t}: PSNR {db:.1} dB");
        lowest = lowest.min(db);
        swap_fails |= swapped_db < min_psnr;
        differs |= a.rgba8 != b.rgba8;
    }
    assert!(
        swap_fails,
        "{name}: {min_psnr} dB would pass red and blue swapped"
    );
    (lowest, differs)
}

/// Loads `file`, printing how long it took.
fn timed_load(file: &Path) -> trisort_scene::Scene {
    let start = std::time::Instant::now();
    let scene = load(file).unwrap();
    eprintln!(
        "{}: imported in {:.2} s",
        file.display(),
        start.elapsed().as_secs_f64()
    );
    scene
}

/// The JSON of GLB `bytes` and its binary chunk.
fn glb_parts(bytes: &[u8]) -> (serde_json::Value, &[u8]) {
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let n = word(12);
    let json = serde_json::from_slice(&bytes[20..20 + n]).unwrap();
    let bin = &bytes[20 + n + 8..20 + n + 8 + word(20 + n)];
    (json, bin)
}

/// A GLB of `json` and binary chunk `bin`.
fn glb(json: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut out = with_json(b"glTF\x02\0\0\0\0\0\0\0\x02\0\0\0JSON  ", &json.to_string());
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    let length = out.len() as u32;
    out[8..12].copy_from_slice(&length.to_le_bytes());
    out
}

/// GLB `bytes` with every image also encoded by Basis Universal's `basisu` with `options` (in
/// `dir`) as a KTX2 image appended to the binary chunk, every texture pointing at it through
/// `KHR_texture_basisu`. With `fallback` the textures keep their PNG/JPEG `source`, else
/// they lose it and the file requires the extension (what `gltfpack -tc` writes).
fn with_ktx2_images(
    bytes: &[u8],
    basisu: &Path,
    dir: &Path,
    options: &[&str],
    fallback: bool,
) -> Vec<u8> {
    let (mut json, bin) = glb_parts(bytes);
    let mut bin = bin.to_vec();
    let images = json["images"].as_array().unwrap().clone();
    for (i, image) in images.iter().enumerate() {
        let view = &json["bufferViews"][image["bufferView"].as_u64().unwrap() as usize];
        let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        let length = view["byteLength"].as_u64().unwrap() as usize;
        let ext = if image["mimeType"] == "image/jpeg" {
            "jpg"
        } else {
            "png"
        };
        let (input, output) = (
            dir.join(format!("{i}.{ext}")),
            dir.join(format!("{i}.ktx2")),
        );
        std::fs::write(&input, &bin[offset..offset + length]).unwrap();
        let run = std::process::Command::new(basisu)
            .args(["-ktx2", "-mipmap"])
            .args(options)
            .arg("-file")
            .arg(&input)
            .arg("-output_file")
            .arg(&output)
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "basisu {options:?} {}: {run:?}",
            input.display()
        );
        let ktx2 = std::fs::read(&output).unwrap();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let views = json["bufferViews"].as_array_mut().unwrap();
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": ktx2.len()}),
        );
        let view = views.len() - 1;
        bin.extend(ktx2);
        let list = json["images"].as_array_mut().unwrap();
        list.push(serde_json::json!({"bufferView": view, "mimeType": "image/ktx2"}));
    }
    let count = images.len() as u64;
    for texture in json["textures"].as_array_mut().unwrap() {
        let source = texture["source"].as_u64().unwrap();
        texture["extensions"]["KHR_texture_basisu"] = serde_json::json!({"source": source + count});
        if !fallback {
            texture.as_object_mut().unwrap().remove("source");
        }
    }
    json["buffers"][0]["byteLength"] = bin.len().into();
    let ext = serde_json::Value::from("KHR_texture_basisu");
    json["extensionsUsed"]
        .as_array_mut()
        .unwrap()
        .push(ext.clone());
    if !fallback {
        json["extensionsRequired"] = serde_json::json!([ext]);
    }
    glb(&json, &bin)
}

#[test]
fn basisu_textures_of_car_concept_import() {
    let Some(car) = trisort_testkit::scene_path("CarConcept/CarConcept.glb") else {
        return;
    };
    let (Some(gltfpack), Some(basisu)) = (trisort_testkit::gltfpack(), trisort_testkit::basisu())
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let plain_file = pack(&gltfpack, &car, d, "noq", &["-noq"]);
    let plain = timed_load(&plain_file);
    let bytes = std::fs::read(&plain_file).unwrap();
    for (name, options, fallback, min_psnr) in [
        // ETC1S at basisu's default quality, as gltfpack -tc writes, without a fallback.
        // Its lowest PSNR, 21.6 dB, is a 128x128 detail map; most are above 30 dB.
        ("etc1s", &[][..], false, 20.0),
        // UASTC at its fastest level, with the PNG fallback the extension image wins over.
        // Its lowest, 25.4 dB, is the same map.
        ("uastc", &["-uastc", "-uastc_level", "0"][..], true, 24.0),
    ] {
        let file = d.join(format!("{name}.glb"));
        let start = std::time::Instant::now();
        let packed = with_ktx2_images(&bytes, &basisu, d, options, fallback);
        eprintln!("{name}: encoded in {:.1} s", start.elapsed().as_secs_f64());
        std::fs::write(&file, packed).unwrap();
        let scene = timed_load(&file);
        let (lowest, differs) = same_but_texels(&plain, &scene, name, min_psnr);
        eprintln!("{name}: lowest PSNR {lowest:.1} dB");
        assert!(
            differs,
            "{name}: the fallback PNGs were read, not the KTX2 images"
        );
    }
    hostile_ktx2_images_are_errors(&std::fs::read(d.join("etc1s.glb")).unwrap(), d);
}

/// A KTX2 image cut short or corrupt is an error naming the file, the image, the texture and
/// the problem, never a panic. Checked on one textured triangle carrying a real KTX2 image of
/// `bytes` (the smallest of more than 4 KiB), so that each of the many loads is quick.
fn hostile_ktx2_images_are_errors(bytes: &[u8], dir: &Path) {
    let (json, bin) = glb_parts(bytes);
    let views = json["bufferViews"].as_array().unwrap();
    let ktx2 = (json["images"].as_array().unwrap().iter())
        .filter(|i| i["mimeType"] == "image/ktx2")
        .map(|i| {
            let view = &views[i["bufferView"].as_u64().unwrap() as usize];
            let offset = view["byteOffset"].as_u64().unwrap() as usize;
            &bin[offset..offset + view["byteLength"].as_u64().unwrap() as usize]
        })
        .filter(|k| k.len() > 4096)
        .min_by_key(|k| k.len())
        .unwrap();
    // A triangle (36 bytes of positions, 24 of uvs) whose material samples the image.
    let mut triangle = Vec::new();
    for x in [
        0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0,
    ] {
        triangle.extend(x.to_le_bytes());
    }
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_texture_basisu"],
        "extensionsRequired": ["KHR_texture_basisu"],
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"extensions": {"KHR_texture_basisu": {"source": 0}}}],
        "images": [{"bufferView": 2, "mimeType": "image/ktx2"}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}],
        "bufferViews": [
            {"buffer": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 24},
            {"buffer": 0, "byteOffset": 60, "byteLength": ktx2.len()}],
        "buffers": [{"byteLength": 60 + ktx2.len()}]
    });
    let with = |ktx2: &[u8]| [&triangle[..], ktx2].concat();
    let file = dir.join("lie.glb");
    std::fs::write(&file, glb(&json, &with(ktx2))).unwrap();
    let scene = load(&file).unwrap();
    assert_eq!(scene.geometry.textures.len(), 1);
    let check = |json: &serde_json::Value, ktx2: &[u8], problem: &str| {
        std::fs::write(&file, glb(json, &with(ktx2))).unwrap();
        let err = load(&file).unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, SceneError::Image { .. }), "{text}");
        assert!(text.contains("lie.glb: image 0"), "{text}");
        assert!(text.contains("texture 0 (KHR_texture_basisu)"), "{text}");
        assert!(text.contains(problem), "{problem}: {text}");
    };
    // The identifier broken.
    let mut broken = ktx2.to_vec();
    broken[1] = b'X';
    check(&json, &broken, "does not start with the KTX2 identifier");
    // The file cut: inside its header, after it, half of it.
    for (cut, problem) in [
        (30, "cut inside its header"),
        (80, "transcoder"),
        (ktx2.len() / 2, "KTX2"),
    ] {
        let mut json = json.clone();
        json["bufferViews"][2]["byteLength"] = cut.into();
        check(&json, ktx2, problem);
    }
    // Eight bytes overwritten at every fourth offset of the header, the level index, the
    // data format descriptor and the start of the BasisLZ global data, then across the
    // payload: an error or (where the transcoder cannot tell) other texels, never a panic.
    let offsets = (0..1024.min(ktx2.len())).step_by(4);
    for at in offsets.chain((1024..ktx2.len()).step_by(ktx2.len() / 64)) {
        let mut bytes = ktx2.to_vec();
        let end = (at + 8).min(bytes.len());
        bytes[at..end].fill(0xA5);
        std::fs::write(&file, glb(&json, &with(&bytes))).unwrap();
        if let Err(err) = load(&file) {
            let text = err.to_string();
            assert!(
                text.contains("lie.glb") && text.contains("KHR_texture_basisu"),
                "{text}"
            );
        }
    }
}

#[test]
fn webp_textures_of_car_concept_import() {
    let Some(car) = trisort_testkit::scene_path("CarConcept/CarConcept.glb") else {
        return;
    };
    let (Some(gltfpack), Some(transform)) = (
        trisort_testkit::gltfpack(),
        trisort_testkit::gltf_transform(),
    ) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let plain_file = pack(&gltfpack, &car, d, "noq", &["-noq"]);
    let plain = timed_load(&plain_file);
    let webp = d.join("webp.glb");
    let status = std::process::Command::new(&transform)
        .arg("webp")
        .arg(&plain_file)
        .arg(&webp)
        .status()
        .unwrap();
    assert!(status.success(), "gltf-transform webp failed");
    let (json, _) = glb_parts(&std::fs::read(&webp).unwrap());
    assert_eq!(
        json["extensionsRequired"],
        serde_json::json!(["EXT_texture_webp"])
    );
    let scene = timed_load(&webp);
    let (lowest, differs) = same_but_texels(&plain, &scene, "webp", 20.0);
    eprintln!("webp: lowest PSNR {lowest:.1} dB");
    assert!(differs, "lossy WebP gave the PNGs' texels exactly");
}

/// A texture's `KHR_texture_basisu` / `EXT_texture_webp` source that is not an image of the
/// file is an error naming the texture, never a panic.
#[test]
fn bad_texture_extension_sources_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("src.gltf");
    for (ext, source, problem) in [
        (
            "KHR_texture_basisu",
            "\"x\"",
            "texture 0: KHR_texture_basisu source is \"x\"",
        ),
        (
            "EXT_texture_webp",
            "-1",
            "texture 0: EXT_texture_webp source is -1",
        ),
        (
            "KHR_texture_basisu",
            "7",
            "textures[0].source: Index out of bounds",
        ),
    ] {
        let gltf = format!(
            r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["{ext}"],"extensionsRequired":["{ext}"],
            "scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":0}}]}}],
            "materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}}}}],
            "textures":[{{"extensions":{{"{ext}":{{"source":{source}}}}}}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}}],
            "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}}]}}"#
        );
        std::fs::write(&file, gltf).unwrap();
        let err = load(&file).unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, SceneError::Malformed { .. }), "{text}");
        assert!(text.contains("src.gltf"), "{text}");
        assert!(text.contains(problem), "{problem}: {text}");
    }
}
