//! `export-order`: a host that loads the original glTF into its own buffers and draws the
//! ORDER file's triangles reproduces the player's frames exactly.
//!
//! The rebuild here reads the .glb with the `gltf` crate alone (not trisort's importer): per
//! ORDER entry, the primitive's positions, normals and texture coordinates at the triangle's
//! three indices. Exactness needs a one-to-one order, so the bake keeps its intersections
//! (`--keep-intersections`): a split bake draws pieces of a source triangle, which the
//! original triangle cannot stand for (docs/FORMAT.md § ORDER); the split case is checked
//! for its mapping only.

use std::collections::HashMap;
use std::path::Path;
use std::process::Output;

use glam::Vec3;
use trisort_capi::Order;
use trisort_format::{Baked, FileKind, Vertex};

use crate::support::{args, gpu_tempdir, run, run_json, scene};

/// Runs `trisort export-order BAKED --scene SCENE -o OUT` in `dir`, expecting success or not.
pub fn export_order(dir: &Path, baked: &str, scene: &str, out: &str, ok: bool) -> Output {
    run(
        dir,
        &["export-order", baked, "--scene", scene, "-o", out],
        ok,
    )
}

/// [`export_order`] with `--json`, expecting success: its figures.
pub fn export_order_json(dir: &Path, baked: &str, scene: &str, out: &str) -> serde_json::Value {
    run_json(dir, &["export-order", baked, "--scene", scene, "-o", out])
}

/// The vertex a host builds from glTF primitive data: position, unit normal (as the file's,
/// scaled to unit length), uv (zero for untextured materials, whose shading ignores it).
struct Rebuilt {
    vertices: Vec<Vertex>,
}

/// Rebuilds the index buffer's triangles from the glTF file and the ORDER file, checking each
/// against the baked file's own triangle (same corners, bit for bit, in the same or the
/// flipped winding), and returns the host's vertices (three per ORDER entry, in order) with
/// the winding the baked file draws.
fn rebuild(glb: &Path, baked: &Baked, order: &Order) -> Rebuilt {
    let (doc, buffers, _) = gltf::import(glb).unwrap();
    let meshes: Vec<gltf::Mesh> = doc.meshes().collect();
    let g = &baked.geometry;
    let file_materials = doc.materials().len() as u32;
    // glTF node → the baked file's node, which must be one-to-one and keep names.
    let mut node_of: HashMap<u32, u32> = HashMap::new();
    let mut vertices = Vec::with_capacity(order.triangles.len() * 3);
    for (k, s) in order.triangles.iter().enumerate() {
        let prim = meshes[s.mesh as usize]
            .primitives()
            .nth(s.primitive as usize)
            .expect("primitive exists");
        assert_eq!(
            prim.mode(),
            gltf::mesh::Mode::Triangles,
            "the truck has triangle lists"
        );
        let reader = prim.reader(|b| Some(&buffers[b.index()]));
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
        let textured = prim
            .material()
            .pbr_metallic_roughness()
            .base_color_texture()
            .is_some();
        let uvs: Vec<[f32; 2]> = match reader.read_tex_coords(0) {
            Some(t) if textured => t.into_f32().collect(),
            _ => vec![[0.0; 2]; positions.len()],
        };
        let corners = [0, 1, 2].map(|c| indices[3 * s.triangle as usize + c] as usize);
        let baked_tri = g.triangles[baked.copies[k] as usize];
        let baked_pos = baked_tri.map(|v| g.vertices[v as usize].position);
        let ours = corners.map(|c| positions[c]);
        let flipped = [ours[0], ours[2], ours[1]];
        let winding = if baked_pos == ours {
            [0, 1, 2]
        } else if baked_pos == flipped {
            [0, 2, 1]
        } else {
            panic!("entry {k} ({s:?}): {ours:?} is not the baked triangle {baked_pos:?}");
        };
        let node = g.vertices[baked_tri[0] as usize].node;
        assert_eq!(
            *node_of.entry(s.node).or_insert(node),
            node,
            "entry {k}: node"
        );
        assert_eq!(
            doc.nodes()
                .nth(s.node as usize)
                .unwrap()
                .name()
                .unwrap_or(""),
            g.nodes[node as usize].name,
            "entry {k}: node name"
        );
        let material = prim.material().index().map_or(file_materials, |m| m as u32);
        for w in winding {
            let c = corners[w];
            let n = Vec3::from(normals[c]);
            vertices.push(Vertex {
                position: positions[c],
                normal: (n / n.length()).into(),
                uv: uvs[c],
                material,
                node,
                tangent: [0.0; 4],
                uv1: [0.0; 2],
            });
        }
    }
    let mut nodes: Vec<u32> = node_of.values().copied().collect();
    nodes.sort();
    nodes.dedup();
    assert_eq!(nodes.len(), node_of.len(), "glTF nodes map one-to-one");
    Rebuilt { vertices }
}

