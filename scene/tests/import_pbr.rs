//! glTF import of what physically based shading uses: metallic-roughness, normal, occlusion and
//! emissive texture slots with `KHR_texture_transform`, clearcoat, TEXCOORD_1, tangents (the
//! file's, or MikkTSpace's), textures per colour space with mip chains; and refusals or notes
//! for malformed values.

use glam::Vec3;
use serde_json::{json, Value};
use trisort_format::{Geometry, Material, Texture};
use trisort_scene::{load, Scene, SceneError};
use trisort_testkit::scene_path;

use crate::gltf_builder::{base64, load_text, tiny_png, Builder};

fn material<'g>(g: &'g Geometry, name: &str) -> &'g Material {
    g.materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name:?}"))
}

/// The vertices of the triangles drawn with material `m`.
fn vertices_of(g: &Geometry, m: usize) -> impl Iterator<Item = &trisort_format::Vertex> {
    (g.triangles.iter())
        .filter(move |t| g.vertices[t[0] as usize].material == m as u32)
        .flat_map(move |t| t.iter().map(move |&v| &g.vertices[v as usize]))
}

/// Every texture is stored at most 1024 texels a side with its full mip chain, and the
/// geometry passes the format's structure check.
fn check_textures(g: &Geometry) {
    g.check_structure().unwrap();
    for t in &g.textures {
        assert!(
            t.width <= 1024 && t.height <= 1024,
            "{} {}x{}",
            t.name,
            t.width,
            t.height
        );
        assert_eq!(
            t.mips.len(),
            Texture::mip_count(t.width, t.height),
            "{}",
            t.name
        );
    }
}

/// Unit xyz orthogonal to the normal (|cos| below `slack`) and w ±1.
fn assert_tangent_frame(v: &trisort_format::Vertex, slack: f32) {
    let t = Vec3::from_slice(&v.tangent[..3]);
    let n = Vec3::from(v.normal);
    assert!((t.length() - 1.0).abs() < 1e-4, "tangent {:?}", v.tangent);
    assert!(
        t.dot(n).abs() < slack,
        "tangent {:?} normal {:?}",
        v.tangent,
        v.normal
    );
    assert!(
        v.tangent[3] == 1.0 || v.tangent[3] == -1.0,
        "{:?}",
        v.tangent
    );
}

