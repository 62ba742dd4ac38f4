//! Tests of the procedural demo car and of its glTF export.

use std::collections::HashMap;

use glam::{DMat4, DVec3, Vec3};
use trisort_format::{world_transforms, NodePose};
use trisort_scene::demo_car::{
    demo_car, DEFAULT_TRIANGLES, DOOR_MAX_OPEN_DEGREES, DOOR_NODE, DOOR_WINDOW_NODE, GLASS_MATERIAL,
};
use trisort_scene::Scene;

/// One connected part of a scene: its triangles (scene ids) and material.
struct Part {
    triangles: Vec<u32>,
    material: u32,
}

/// World-space corners of every triangle, with the given node poses.
fn world_triangles(scene: &Scene, poses: &[NodePose]) -> Vec<[DVec3; 3]> {
    let g = &scene.geometry;
    let world = world_transforms(&g.nodes, poses);
    g.triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                let v = &g.vertices[v as usize];
                world[v.node as usize].transform_point3(Vec3::from(v.position).as_dvec3())
            })
        })
        .collect()
}

/// Vertex ids welded by (node, exact local position).
fn welded(scene: &Scene) -> Vec<u32> {
    let mut ids = HashMap::new();
    scene
        .geometry
        .vertices
        .iter()
        .map(|v| {
            let key = (v.node, v.position.map(f32::to_bits));
            let n = ids.len() as u32;
            *ids.entry(key).or_insert(n)
        })
        .collect()
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        parent[x as usize] = parent[parent[x as usize] as usize];
        x = parent[x as usize];
    }
    x
}

/// Connected components of the welded mesh.
fn parts(scene: &Scene) -> Vec<Part> {
    let weld = welded(scene);
    let n = weld.iter().max().map_or(0, |m| m + 1);
    let mut parent: Vec<u32> = (0..n).collect();
    for t in &scene.geometry.triangles {
        let [a, b, c] = t.map(|v| weld[v as usize]);
        for (x, y) in [(a, b), (b, c)] {
            let (rx, ry) = (find(&mut parent, x), find(&mut parent, y));
            parent[rx as usize] = ry;
        }
    }
    let mut by_root: HashMap<u32, usize> = HashMap::new();
    let mut out: Vec<Part> = Vec::new();
    for (id, t) in scene.geometry.triangles.iter().enumerate() {
        let root = find(&mut parent, weld[t[0] as usize]);
        let k = *by_root.entry(root).or_insert_with(|| {
            out.push(Part {
                triangles: Vec::new(),
                material: scene.geometry.triangle_material(id as u32),
            });
            out.len() - 1
        });
        assert_eq!(
            out[k].material,
            scene.geometry.triangle_material(id as u32),
            "a part mixes materials"
        );
        out[k].triangles.push(id as u32);
    }
    out
}

fn is_glass(scene: &Scene, material: u32) -> bool {
    scene.geometry.materials[material as usize].transmission > 0.0
}

/// Does segment p→q cross triangle t (Möller–Trumbore, parameter in [0, 1])?
fn segment_hits(p: DVec3, q: DVec3, t: &[DVec3; 3]) -> bool {
    ray_hit(p, q - p, t).is_some_and(|s| s <= 1.0)
}