#[test]
fn rebuilding_the_order_from_the_gltf_reproduces_the_players_frames() {
    let Some(truck) = scene("CesiumMilkTruck") else {
        return;
    };
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let mut bake = args(
        "bake --path gltf --fps 4 --size 64x48 --samples 4 --keep-intersections -o truck.baked",
    );
    bake.insert(1, &truck);
    run(d, &bake, true);
    let v = export_order_json(d, "truck.baked", &truck, "truck.order");
    let info = run_json(d, &["inspect", "truck.baked"]);
    assert_eq!(v["triangles"], info["index_triangles"]);
    assert_eq!(v["frames"], info["frames"]);
    assert_eq!(v["split"], false);
    assert_eq!(v["repeated_sources"], 0);

    let baked: Baked = trisort_format::read_file(FileKind::Baked, &d.join("truck.baked")).unwrap();
    let order = Order::read(&d.join("truck.order")).unwrap();
    assert_eq!(order.ranges.len(), baked.draws.len());
    let rebuilt = rebuild(Path::new(&truck), &baked, &order);

    // The host's draw: its own vertex buffer, indices 0, 1, 2, … in ORDER order, the ORDER
    // ranges per frame. Played by the same player, it must give the same pixels.
    let n = order.triangles.len() as u32;
    let mut host = baked.clone();
    host.geometry.vertices = rebuilt.vertices;
    host.geometry.triangles = (0..n).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]).collect();
    host.scene_ids = (0..n).collect();
    host.copies = (0..n).collect();
    host.removed_edges = vec![Vec::new(); host.frames.len()];
    for (draw, range) in host.draws.iter_mut().zip(&order.ranges) {
        draw.first_index = 3 * range.first;
        draw.index_count = 3 * range.count;
    }
    host.check_structure().unwrap();
    trisort_format::write_file_atomic(FileKind::Baked, &d.join("host.baked"), &host).unwrap();
    for (file, out) in [("truck.baked", "player"), ("host.baked", "host")] {
        run(
            d,
            &["play", file, "--out-dir", out, "--mode", "blend"],
            true,
        );
    }
    let mut compared = 0;
    for f in 0..baked.frames.len() {
        let name = format!("frame-{f:05}.png");
        let a = image::open(d.join("player").join(&name))
            .unwrap()
            .to_rgba8();
        let b = image::open(d.join("host").join(&name)).unwrap().to_rgba8();
        assert!(
            a == b,
            "frame {f}: the rebuilt order draws different pixels"
        );
        compared += 1;
    }
    assert!(compared >= 4);
}

#[test]
fn split_bakes_map_every_piece_to_its_source_and_wrong_scenes_are_refused() {
    let (Some(truck), Some(bunny)) = (scene("CesiumMilkTruck"), scene("StanfordBunny")) else {
        return;
    };
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    let mut bake = args("bake --path gltf --fps 4 --size 64x48 --samples 4 -o split.baked");
    bake.insert(1, &truck);
    run(d, &bake, true);
    let v = export_order_json(d, "split.baked", &truck, "split.order");
    assert_eq!(v["split"], true);
    let baked: Baked = trisort_format::read_file(FileKind::Baked, &d.join("split.baked")).unwrap();
    let order = Order::read(&d.join("split.order")).unwrap();
    assert!(order.split);
    assert_eq!(order.triangles.len(), baked.copies.len());
    // Every piece names a real triangle of its primitive.
    let (doc, _, _) = gltf::import(&truck).unwrap();
    for s in &order.triangles {
        let prim = doc
            .meshes()
            .nth(s.mesh as usize)
            .unwrap()
            .primitives()
            .nth(s.primitive as usize)
            .unwrap();
        let count = prim.indices().map_or(0, |a| a.count()) / 3;
        assert!((s.triangle as usize) < count, "{s:?}");
    }

    let out = export_order(d, "split.baked", &bunny, "wrong.order", false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("not the scene") && err.contains("split.baked"),
        "{err}"
    );
    assert!(!d.join("wrong.order").exists(), "no output on failure");
    let out = export_order(d, "split.baked", "demo", "wrong.order", false);
    assert!(String::from_utf8_lossy(&out.stderr).contains(".glb/.gltf"));
    let out = export_order(d, "split.baked", "demolition.glb", "wrong.order", false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("demolition.glb") && !err.contains("procedural demo car"),
        "a missing file is not the demo car: {err}"
    );
    std::fs::write(d.join("junk.baked"), b"TRISBAK\0junk").unwrap();
    let out = export_order(d, "junk.baked", &truck, "wrong.order", false);
    assert!(String::from_utf8_lossy(&out.stderr).contains("junk.baked"));
}