#[test]
fn car_concept_reads_every_pbr_slot_clearcoat_tangents_and_uv1() {
    let Some(path) = scene_path("CarConcept/CarConcept.glb") else {
        return;
    };
    let scene = load(&path).unwrap();
    let g = &scene.geometry;
    check_textures(g);

    // The contract's example: the paints' normal textures repeat 30×30, Paint 2 rotated.
    let paint1 = material(g, "Paint 1 Carmine");
    let normal = paint1.normal_texture.expect("Paint 1 normal texture");
    assert_eq!(normal.transform.scale, [30.0, 30.0]);
    assert_eq!(normal.transform.rotation, 0.0);
    assert_eq!(normal.tex_coord, 0);
    assert!((paint1.normal_scale - 0.3).abs() < 1e-6);
    assert_eq!((paint1.clearcoat, paint1.clearcoat_roughness), (1.0, 0.0));
    assert_eq!((paint1.metallic, paint1.roughness), (1.0, 0.25));
    assert!(!g.textures[normal.texture as usize].srgb);
    let paint2 = material(g, "Paint 2 Carmine");
    let normal2 = paint2.normal_texture.expect("Paint 2 normal texture");
    assert_eq!(normal2.transform.rotation, 0.585398);
    assert_eq!(normal2.transform.scale, [30.0, 30.0]);
    assert_eq!(
        normal2.texture, normal.texture,
        "one image, one linear texture"
    );
    assert_eq!(paint2.clearcoat, 0.25);
    // Occlusion samples TEXCOORD_1 at strength 0.85; metallic-roughness and the tyre's
    // offset transform are read too.
    let mech = material(g, "Mechanical");
    let occlusion = mech.occlusion_texture.expect("occlusion");
    assert_eq!(occlusion.tex_coord, 1);
    assert_eq!(mech.occlusion_strength, 0.85);
    assert!(!g.textures[occlusion.texture as usize].srgb);
    let mr = mech.metallic_roughness_texture.expect("metallic-roughness");
    assert!(!g.textures[mr.texture as usize].srgb);
    let tread = material(g, "Tiretread").normal_texture.unwrap();
    assert_eq!(
        (tread.transform.offset, tread.transform.scale),
        ([0.0, 1.5], [1.0, 4.0])
    );
    // Emissive and base-colour textures are sRGB: the licence plate image is both, once.
    let license = material(g, "License");
    let plate = license.base_color_texture.unwrap();
    assert!(g.textures[plate as usize].srgb);
    assert_eq!(
        material(g, "Mirror").emissive_texture.unwrap().texture,
        plate
    );
    let disc = material(g, "Disc");
    assert_eq!(disc.base_color_transform.scale, [20.0, 10.0]);

    // The paint's tangents come from the file (no MikkTSpace copies: one vertex per file
    // vertex), unit and orthogonal to the normal; its vertices carry TEXCOORD_1.
    let slot = g
        .materials
        .iter()
        .position(|m| m.name == "Paint 1 Carmine")
        .unwrap();
    let mut count = 0;
    for v in vertices_of(g, slot) {
        // The file's tangents are not quite orthogonal to its normals (shaders orthogonalise).
        assert_tangent_frame(v, 0.05);
        count += 1;
    }
    assert!(count > 1000, "{count} paint corners");
    assert!(vertices_of(g, slot).any(|v| v.uv1 != [0.0; 2]));
    assert!(vertices_of(g, slot).any(|v| v.uv != [0.0; 2]));
    // Without a normal texture there are no tangents.
    let glass = g.materials.iter().position(|m| m.name == "Glass").unwrap();
    assert!(vertices_of(g, glass).all(|v| v.tangent == [0.0; 4]));

    // What is not rendered is named per material.
    let pearl = scene
        .notes
        .iter()
        .find(|n| n.contains("\"Paint 1 Pearl\"") && n.contains("not rendered"))
        .expect("a note on Paint 1 Pearl");
    assert!(pearl.contains("KHR_materials_iridescence"), "{pearl}");
    assert!(!pearl.contains("clearcoatFactor"), "{pearl}");
    assert!(!scene
        .notes
        .iter()
        .any(|n| n.contains("KHR_texture_transform")));
    // The one 2048x2048 image is stored from its 1024x1024 level, and the note says the bytes.
    let capped = scene
        .notes
        .iter()
        .find(|n| n.contains("(2048x2048) is stored from mip level 1 (1024x1024"))
        .expect("a note on the capped image");
    assert!(
        capped.contains("5592404 bytes with its mips instead of 22369620"),
        "{capped}"
    );
}

#[test]
fn glass_vase_flowers_gets_mikktspace_tangents() {
    let Some(path) = scene_path("GlassVaseFlowers/GlassVaseFlowers.glb") else {
        return;
    };
    let scene = load(&path).unwrap();
    let g = &scene.geometry;
    check_textures(g);
    let flowers = g
        .materials
        .iter()
        .position(|m| m.name == "Flowers")
        .unwrap();
    assert!(g.materials[flowers].normal_texture.is_some());
    let (mut corners, mut zero) = (0, 0);
    for v in vertices_of(g, flowers) {
        corners += 1;
        if v.tangent == [0.0; 4] {
            zero += 1;
        } else {
            assert_tangent_frame(v, 1e-4);
        }
    }
    // MikkTSpace leaves a tangent zero only where the texture coordinates are degenerate.
    assert!(
        corners > 1000 && zero * 100 < corners,
        "{zero} of {corners} zero"
    );
    // The other materials have no normal texture and so no tangents.
    let glass = g
        .materials
        .iter()
        .position(|m| m.name == "GlassAlpha")
        .unwrap();
    assert!(vertices_of(g, glass).all(|v| v.tangent == [0.0; 4]));
}

/// A unit quad in the xy plane facing +z, uv = xy, with a normal-mapped material
/// (`material`, merged into a default one), TEXCOORD_1 = 2·xy, drawn by `nodes`.
fn quad_doc(b: &mut Builder, material: Value, normals: bool, indexed: bool) -> Value {
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let order: Vec<usize> = if indexed {
        vec![0, 1, 2, 3]
    } else {
        vec![0, 1, 2, 0, 2, 3]
    };
    let pos: Vec<[f32; 3]> = order.iter().map(|&i| corners[i]).collect();
    let uv: Vec<f32> = pos.iter().flat_map(|p| [p[0], p[1]]).collect();
    let uv1: Vec<f32> = uv.iter().map(|x| 2.0 * x).collect();
    let mut attributes = json!({
        "POSITION": b.vec3(&pos),
        "TEXCOORD_0": b.floats(&uv, "VEC2", pos.len()),
        "TEXCOORD_1": b.floats(&uv1, "VEC2", pos.len()),
    });
    if normals {
        attributes["NORMAL"] = json!(b.vec3(&vec![[0.0, 0.0, 1.0]; pos.len()]));
    }
    let mut prim = json!({"attributes": attributes, "material": 0});
    if indexed {
        prim["indices"] = json!(b.indices(&[0, 1, 2, 0, 2, 3]));
    }
    let mut m = json!({"name": "bumpy", "normalTexture": {"index": 0}});
    for (k, v) in material.as_object().unwrap() {
        m[k] = v.clone();
    }
    let png = format!("data:image/png;base64,{}", base64(&tiny_png()));
    json!({
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim]}],
        "materials": [m],
        "images": [{"uri": png}],
        "textures": [{"source": 0}],
    })
}

