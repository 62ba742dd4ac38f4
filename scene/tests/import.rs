//! glTF import on the shared real scenes: counts, materials, textures, animations, nodes.

use glam::{DMat4, Vec3};
use trisort_format::{world_transforms, AlphaMode, NodePose};
use trisort_scene::{load, Property, Scene};
use trisort_testkit::scene_path;

/// Imports a shared scene, or `None` to skip (see [`scene_path`]).
fn import(rel: &str) -> Option<Scene> {
    let path = scene_path(rel)?;
    Some(load(&path).unwrap_or_else(|e| panic!("{e}")))
}

/// Structural invariants every imported scene must satisfy.
fn check_invariants(scene: &Scene) {
    let g = &scene.geometry;
    for (i, n) in g.nodes.iter().enumerate() {
        if let Some(p) = n.parent {
            assert!((p as usize) < i, "node {i}: parent {p} does not precede it");
        }
        assert!(n.rest.iter().all(|x| x.is_finite()));
    }
    for v in &g.vertices {
        assert!((v.node as usize) < g.nodes.len());
        assert!((v.material as usize) < g.materials.len());
        assert!(v.position.iter().all(|x| x.is_finite()));
        let len = Vec3::from(v.normal).length();
        assert!(
            len == 0.0 || (len - 1.0).abs() < 1e-4,
            "normal length {len}"
        );
    }
    for t in &g.triangles {
        assert!(t.iter().all(|&v| (v as usize) < g.vertices.len()));
        let a = g.vertices[t[0] as usize];
        assert!(t.iter().all(|&v| {
            let v = g.vertices[v as usize];
            v.node == a.node && v.material == a.material
        }));
    }
    for m in &g.materials {
        if let Some(t) = m.base_color_texture {
            assert!((t as usize) < g.textures.len());
        }
    }
    for t in &g.textures {
        assert_eq!(
            t.rgba8.len(),
            (t.width * t.height * 4) as usize,
            "{}",
            t.name
        );
    }
    assert_eq!(scene.stats.triangles, g.triangles.len() as u64);
    assert_eq!(scene.stats.nodes, g.nodes.len() as u64);
    assert_eq!(scene.stats.textures, g.textures.len() as u64);
    assert!(scene.stats.zero_area_triangles <= scene.stats.triangles);
    for a in &scene.animations {
        for c in &a.channels {
            assert!((c.node as usize) < g.nodes.len());
        }
    }
}

fn expect_triangles(rel: &str, expected: u64) -> Option<Scene> {
    let scene = import(rel)?;
    assert_eq!(scene.stats.triangles, expected, "{rel}");
    check_invariants(&scene);
    Some(scene)
}

#[test]
fn car_concept_counts_glass_and_door_node() {
    let Some(scene) = expect_triangles("CarConcept/CarConcept.glb", 213_347) else {
        return;
    };
    assert_eq!(scene.name, "CarConcept");
    let g = &scene.geometry;
    assert_eq!(scene.stats.nodes, 101);
    assert_eq!(scene.stats.meshes, 97);
    assert_eq!(scene.stats.materials, 29);
    let glass = g
        .materials
        .iter()
        .position(|m| m.name == "Glass")
        .expect("a Glass material");
    assert!(g.materials[glass].transmission > 0.0);
    assert!(g
        .triangles
        .iter()
        .enumerate()
        .any(|(t, _)| g.triangle_material(t as u32) == glass as u32));
    // Emissive strength multiplies the emissive factor of the lights.
    assert!(g
        .materials
        .iter()
        .any(|m| m.emissive.iter().any(|&c| c > 1.0)));
    // Clearcoat is read (see import_pbr); iridescence is not rendered, and said so.
    assert!(scene
        .notes
        .iter()
        .any(|n| n.contains("KHR_materials_iridescence")));
    assert!(!scene
        .notes
        .iter()
        .any(|n| n.contains("KHR_materials_transmission")));

    // The driver's door moves its own triangles and nothing else.
    let door = scene.node_by_name("BodyDoorLColor1").expect("door node");
    let hood = scene.node_by_name("BodyHood").expect("hood node");
    let rest = DMat4::from_cols_array(&g.nodes[door as usize].rest);
    let pose = NodePose {
        node: door,
        local: (rest * DMat4::from_rotation_y(0.5)).to_cols_array(),
    };
    let still = world_transforms(&g.nodes, &[]);
    let moved = world_transforms(&g.nodes, &[pose]);
    let world_of = |w: &[DMat4], t: u32| {
        let v = g.vertices[g.triangles[t as usize][0] as usize];
        w[v.node as usize].transform_point3(Vec3::from(v.position).as_dvec3())
    };
    let door_tris: Vec<u32> = (0..g.triangles.len() as u32)
        .filter(|&t| g.triangle_node(t) == door)
        .collect();
    assert!(
        door_tris.len() > 100,
        "door has {} triangles",
        door_tris.len()
    );
    let displaced = door_tris
        .iter()
        .filter(|&&t| (world_of(&moved, t) - world_of(&still, t)).length() > 1e-3)
        .count();
    assert!(
        displaced > door_tris.len() / 2,
        "{displaced} of {} moved",
        door_tris.len()
    );
    let hood_tri = (0..g.triangles.len() as u32)
        .find(|&t| g.triangle_node(t) == hood)
        .expect("hood triangles");
    assert_eq!(world_of(&moved, hood_tri), world_of(&still, hood_tri));
}

