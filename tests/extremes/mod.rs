//! Numerical extremes through the real pipeline: scenes written here as glTF binaries and
//! TOML paths, baked by the `trisort` binary at 32²–64², then checked against the graph rules
//! (`verify --recording`) and against facts computed independently from the geometry. Each
//! test states what must hold and, where there is one, the limit found (measured on lavapipe).

mod limits;
mod precision;

use std::collections::BTreeSet;
use std::path::Path;

use serde_json::json;
use trisort_format::{Baked, FileKind, Recording};
use trisort_testkit::fixtures::quad_triangles;

use crate::support::*;

// ---------------------------------------------------------------------------------------------
// Scene and path writers.

/// A material: linear RGBA base colour; alpha < 1 makes it BLEND. Always double-sided.
#[derive(Clone, Copy)]
struct Mat([f32; 4]);

/// One node with one single-primitive mesh of unindexed triangles (local positions).
struct Part {
    translation: [f64; 3],
    material: usize,
    triangles: Vec<[[f32; 3]; 3]>,
}

fn part(material: usize, triangles: Vec<[[f32; 3]; 3]>) -> Part {
    Part {
        translation: [0.0; 3],
        material,
        triangles,
    }
}

/// Two triangles spanning [x0,x1]×[y0,y1] at depth z, ids in this order (the corners of
/// [`trisort_testkit::fixtures::quad`]).
fn quad(x0: f32, x1: f32, y0: f32, y1: f32, z: f32) -> Vec<[[f32; 3]; 3]> {
    quad_triangles(x0, x1, y0, y1, z, z).to_vec()
}

/// A glTF 2.0 binary of `parts` (one root node each, in order: triangle ids follow it).
fn glb(parts: &[Part], mats: &[Mat]) -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    let mut nodes = vec![];
    let mut meshes = vec![];
    let mut accessors = vec![];
    let mut views = vec![];
    for (k, p) in parts.iter().enumerate() {
        let offset = bin.len();
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for v in p.triangles.iter().flatten() {
            for c in 0..3 {
                lo[c] = lo[c].min(v[c]);
                hi[c] = hi[c].max(v[c]);
                bin.extend_from_slice(&v[c].to_le_bytes());
            }
        }
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bin.len() - offset}));
        accessors.push(
            json!({"bufferView": k, "componentType": 5126, "count": p.triangles.len() * 3,
            "type": "VEC3", "min": lo, "max": hi}),
        );
        meshes
            .push(json!({"primitives": [{"attributes": {"POSITION": k}, "material": p.material}]}));
        nodes.push(json!({"name": format!("part{k}"), "mesh": k, "translation": p.translation}));
    }
    let materials: Vec<_> = mats
        .iter()
        .map(|m| {
            json!({"pbrMetallicRoughness": {"baseColorFactor": m.0, "metallicFactor": 0.0},
                "alphaMode": if m.0[3] < 1.0 { "BLEND" } else { "OPAQUE" }, "doubleSided": true})
        })
        .collect();
    let doc = json!({
        "asset": {"version": "2.0"}, "scene": 0,
        "scenes": [{"nodes": (0..parts.len()).collect::<Vec<_>>()}],
        "nodes": nodes, "meshes": meshes, "materials": materials,
        "accessors": accessors, "bufferViews": views, "buffers": [{"byteLength": bin.len()}],
    });
    let mut json_bytes = serde_json::to_vec(&doc).unwrap();
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// A TOML path: one camera key per frame (`(eye, target)`), so no frame is interpolated.
fn path_toml(yfov: f64, clip: Option<(f64, f64)>, keys: &[([f64; 3], [f64; 3])]) -> String {
    let mut s = String::from("[camera]\n");
    s += &format!("yfov = {yfov:?}\n");
    if let Some((near, far)) = clip {
        s += &format!("znear = {near:?}\nzfar = {far:?}\n");
    }
    for (f, (eye, target)) in keys.iter().enumerate() {
        s += &format!("[[camera.key]]\nframe = {f}\neye = {eye:?}\ntarget = {target:?}\n");
    }
    s
}

/// The result of a bake: the recording and the baked file.
struct Baking {
    rec: Recording,
    baked: Baked,
}

