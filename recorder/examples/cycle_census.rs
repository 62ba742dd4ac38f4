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
//! - `intersecting`: an edge of one passes through the other;
//! - `skew`: each crosses the other's plane, yet neither passes through the other.
//!
//! It prints per class the edges, their weight (unordered samples), and how many are one side
//! of a two-cycle (the recording also holds the reverse edge at that frame); for intersecting
//! and skew pairs also the samples per frame and the node pairs with the most samples.

use std::collections::{BTreeMap, HashSet};

use glam::DVec3;
use trisort_format::{world_transforms, Baked, FileKind, Recording};

/// Whether an edge of triangle `t` passes through triangle `o` (f64, exact enough here).
fn crosses(t: &[DVec3; 3], o: &[DVec3; 3]) -> bool {
    let n = (o[1] - o[0]).cross(o[2] - o[0]);
    (0..3).any(|k| {
        let (p, q) = (t[k], t[(k + 1) % 3]);
        let (dp, dq) = (n.dot(p - o[0]), n.dot(q - o[0]));
        if dp * dq > 0.0 || dp == dq {
            return false;
        }
        let x = p + (q - p) * (dp / (dp - dq));
        (0..3).all(|j| {
            let (a, b) = (o[j], o[(j + 1) % 3]);
            n.dot((b - a).cross(x - a)) >= 0.0
        })
    })
}

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
    let mut frames_of: BTreeMap<usize, u32> = BTreeMap::new();
    let mut node_pairs: BTreeMap<(u32, u32), u32> = BTreeMap::new();
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
            } else if crosses(&a, &b) || crosses(&b, &a) {
                "intersecting"
            } else {
                "skew"
            };
            if class == "intersecting" || class == "skew" {
                *frames_of.entry(f).or_default() += e.weight;
                let na = g.vertices[g.triangles[e.from as usize][0] as usize].node;
                let nb = g.vertices[g.triangles[e.to as usize][0] as usize].node;
                *node_pairs.entry((na.min(nb), na.max(nb))).or_default() += e.weight;
            }
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
    println!("intersecting or skew, samples per frame: {frames_of:?}");
    let mut pairs: Vec<_> = node_pairs.into_iter().collect();
    pairs.sort_by_key(|p| std::cmp::Reverse(p.1));
    let names = |n: u32| {
        g.nodes
            .get(n as usize)
            .map(|x| x.name.as_str())
            .unwrap_or("?")
    };
    for ((a, b), w) in pairs.iter().take(8) {
        println!(
            "  nodes {a} {:?} / {b} {:?}: {w} samples",
            names(*a),
            names(*b)
        );
    }
    println!("class: edges, unordered samples, of which two-cycles");
    for (k, (n, w, two)) in classes {
        println!("{k}: {n}, {w}, {two}");
    }
}