#[test]
fn glass_vase_flowers_has_blend_mask_and_textures() {
    let Some(scene) = expect_triangles("GlassVaseFlowers/GlassVaseFlowers.glb", 14_036) else {
        return;
    };
    let g = &scene.geometry;
    let mask = g
        .materials
        .iter()
        .position(|m| m.alpha_mode == AlphaMode::Mask)
        .expect("a MASK material");
    assert!(g.materials.iter().any(|m| m.alpha_mode == AlphaMode::Blend));
    assert!(g.materials.iter().any(|m| m.transmission > 0.0));
    let tex = g.materials[mask]
        .base_color_texture
        .expect("foliage texture");
    let t = &g.textures[tex as usize];
    assert!(t.width >= 64 && t.height >= 64);
    // Base colour (sRGB), metallic-roughness and normal maps (linear) are decoded; the volume
    // extension's thickness texture is not.
    assert_eq!(g.textures.len(), 3);
    assert!(t.srgb);
    let flowers = &g.materials[mask];
    for slot in [flowers.metallic_roughness_texture, flowers.normal_texture] {
        assert!(!g.textures[slot.expect("a map").texture as usize].srgb);
    }
    // The foliage texture has cut-out texels and its vertices carry texture coordinates.
    assert!(t.rgba8.chunks_exact(4).any(|p| p[3] < 128));
    assert!(g
        .vertices
        .iter()
        .any(|v| v.material == mask as u32 && v.uv != [0.0, 0.0]));
    assert!(scene
        .notes
        .iter()
        .any(|n| n.contains("KHR_materials_volume")));
}

#[test]
fn cesium_milk_truck_wheels_rotate() {
    let Some(scene) = expect_triangles("CesiumMilkTruck/CesiumMilkTruck.glb", 3_624) else {
        return;
    };
    // Two textures share one image: decoded once.
    assert_eq!(scene.geometry.textures.len(), 1);
    assert!(!scene.animations.is_empty());
    let mut wheel_channels = 0;
    for c in scene.animations.iter().flat_map(|a| &a.channels) {
        let name = &scene.geometry.nodes[c.node as usize].name;
        assert_eq!(c.property, Property::Rotation);
        assert!(name.starts_with("Wheels"), "channel on {name}");
        assert_eq!(c.values.len(), 4 * c.times.len());
        assert!(c.times.windows(2).all(|w| w[0] <= w[1]));
        wheel_channels += 1;
        // The wheel node carries wheel triangles.
        assert!(
            (0..scene.stats.triangles as u32).any(|t| scene.geometry.triangle_node(t) == c.node)
        );
    }
    assert_eq!(wheel_channels, 2);
}

#[test]
fn alpha_blend_mode_test_counts() {
    let Some(scene) = expect_triangles("AlphaBlendModeTest/AlphaBlendModeTest.glb", 61) else {
        return;
    };
    let cutoffs: Vec<f32> = scene
        .geometry
        .materials
        .iter()
        .filter(|m| m.alpha_mode == AlphaMode::Mask)
        .map(|m| m.alpha_cutoff)
        .collect();
    assert!(cutoffs.contains(&0.25) && cutoffs.contains(&0.75) && cutoffs.contains(&0.5));
}

#[test]
fn stanford_bunny_counts() {
    let Some(scene) = expect_triangles("StanfordBunny/StanfordBunny.glb", 144_046) else {
        return;
    };
    assert_eq!(scene.stats.meshes, 1);
    let (lo, hi) = scene.bounds().expect("bounds");
    assert!((hi - lo).min_element() > 0.0);
}

#[test]
fn fps_map_counts() {
    let Some(scene) = expect_triangles("FpsMap/FpsMap.glb", 58_758) else {
        return;
    };
    assert_eq!(scene.stats.nodes, 529);
    assert_eq!(scene.stats.meshes, 295);
}