#[test]
fn generated_tangents_follow_u_under_mirrors_and_without_normals_or_indices() {
    let dir = tempfile::tempdir().unwrap();
    for (normals, indexed) in [(true, true), (false, true), (true, false), (false, false)] {
        let mut b = Builder::default();
        let mut doc = quad_doc(&mut b, json!({}), normals, indexed);
        // Node 1 mirrors the quad in x: it is drawn with flipped winding, and its local
        // tangents are the plain node's (the frame is the file's, before the flip).
        doc["nodes"] = json!([{"mesh": 0}, {"mesh": 0, "scale": [-1.0, 1.0, 1.0]}]);
        doc["scenes"] = json!([{"nodes": [0, 1]}]);
        let scene = load_text(dir.path(), "quad.gltf", &b.gltf(doc)).unwrap();
        let g = &scene.geometry;
        g.check_structure().unwrap();
        assert_eq!(g.triangles.len(), 4);
        for (t, tri) in g.triangles.iter().enumerate() {
            for &v in tri {
                let v = &g.vertices[v as usize];
                assert_eq!(
                    v.normal,
                    [0.0, 0.0, 1.0],
                    "normals {normals} indexed {indexed}"
                );
                assert_eq!(
                    v.tangent,
                    [1.0, 0.0, 0.0, 1.0],
                    "triangle {t} {normals} {indexed}"
                );
            }
        }
        // The mirrored instance's winding is flipped.
        assert_eq!(
            g.triangles[2],
            [g.triangles[0][0], g.triangles[0][2], g.triangles[0][1]]
                .map(|i| i + g.triangles[2][0] - g.triangles[0][0])
        );
    }
}

#[test]
fn tangents_are_generated_from_the_normal_textures_set_and_split_at_mirrored_uvs() {
    let dir = tempfile::tempdir().unwrap();
    // On TEXCOORD_1 (2·xy) the tangent is still +x.
    let mut b = Builder::default();
    let doc = quad_doc(
        &mut b,
        json!({"normalTexture": {"index": 0, "texCoord": 1}}),
        true,
        true,
    );
    let scene = load_text(dir.path(), "set1.gltf", &b.gltf(doc)).unwrap();
    let g = &scene.geometry;
    assert_eq!(g.materials[0].normal_texture.unwrap().tex_coord, 1);
    assert!(g.vertices.iter().all(|v| v.tangent == [1.0, 0.0, 0.0, 1.0]));
    assert_eq!(g.vertices[2].uv1, [2.0, 2.0]);
    assert_eq!(
        g.vertices[2].uv,
        [0.0, 0.0],
        "TEXCOORD_0 is sampled by no slot"
    );

    // The second triangle's uv is mirrored in u: the vertices it shares with the first get a
    // copy with the other handedness.
    let mut b = Builder::default();
    let mut doc = quad_doc(&mut b, json!({}), true, true);
    let uv = b.floats(&[0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 2.0, 1.0], "VEC2", 4);
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(uv);
    let scene = load_text(dir.path(), "mirrored.gltf", &b.gltf(doc)).unwrap();
    let g = &scene.geometry;
    assert_eq!(g.vertices.len(), 6, "two shared vertices copied");
    let w = |t: usize| g.triangles[t].map(|v| g.vertices[v as usize].tangent[3]);
    assert_eq!(w(0), [1.0; 3]);
    assert_eq!(w(1), [-1.0; 3]);
    for v in &g.vertices {
        assert_tangent_frame(v, 1e-6);
    }
}

fn malformed(material: Value) -> Result<Scene, SceneError> {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let doc = quad_doc(&mut b, material, true, true);
    load_text(dir.path(), "bad.gltf", &b.gltf(doc))
}

