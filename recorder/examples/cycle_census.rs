//! Diagnostic (not a test): what the edges a merge had to leave unordered are, geometrically.
//!
//! `cargo run --release -p trisort-recorder --example cycle_census -- BAKED REC`
//!
//! For every frame's removed edges (`Baked::removed_edges`, the recording's cycles cut by the
//! merger) it looks at the two triangles in camera space and sorts the pair into one class:
//! - `coplanar`: each lies in the other's plane (within 1e-6 of its size);
//! - `separable`: one lies wholly on one side of the other's plane, so with exact depth one is
//!   in front wherever both cover a point: the cycle is numerical (or the conservative
//!   recording's), not geometric;
//! - `touching`: they share a corner or an edge and are not separable;
//! - `straddling`: each crosses the other's plane (they pass through each other, or are skew).
//!
//! It prints per class the edges, their weight (unordered samples), and how many are one side
//! of a two-cycle (the recording also holds the reverse edge at that frame).

use std::collections::{BTreeMap, HashSet};

use glam::DVec3;
use trisort_format::{world_transforms, Baked, FileKind, Recording};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [baked, rec] = &args[..] else {
        eprintln!("usage: cycle_census BAKED REC");
        std::process::exit(2);
    };
    let baked: Baked = trisort_format::read_file(FileKind::Baked, baked.as_ref()).unwrap();
    let rec: Recording = trisort_format::read_file(FileKind::Recording, rec.as_ref()).unwrap();
    let g = &baked.geometry;
    let mut classes: BTreeMap<&str, (u32, u64, u32)> = BTreeMap::new();
    for (f, removed) in baked.removed_edges.iter().enumerate() {
        if removed.is_empty() {
            continue;
        }
        let state = &baked.frame_states[f];
        let world = world_transforms(&g.nodes, &state.poses);
        let eye = state.camera.eye();
        let corners = |t: u32| -> [DVec3; 3] {
            g.triangles[t as usize].map(|v| {
                let v = &g.vertices[v as usize];
                let p = DVec3::new(
                    v.position[0] as f64,
                    v.position[1] as f64,
                    v.position[2] as f64,
                );
                world[v.node as usize].transform_point3(p) - eye
            })
        };
        let edges: HashSet<(u32, u32)> =
            rec.frames[f].edges.iter().map(|e| (e.from, e.to)).collect();
        for e in removed {
            let (a, b) = (corners(e.from), corners(e.to));
            let size = |t: &[DVec3; 3]| {
                (t[1] - t[0])
                    .length()
                    .max((t[2] - t[1]).length())
                    .max((t[0] - t[2]).length())
            };
            let scale = size(&a).max(size(&b));
            let side = |t: &[DVec3; 3], q: &[DVec3; 3]| -> [f64; 3] {
                let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
                q.map(|p| n.dot(p - t[0]))
            };
            let eps = 1e-6 * scale;
            let (ab, ba) = (side(&a, &b), side(&b, &a));
            let flat = |d: &[f64; 3]| d.iter().all(|x| x.abs() <= eps);
            let one_side =
                |d: &[f64; 3]| d.iter().all(|&x| x >= -eps) || d.iter().all(|&x| x <= eps);
            let shared = a
                .iter()
                .filter(|p| b.iter().any(|q| (**p - *q).length() <= eps))
                .count();
            let class = if flat(&ab) && flat(&ba) {
                "coplanar"
            } else if one_side(&ab) || one_side(&ba) {
                if shared > 0 {
                    "separable, sharing corners"
                } else {
                    "separable"
                }
            } else if shared > 0 {
                "touching"
            } else {
                "straddling"
            };
            let two = edges.contains(&(
                baked.scene_ids[e.to as usize],
                baked.scene_ids[e.from as usize],
            ));
            let c = classes.entry(class).or_default();
            c.0 += 1;
            c.1 += e.weight as u64;
            c.2 += two as u32;
        }
    }
    println!("class: edges, unordered samples, of which two-cycles");
    for (k, (n, w, two)) in classes {
        println!("{k}: {n}, {w}, {two}");
    }
}