/// Writes the scene and path, bakes at `size`² with `samples` at the recorded pattern only
/// (`--conservative=false`), checks the graph rules with `verify --recording` and returns both
/// files. `None` when no GPU (the test skips).
fn bake(
    dir: &Path,
    name: &str,
    scene: &[u8],
    path: &str,
    size: u32,
    samples: u32,
) -> Option<Baking> {
    bake_with(dir, name, scene, path, size, samples, &[])
}

fn bake_with(
    dir: &Path,
    name: &str,
    scene: &[u8],
    path: &str,
    size: u32,
    samples: u32,
    extra: &[&str],
) -> Option<Baking> {
    if !gpu_available() {
        return None;
    }
    std::fs::write(dir.join(format!("{name}.glb")), scene).unwrap();
    std::fs::write(dir.join(format!("{name}.toml")), path).unwrap();
    let (glb, toml, out) = (
        format!("{name}.glb"),
        format!("{name}.toml"),
        format!("{name}.baked"),
    );
    let size = format!("{size}x{size}");
    let samples = samples.to_string();
    let mut args = bake_args(&glb, &toml, &size, &samples, &out);
    // The known answers below are the recorded pattern's (which triangle wins which sample,
    // ties, depth precision): recorded at that pattern only, not conservatively (the
    // default), unless a test asks otherwise.
    if !extra
        .iter()
        .any(|a| a.starts_with("--conservative") || a.starts_with("--raster-profile"))
    {
        args.push("--conservative=false");
    }
    args.extend_from_slice(extra);
    run(dir, &args, true);
    let rec: Recording =
        trisort_format::read_file(FileKind::Recording, &dir.join(format!("{out}.rec"))).unwrap();
    let baked: Baked = trisort_format::read_file(FileKind::Baked, &dir.join(&out)).unwrap();
    rec.check_structure().unwrap();
    baked.check_structure().unwrap();
    Some(Baking { rec, baked })
}

/// The bake must pass `verify --recording` (the graph rules) and `verify --scene` (its frames
/// against the exact reference of the full scene, at the recorded pattern) in every mode:
/// depth bit-exact, blend and saturate within 1/255 except at pixels with a sample on a cycle
/// of the recording's graphs (given, so that the recording decides what may be unordered).
/// Returns the blend-mode report.
fn assert_verifies(dir: &Path, name: &str) -> serde_json::Value {
    let baked = format!("{name}.baked");
    let v = run_json(
        dir,
        &[
            "verify",
            &baked,
            "--recording",
            &format!("{name}.baked.rec"),
        ],
    );
    assert_eq!(v["ok"], true, "{name}: {v}");
    let glb = format!("{name}.glb");
    let mut blend = serde_json::Value::Null;
    for mode in ["blend", "depth", "saturate"] {
        let rec = format!("{name}.baked.rec");
        let image = [
            "verify",
            &baked,
            "--recording",
            &rec,
            "--scene",
            &glb,
            "--mode",
            mode,
        ];
        let v = run_json(dir, &image);
        assert_eq!(v["ok"], true, "{name}, {mode} mode: {v}");
        if mode == "blend" {
            blend = v;
        }
    }
    blend
}

fn edge_weight(r: &Recording, f: usize, from: &[u32], to: &[u32]) -> u32 {
    r.frames[f]
        .edges
        .iter()
        .filter(|e| from.contains(&e.from) && to.contains(&e.to))
        .map(|e| e.weight)
        .sum()
}

fn set(v: &[u32]) -> BTreeSet<u32> {
    v.iter().copied().collect()
}

/// Looks from the origin down −Z (view = identity).
const EYE0: [f64; 3] = [0.0, 0.0, 0.0];
const AHEAD: [f64; 3] = [0.0, 0.0, -1.0];

/// Overlapping quads, some transparent: a scene whose graphs have edges and ties.
fn layered_parts(offset: [f64; 3]) -> Vec<Part> {
    let mut a = part(0, quad(-1.0, 0.6, -0.8, 0.8, 0.0));
    let mut b = part(1, quad(-0.4, 1.2, -1.0, 0.5, -0.7));
    let mut c = part(0, quad(-1.5, 1.5, -1.5, 1.5, -1.6));
    let mut d = part(
        1,
        [
            quad(-0.2, 0.9, -0.3, 0.9, 0.4),
            quad(-0.9, 0.3, -0.9, 0.2, -1.1),
        ]
        .concat(),
    );
    for p in [&mut a, &mut b, &mut c, &mut d] {
        p.translation = offset;
    }
    vec![a, b, c, d]
}