#[test]
fn malformed_transforms_and_clearcoat_are_errors_naming_file_and_material() {
    let transform = |t: Value| json!({"normalTexture": {"index": 0, "extensions": {"KHR_texture_transform": t}}});
    for (material, expected) in [
        (
            transform(json!({"rotation": "x"})),
            "normal texture: rotation \"x\" is not a finite number",
        ),
        (
            transform(json!({"scale": [1.0]})),
            "scale [1.0] is not an array of two numbers",
        ),
        (
            transform(json!({"offset": [0.0, 1e300]})),
            "offset 1e+300 is not a finite number",
        ),
        (
            transform(json!({"texCoord": -1})),
            "texCoord -1 is not a non-negative integer",
        ),
        (transform(json!(3)), "3 is not an object"),
        (
            json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"rotation": null}}}}}),
            "base-colour texture: rotation null",
        ),
        (
            json!({"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": "a"}}}),
            "clearcoatFactor is \"a\", not a number from 0 to 1",
        ),
        (
            json!({"extensions": {"KHR_materials_clearcoat": {"clearcoatRoughnessFactor": 2.0}}}),
            "clearcoatRoughnessFactor is 2.0",
        ),
        (
            json!({"extensions": {"KHR_materials_clearcoat": []}}),
            "KHR_materials_clearcoat: is not an object",
        ),
    ] {
        let err = malformed(material).unwrap_err();
        assert!(matches!(err, SceneError::Malformed { .. }), "{err:?}");
        let text = err.to_string();
        for needle in ["bad.gltf", "material 0 \"bumpy\"", expected] {
            assert!(text.contains(needle), "{text:?} lacks {needle:?}");
        }
    }
}

#[test]
fn texture_coordinate_sets_above_one_are_noted_and_read_as_zero() {
    let transform = json!({"KHR_texture_transform": {"texCoord": 2, "rotation": 0.5}});
    let scene = malformed(json!({
        "normalTexture": {"index": 0, "texCoord": 1, "extensions": transform},
        "occlusionTexture": {"index": 0, "texCoord": 7},
        "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 0.5, "clearcoatTexture": {"index": 0}},
                       "KHR_materials_sheen": {"sheenColorFactor": [1.0, 1.0, 1.0]}}
    }))
    .unwrap();
    let m = &scene.geometry.materials[0];
    let normal = m.normal_texture.unwrap();
    assert_eq!((normal.tex_coord, normal.transform.rotation), (0, 0.5));
    assert_eq!(m.occlusion_texture.unwrap().tex_coord, 0);
    assert_eq!(m.clearcoat, 0.5);
    for needle in [
        "material 0 \"bumpy\" samples its normal texture with TEXCOORD_2",
        "material 0 \"bumpy\" samples its occlusion texture with TEXCOORD_7",
    ] {
        assert!(
            scene.notes.iter().any(|n| n.contains(needle)),
            "{:?} lacks {needle}",
            scene.notes
        );
    }
    let ignored = scene
        .notes
        .iter()
        .find(|n| n.contains("not rendered"))
        .unwrap();
    assert!(
        ignored.contains("KHR_materials_clearcoat clearcoatTexture"),
        "{ignored}"
    );
    assert!(ignored.contains("KHR_materials_sheen"), "{ignored}");
    // One image used as normal and occlusion (both linear) is one texture.
    assert_eq!(scene.geometry.textures.len(), 1);
}

#[test]
fn an_image_used_as_colour_and_data_is_stored_once_per_colour_space() {
    let scene = malformed(json!({
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
        "emissiveTexture": {"index": 0}
    }))
    .unwrap();
    let g = &scene.geometry;
    let m = &g.materials[0];
    assert_eq!(g.textures.len(), 2);
    let colour = m.base_color_texture.unwrap();
    assert_eq!(m.emissive_texture.unwrap().texture, colour);
    assert!(g.textures[colour as usize].srgb);
    let data = m.normal_texture.unwrap().texture;
    assert_ne!(data, colour);
    assert!(!g.textures[data as usize].srgb);
    assert_eq!(
        g.textures[data as usize].rgba8,
        g.textures[colour as usize].rgba8
    );
    // The 2×2 image's 1×1 level averages its four texels: in linear light for colour.
    assert_eq!(g.textures[data as usize].mips.len(), 1);
    assert_ne!(
        g.textures[data as usize].mips,
        g.textures[colour as usize].mips
    );
}