/// Ray parameter of the hit of o + s·d with triangle t, s ≥ 0.
fn ray_hit(o: DVec3, d: DVec3, t: &[DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det.abs() < 1e-18 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - t[0];
    let u = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = tv.cross(e1);
    let v = d.dot(qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let s = e2.dot(qv) * inv;
    (s >= 0.0).then_some(s)
}

/// Do two triangles intersect (an edge of one crosses the other)?
fn triangles_intersect(a: &[DVec3; 3], b: &[DVec3; 3]) -> bool {
    (0..3).any(|k| segment_hits(a[k], a[(k + 1) % 3], b))
        || (0..3).any(|k| segment_hits(b[k], b[(k + 1) % 3], a))
}

/// Pairs (part, part) whose triangles intersect, found through a uniform grid.
fn intersecting_parts(scene: &Scene, poses: &[NodePose]) -> Vec<(usize, usize)> {
    let tris = world_triangles(scene, poses);
    let parts = parts(scene);
    let mut part_of = vec![0usize; tris.len()];
    for (k, p) in parts.iter().enumerate() {
        for &t in &p.triangles {
            part_of[t as usize] = k;
        }
    }
    const CELL: f64 = 0.05;
    let cell = |p: DVec3| (p / CELL).floor().as_ivec3();
    let mut grid: HashMap<glam::IVec3, Vec<u32>> = HashMap::new();
    for (id, t) in tris.iter().enumerate() {
        let lo = cell(t[0].min(t[1]).min(t[2]));
        let hi = cell(t[0].max(t[1]).max(t[2]));
        for x in lo.x..=hi.x {
            for y in lo.y..=hi.y {
                for z in lo.z..=hi.z {
                    grid.entry(glam::IVec3::new(x, y, z))
                        .or_default()
                        .push(id as u32);
                }
            }
        }
    }
    let mut found = std::collections::BTreeSet::new();
    for ids in grid.values() {
        for (k, &a) in ids.iter().enumerate() {
            for &b in &ids[k + 1..] {
                let (pa, pb) = (part_of[a as usize], part_of[b as usize]);
                if pa != pb
                    && !found.contains(&(pa.min(pb), pa.max(pb)))
                    && triangles_intersect(&tris[a as usize], &tris[b as usize])
                {
                    found.insert((pa.min(pb), pa.max(pb)));
                }
            }
        }
    }
    found.into_iter().collect()
}

fn door_pose(scene: &Scene, degrees: f64) -> NodePose {
    let door = scene.node_by_name(DOOR_NODE).expect("door node");
    let rest = DMat4::from_cols_array(&scene.geometry.nodes[door as usize].rest);
    NodePose {
        node: door,
        local: (rest * DMat4::from_rotation_y(degrees.to_radians())).to_cols_array(),
    }
}

#[test]
fn triangle_count_follows_the_request() {
    for request in [10_000, DEFAULT_TRIANGLES, 1_000_000, 5_000_000] {
        let start = std::time::Instant::now();
        let car = demo_car(request);
        let got = car.geometry.triangles.len() as f64;
        eprintln!(
            "requested {request}: {got} triangles in {:.2} s",
            start.elapsed().as_secs_f64()
        );
        assert!(
            (got - f64::from(request)).abs() <= 0.1 * f64::from(request),
            "requested {request}, got {got}"
        );
        assert_eq!(car.stats.triangles, got as u64);
    }
    // Below the supported range: the coarsest car, still whole.
    let tiny = demo_car(1);
    assert!((1_000..10_000).contains(&tiny.geometry.triangles.len()));
    assert!(tiny.node_by_name(DOOR_NODE).is_some());
}

#[test]
fn generation_is_deterministic() {
    let (a, b) = (demo_car(15_000), demo_car(15_000));
    assert_eq!(a.geometry, b.geometry);
    assert_eq!(a.stats, b.stats);
    assert_ne!(demo_car(30_000).geometry, a.geometry);
}

#[test]
fn stats_and_layout() {
    let car = demo_car(DEFAULT_TRIANGLES);
    let g = &car.geometry;
    assert_eq!(car.name, "demo car");
    assert_eq!(car.stats.zero_area_triangles, 0);
    assert_eq!(car.stats.nodes, g.nodes.len() as u64);
    assert_eq!(car.stats.materials, g.materials.len() as u64);
    assert_eq!(car.stats.textures, 1);
    // Every part is one connected surface with one material.
    assert_eq!(car.stats.meshes, parts(&car).len() as u64);
    for t in world_triangles(&car, &[]) {
        assert!((t[1] - t[0]).cross(t[2] - t[0]).length() > 0.0);
    }
    for (k, n) in g.nodes.iter().enumerate() {
        assert!(n.parent.is_none_or(|p| (p as usize) < k));
    }
    // Metres, Y up, on the ground, centred, front towards +Z.
    let (lo, hi) = car.bounds().unwrap();
    let size = hi - lo;
    assert!((4.1..4.4).contains(&size.z), "length {size}");
    assert!((1.6..2.0).contains(&size.x) && (1.2..1.6).contains(&size.y));
    assert!(lo.y.abs() < 1e-3, "not on the ground: {lo}");
    assert!((lo.x + hi.x).abs() < 1e-3 && (lo.z + hi.z).abs() < 0.05);
    // The texture is RGBA8 of the stated size, used by a material with UVs in [0, 1].
    let tex = &g.textures[0];
    assert_eq!(tex.rgba8.len(), (tex.width * tex.height * 4) as usize);
    let textured: Vec<u32> = (0..g.materials.len() as u32)
        .filter(|&m| g.materials[m as usize].base_color_texture == Some(0))
        .collect();
    assert_eq!(textured.len(), 1);
    let uvs: Vec<[f32; 2]> = g
        .vertices
        .iter()
        .filter(|v| v.material == textured[0])
        .map(|v| v.uv)
        .collect();
    assert!(!uvs.is_empty());
    assert!(uvs
        .iter()
        .all(|uv| uv.iter().all(|c| (-1e-4..=1.0001).contains(c))));
    assert!(uvs.iter().any(|uv| uv[0] > 0.9) && uvs.iter().any(|uv| uv[1] < 0.1));
}

#[test]
fn glass_is_transmissive_double_sided_blend() {
    let car = demo_car(DEFAULT_TRIANGLES);
    let glass: Vec<_> = car
        .geometry
        .materials
        .iter()
        .filter(|m| m.transmission > 0.0)
        .collect();
    assert_eq!(glass.len(), 1);
    let m = glass[0];
    assert_eq!(m.name, GLASS_MATERIAL);
    assert_eq!(m.transmission, 1.0);
    assert!(m.double_sided);
    assert_eq!(m.alpha_mode, trisort_format::AlphaMode::Blend);
    assert!((m.base_color[3] - 0.3).abs() < 0.05 && m.base_color[2] > m.base_color[0]);
}

#[test]
fn opaque_parts_are_closed_and_face_outwards() {
    for request in [10_000, 60_000] {
        let car = demo_car(request);
        let weld = welded(&car);
        let tris = world_triangles(&car, &[]);
        let parts = parts(&car);
        let mut closed = 0;
        for (k, part) in parts.iter().enumerate() {
            if is_glass(&car, part.material) {
                continue;
            }
            let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
            for &t in &part.triangles {
                let v = car.geometry.triangles[t as usize].map(|v| weld[v as usize]);
                for e in 0..3 {
                    *edges.entry((v[e], v[(e + 1) % 3])).or_default() += 1;
                }
            }
            for (&(a, b), &n) in &edges {
                assert_eq!(n, 1, "part {k}: edge {a}->{b} used {n} times");
                assert_eq!(
                    edges.get(&(b, a)),
                    Some(&1),
                    "part {k} ({} triangles, material {}): edge {a}->{b} is open or \
                     inconsistently wound",
                    part.triangles.len(),
                    part.material
                );
            }
            let volume: f64 = part
                .triangles
                .iter()
                .map(|&t| {
                    let [a, b, c] = tris[t as usize];
                    a.dot(b.cross(c)) / 6.0
                })
                .sum();
            assert!(volume > 0.0, "part {k} faces inwards (volume {volume})");
            closed += 1;
        }
        // Body, door, 4 tyres, 4 rims, 4 seat parts, dashboard, 3 steering parts, 2 plates.
        assert_eq!(closed, 20, "request {request}");
        assert_eq!(parts.len(), 26, "6 glass panes");
    }
}

#[test]
fn no_parts_interpenetrate() {
    for request in [10_000, 20_000, 150_000, 1_000_000] {
        let car = demo_car(request);
        let hits = intersecting_parts(&car, &[]);
        assert!(hits.is_empty(), "{request}: intersecting parts: {hits:?}");
        // The check itself finds a collision: the door swung inwards hits the body.
        let hits = intersecting_parts(&car, &[door_pose(&car, -20.0)]);
        assert!(!hits.is_empty(), "{request}: door swung inwards collides");
    }
}

#[test]
fn door_opens_about_its_hinge_without_collisions() {
    let car = demo_car(12_000);
    let g = &car.geometry;
    let door = car.node_by_name(DOOR_NODE).expect("door node");
    let window = car
        .node_by_name(DOOR_WINDOW_NODE)
        .expect("door window node");
    assert_eq!(g.nodes[window as usize].parent, Some(door));
    assert_eq!(g.nodes[door as usize].parent, Some(0));
    let door_tris: Vec<u32> = (0..g.triangles.len() as u32)
        .filter(|&t| g.triangle_node(t) == door)
        .collect();
    let window_tris: Vec<u32> = (0..g.triangles.len() as u32)
        .filter(|&t| g.triangle_node(t) == window)
        .collect();
    assert!(!door_tris.is_empty() && !window_tris.is_empty());
    assert!(window_tris
        .iter()
        .all(|&t| is_glass(&car, g.triangle_material(t))));
    assert!(door_tris
        .iter()
        .all(|&t| !is_glass(&car, g.triangle_material(t))));
    // The origin is on the hinge line: the door lies behind it (−Z) and not outside it.
    for &t in door_tris.iter().chain(&window_tris) {
        for v in g.triangles[t as usize] {
            let p = g.vertices[v as usize].position;
            assert!(p[2] <= 0.01 && p[0] >= -1e-3, "door vertex {p:?}");
        }
    }
    // A positive rotation about local +Y swings the door out (towards −X, the driver's side).
    let centroid = |poses: &[NodePose]| {
        let tris = world_triangles(&car, poses);
        door_tris
            .iter()
            .map(|&t| tris[t as usize][0])
            .sum::<DVec3>()
            / door_tris.len() as f64
    };
    let closed = centroid(&[]);
    let open = centroid(&[door_pose(&car, 45.0)]);
    assert!(closed.x < -0.5, "the driver door is on the −X side");
    assert!(open.x < closed.x - 0.2, "{closed} → {open}");
    for car in [car, demo_car(150_000)] {
        for degrees in [20.0, DOOR_MAX_OPEN_DEGREES] {
            let hits = intersecting_parts(&car, &[door_pose(&car, degrees)]);
            assert!(hits.is_empty(), "door at {degrees}°: {hits:?}");
        }
    }
}

/// Hits along a ray, nearest first: (distance, material).
fn ray_hits(car: &Scene, origin: DVec3, target: DVec3) -> Vec<(f64, u32)> {
    let tris = world_triangles(car, &[]);
    let d = (target - origin).normalize();
    let mut hits: Vec<(f64, u32)> = tris
        .iter()
        .enumerate()
        .filter_map(|(id, t)| {
            ray_hit(origin, d, t).map(|s| (s, car.geometry.triangle_material(id as u32)))
        })
        .collect();
    hits.sort_by(|a, b| a.0.total_cmp(&b.0));
    hits
}

#[test]
fn windows_are_seen_through_each_other_and_show_the_interior() {
    let car = demo_car(DEFAULT_TRIANGLES);
    let name = |m: u32| car.geometry.materials[m as usize].name.as_str();
    // Across the cabin, through the driver door window and the opposite side window.
    let hits = ray_hits(
        &car,
        DVec3::new(-5.0, 1.12, 0.15),
        DVec3::new(5.0, 1.12, 0.15),
    );
    let names: Vec<&str> = hits.iter().map(|h| name(h.1)).collect();
    assert!(names.len() >= 2, "{names:?}");
    assert_eq!(names[..2], [GLASS_MATERIAL, GLASS_MATERIAL], "{names:?}");
    // Through the windscreen, the steering wheel; then the driver seat.
    let hits = ray_hits(
        &car,
        DVec3::new(-0.40, 2.2, 3.0),
        DVec3::new(-0.40, 0.95, 0.42),
    );
    let names: Vec<&str> = hits.iter().map(|h| name(h.1)).collect();
    assert_eq!(names.first(), Some(&GLASS_MATERIAL), "{names:?}");
    assert_eq!(names.get(1), Some(&"steering"), "{names:?}");
    // Through the side window, a seat back.
    let hits = ray_hits(
        &car,
        DVec3::new(5.0, 1.05, -0.50),
        DVec3::new(0.40, 1.0, -0.50),
    );
    let names: Vec<&str> = hits.iter().map(|h| name(h.1)).collect();
    assert_eq!(names[..2], [GLASS_MATERIAL, "seat"], "{names:?}");
}

// ---------------------------------------------------------------------------------------------
// glTF export.

use trisort_scene::export::{export_glb, ExportError};

/// Triangles of the default scene, counted through node instances.
fn gltf_triangles(node: gltf::Node, buffers: &[gltf::buffer::Data]) -> usize {
    let own = node.mesh().map_or(0, |mesh| {
        mesh.primitives()
            .map(|p| {
                assert_eq!(p.mode(), gltf::mesh::Mode::Triangles);
                let reader = p.reader(|b| Some(&buffers[b.index()]));
                let n = reader.read_indices().expect("indexed").into_u32().count();
                assert_eq!(n % 3, 0);
                n / 3
            })
            .sum()
    });
    own + node
        .children()
        .map(|c| gltf_triangles(c, buffers))
        .sum::<usize>()
}

#[test]
fn exported_car_is_valid_gltf() {
    let car = demo_car(DEFAULT_TRIANGLES);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("car.glb");
    export_glb(&car, &path).unwrap();
    let bytes = std::fs::read(&path).unwrap();

    // GLB framing: header, 4-byte aligned JSON and BIN chunks.
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(word(4), 2);
    assert_eq!(word(8), bytes.len());
    let json_len = word(12);
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let bin_at = 20 + json_len;
    assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
    assert_eq!(word(bin_at) % 4, 0);
    assert_eq!(bin_at + 8 + word(bin_at), bytes.len());

    let (doc, buffers, images) = gltf::import(&path).expect("gltf crate reads the export");
    let scene = doc.default_scene().expect("a default scene");
    let triangles: usize = scene.nodes().map(|n| gltf_triangles(n, &buffers)).sum();
    assert_eq!(triangles, car.geometry.triangles.len());
    // One mesh per (node, material) group, POSITION bounds on every primitive.
    let mut groups = std::collections::BTreeSet::new();
    for v in &car.geometry.vertices {
        groups.insert((v.node, v.material));
    }
    assert_eq!(doc.meshes().count(), groups.len());
    for mesh in doc.meshes() {
        for p in mesh.primitives() {
            let pos = p.get(&gltf::Semantic::Positions).unwrap();
            assert!(pos.min().is_some() && pos.max().is_some());
            assert!(p.get(&gltf::Semantic::Normals).is_some());
        }
    }
    // Materials: glass through KHR_materials_transmission, listed as used.
    assert!(doc
        .extensions_used()
        .any(|e| e == "KHR_materials_transmission"));
    let glass: Vec<_> = doc
        .materials()
        .filter(|m| m.transmission().is_some())
        .collect();
    assert_eq!(glass.len(), 1);
    assert_eq!(glass[0].transmission().unwrap().transmission_factor(), 1.0);
    assert_eq!(glass[0].alpha_mode(), gltf::material::AlphaMode::Blend);
    assert!(glass[0].double_sided());
    // The texture round-trips texel for texel and is used with TEXCOORD_0.
    assert_eq!(images.len(), 1);
    let tex = &car.geometry.textures[0];
    assert_eq!((images[0].width, images[0].height), (tex.width, tex.height));
    assert_eq!(images[0].format, gltf::image::Format::R8G8B8A8);
    assert_eq!(images[0].pixels, tex.rgba8);
    let textured = doc
        .materials()
        .find(|m| m.pbr_metallic_roughness().base_color_texture().is_some())
        .expect("a textured material");
    assert!(doc
        .meshes()
        .flat_map(|m| m.primitives().collect::<Vec<_>>())
        .any(|p| {
            p.material().index() == textured.index()
                && p.get(&gltf::Semantic::TexCoords(0)).is_some()
        }));
    // The door hierarchy, with the hinge transform.
    let door = doc
        .nodes()
        .find(|n| n.name() == Some(DOOR_NODE))
        .expect("door node");
    assert!(door.children().any(|c| c.name() == Some(DOOR_WINDOW_NODE)));
    let rest = &car.geometry.nodes[car.node_by_name(DOOR_NODE).unwrap() as usize].rest;
    let (t, _, _) = door.transform().decomposed();
    assert!((f64::from(t[0]) - rest[12]).abs() < 1e-6);
}

#[test]
fn export_is_deterministic() {
    let car = demo_car(10_000);
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.glb"), dir.path().join("b.glb"));
    export_glb(&car, &a).unwrap();
    export_glb(&car, &b).unwrap();
    assert_eq!(std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
}

#[test]
fn exported_car_round_trips_through_the_importer() {
    let car = demo_car(DEFAULT_TRIANGLES);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("car.glb");
    export_glb(&car, &path).unwrap();
    let back = trisort_scene::load(&path).expect("the importer reads the export");
    assert_eq!(back.stats.triangles, car.stats.triangles);
    assert_eq!(back.geometry.triangles.len(), car.geometry.triangles.len());
    assert_eq!(back.stats.zero_area_triangles, 0);
    let door = back.node_by_name(DOOR_NODE).expect("door node");
    let window = back
        .node_by_name(DOOR_WINDOW_NODE)
        .expect("door window node");
    assert_eq!(back.geometry.nodes[window as usize].parent, Some(door));
    assert!(back
        .geometry
        .materials
        .iter()
        .any(|m| m.name == GLASS_MATERIAL && m.transmission > 0.0 && m.double_sided));
    assert_eq!(back.geometry.textures.len(), 1);
    assert_eq!(
        back.geometry.textures[0].rgba8,
        car.geometry.textures[0].rgba8
    );
    let ((lo_a, hi_a), (lo_b, hi_b)) = (car.bounds().unwrap(), back.bounds().unwrap());
    assert!(lo_a.distance(lo_b) < 1e-5 && hi_a.distance(hi_b) < 1e-5);
    // The door's triangles still move with the door.
    let moved = |s: &Scene| {
        (0..s.geometry.triangles.len() as u32)
            .filter(|&t| {
                let mut n = Some(s.geometry.triangle_node(t));
                while let Some(k) = n {
                    if k == s.node_by_name(DOOR_NODE).unwrap() {
                        return true;
                    }
                    n = s.geometry.nodes[k as usize].parent;
                }
                false
            })
            .count()
    };
    assert_eq!(moved(&back), moved(&car));
}

#[test]
fn export_writes_emissive_strength_and_mask_cutoff() {
    let mut car = demo_car(10_000);
    car.geometry.materials[0].emissive = [4.0, 2.0, 0.0];
    car.geometry.materials[2].alpha_mode = trisort_format::AlphaMode::Mask;
    car.geometry.materials[2].alpha_cutoff = 0.25;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("e.glb");
    export_glb(&car, &path).unwrap();
    let (doc, _, _) = gltf::import(&path).unwrap();
    let m0 = doc.materials().next().unwrap();
    assert_eq!(m0.emissive_factor(), [1.0, 0.5, 0.0]);
    assert_eq!(m0.emissive_strength(), Some(4.0));
    assert!(doc
        .extensions_used()
        .any(|e| e == "KHR_materials_emissive_strength"));
    let m2 = doc.materials().nth(2).unwrap();
    assert_eq!(m2.alpha_mode(), gltf::material::AlphaMode::Mask);
    assert_eq!(m2.alpha_cutoff(), Some(0.25));
}

#[test]
fn export_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut car = demo_car(10_000);
    let path = dir.path().join("bad.glb");
    car.geometry.triangles[7][1] = u32::MAX;
    let err = export_glb(&car, &path).unwrap_err();
    assert!(matches!(err, ExportError::InvalidScene { .. }), "{err}");
    assert!(err.to_string().contains("bad.glb") && err.to_string().contains("triangle 7"));
    assert!(!path.exists());

    let mut car = demo_car(10_000);
    car.geometry.textures[0].rgba8.pop();
    let err = export_glb(&car, &path).unwrap_err();
    assert!(matches!(err, ExportError::Png { texture: 0, .. }), "{err}");

    let car = demo_car(10_000);
    let missing = dir.path().join("no such dir").join("car.glb");
    let err = export_glb(&car, &missing).unwrap_err();
    assert!(matches!(err, ExportError::Write { .. }), "{err}");
    assert!(err.to_string().contains("car.glb"));
}

#[test]
fn materials_are_physically_plausible_and_survive_export() {
    let car = demo_car(10_000);
    let g = &car.geometry;
    g.check_structure().unwrap();
    let m = |name: &str| g.materials.iter().find(|m| m.name == name).unwrap();
    // Clear-coated metallic paint, chrome rims, rough rubber, smooth dielectric glass.
    let paint = m("paint");
    assert!(paint.metallic > 0.0 && paint.clearcoat == 1.0 && paint.clearcoat_roughness < 0.1);
    assert_eq!((m("rim").metallic, m("rim").roughness < 0.1), (1.0, true));
    assert_eq!(m("tyre").metallic, 0.0);
    assert!(m("tyre").roughness >= 0.8);
    let glass = m(GLASS_MATERIAL);
    assert_eq!((glass.metallic, glass.transmission), (0.0, 1.0));
    assert!(glass.roughness < 0.1);
    for m in &g.materials {
        assert!((0.0..=1.0).contains(&m.metallic) && (0.0..=1.0).contains(&m.roughness));
    }
    // The plate texture carries its mip chain: 64x16 down to 1x1.
    let plate = &g.textures[0];
    assert!(plate.srgb);
    assert_eq!(plate.mips.len(), 6);
    assert_eq!(plate.mips[5].len(), 4);

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("car.glb");
    trisort_scene::export::export_glb(&car, &path).unwrap();
    let back = trisort_scene::load(&path).unwrap();
    for (a, b) in g.materials.iter().zip(&back.geometry.materials) {
        assert_eq!(a.name, b.name);
        assert_eq!(
            (a.metallic, a.roughness),
            (b.metallic, b.roughness),
            "{}",
            a.name
        );
        assert_eq!(
            (a.clearcoat, a.clearcoat_roughness),
            (b.clearcoat, b.clearcoat_roughness)
        );
    }
    assert_eq!(back.geometry.textures[0].mips, plate.mips);
}
