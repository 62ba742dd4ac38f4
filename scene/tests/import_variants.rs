//! `KHR_materials_variants` tables: per variant, the material each slot
//! shows; primitives that share a material but map it differently get slots of their own;
//! mappings naming what the file lacks are left out with a note, never an error.

use std::path::Path;

use trisort_scene::load;

/// A two-node file: both nodes' meshes use material 0 ("base"); `mappings` are the two
/// primitives' `KHR_materials_variants` mapping lists (JSON), over materials base, red, blue
/// and variants "Red", "Blue".
fn file(dir: &Path, mappings: [&str; 2]) -> std::path::PathBuf {
    let prim = |m: &str| {
        format!(
            r#"{{"attributes":{{"POSITION":0}},"material":0,"extensions":{{"KHR_materials_variants":{{"mappings":{m}}}}}}}"#
        )
    };
    let text = format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["KHR_materials_variants"],
        "extensions":{{"KHR_materials_variants":{{"variants":[{{"name":"Red"}},{{"name":"Blue"}}]}}}},
        "scene":0,"scenes":[{{"nodes":[0,1]}}],"nodes":[{{"mesh":0}},{{"mesh":1}}],
        "materials":[{{"name":"base"}},{{"name":"red"}},{{"name":"blue"}}],
        "meshes":[{{"primitives":[{}]}},{{"primitives":[{}]}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}}]}}"#,
        prim(mappings[0]),
        prim(mappings[1])
    );
    let path = dir.join("v.gltf");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn primitives_mapped_alike_share_a_slot() {
    let dir = tempfile::tempdir().unwrap();
    let m = r#"[{"material":1,"variants":[0]},{"material":2,"variants":[1]}]"#;
    let scene = load(&file(dir.path(), [m, m])).unwrap();
    let g = &scene.geometry;
    assert_eq!(g.materials.len(), 3);
    assert!(g.vertices.iter().all(|v| v.material == 0));
    assert_eq!(g.variants.len(), 2);
    assert_eq!(
        (g.variants[0].name.as_str(), &g.variants[0].materials[..]),
        ("Red", &[1, 1, 2][..])
    );
    assert_eq!(
        (g.variants[1].name.as_str(), &g.variants[1].materials[..]),
        ("Blue", &[2, 1, 2][..])
    );
    g.check_structure().unwrap();
    let red = g.variant_materials(Some("Red")).unwrap();
    assert_eq!(red[0].name, "red");
}

#[test]
fn primitives_mapped_differently_get_a_slot_each() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load(&file(
        dir.path(),
        [
            r#"[{"material":1,"variants":[0]}]"#,
            r#"[{"material":2,"variants":[0,1]}]"#,
        ],
    ))
    .unwrap();
    let g = &scene.geometry;
    // Triangle 0 (node 0) keeps slot 0; triangle 1 (node 1) gets a copy of "base" in slot 3.
    assert_eq!(g.materials.len(), 4);
    assert_eq!(g.materials[3], g.materials[0]);
    assert_eq!((g.triangle_material(0), g.triangle_material(1)), (0, 3));
    assert_eq!(g.variants[0].materials, [1, 1, 2, 2]);
    assert_eq!(g.variants[1].materials, [0, 1, 2, 2]);
    g.check_structure().unwrap();
}

#[test]
fn mappings_naming_what_the_file_lacks_are_left_out_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load(&file(
        dir.path(),
        [
            r#"[{"material":7,"variants":[0]},{"material":1,"variants":[5,"x"]}]"#,
            r#"[{"material":2,"variants":[1]},{"material":1,"variants":[1]}]"#,
        ],
    ))
    .unwrap();
    let g = &scene.geometry;
    g.check_structure().unwrap();
    assert_eq!(
        scene
            .notes
            .iter()
            .filter(|n| n.contains("left out"))
            .count(),
        4,
        "{:?}",
        scene.notes
    );
    // Node 0's primitive keeps its default under both; node 1's shows blue under "Blue".
    assert_eq!(g.variants[1].materials[g.triangle_material(1) as usize], 2);
    assert_eq!(
        g.variants[1].materials[g.triangle_material(0) as usize],
        g.triangle_material(0)
    );
}

#[test]
fn car_concept_has_one_table_per_paint() {
    let Some(car) = trisort_testkit::scene_path("CarConcept/CarConcept.glb") else {
        return;
    };
    let scene = load(&car).unwrap();
    let g = &scene.geometry;
    g.check_structure().unwrap();
    let name = |m: u32| g.materials[m as usize].name.as_str();
    let names: Vec<&str> = g.variants.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(
        names,
        ["Carmine Candy", "Pearly Swirly", "Torched Graphite"]
    );
    // Its primitives map consistently: no slot is added.
    assert_eq!(g.materials.len(), scene.stats.materials as usize);
    for (v, paint) in g.variants.iter().zip(["Carmine", "Pearl", "Graphite"]) {
        for (slot, base) in [(11, "Paint 1"), (10, "Paint 2"), (6, "Interior 3")] {
            assert_eq!(name(v.materials[slot]), format!("{base} {paint}"));
        }
        let changed = (v.materials.iter().enumerate())
            .filter(|&(s, &m)| s as u32 != m)
            .count();
        assert_eq!(changed, if paint == "Carmine" { 0 } else { 3 });
        g.variant_materials(Some(&v.name)).unwrap();
    }
}
