//! How far apart two conformant GPUs may put the same projected corner (numbers for
//! BENCHMARKS.md § Raster profiles, not a test): the floating-point part of the conformant
//! raster profile's tolerance ([`trisort_format::Robust::CONFORMANT_TOLERANCE`]).
//!
//! ```sh
//! cargo run --release -p trisort-recorder --example transform_spread -- SCENE PATH WIDTHxHEIGHT
//! ```
//!
//! The player's one vertex transform is `proj * (node * vec4(position, 1))` in f32 with
//! matrices the CPU computed in f64 and rounded to f32 (identical on every device), then the
//! rasterizer divides by w. Devices differ only in how they evaluate that: the order in which
//! a matrix-vector product adds its four terms, whether it fuses multiply and add, and how
//! exactly it divides (Vulkan allows 2.5 ulp for a division). For every vertex of the scene
//! in every frame of the path whose corner lands inside the image in front of the near plane,
//! this evaluates the transform four ways (column order forward and reversed, each with and
//! without fused multiply-add), each divided correctly rounded and then moved by 2.5 ulp
//! either way, and prints the largest distance in pixels, per axis, between any of them and
//! the exact value of the same f32 inputs (computed in f64): twice that bounds how far two
//! devices of these kinds put one corner apart.

use glam::{DVec4, Mat4, Vec4};
use trisort_format::camera::node_view_matrices;

/// `m * v` in f32 with the four column terms added in `order`, fused or not.
fn product(m: &Mat4, v: Vec4, reversed: bool, fused: bool) -> Vec4 {
    let cols = [m.x_axis, m.y_axis, m.z_axis, m.w_axis];
    let w = [v.x, v.y, v.z, v.w];
    let idx: [usize; 4] = if reversed { [3, 2, 1, 0] } else { [0, 1, 2, 3] };
    let mut out = [0f32; 4];
    for (r, o) in out.iter_mut().enumerate() {
        let mut acc = cols[idx[0]][r] * w[idx[0]];
        for &k in &idx[1..] {
            acc = if fused {
                cols[k][r].mul_add(w[k], acc)
            } else {
                acc + cols[k][r] * w[k]
            };
        }
        *o = acc;
    }
    Vec4::from_array(out)
}

/// `x` moved by `ulps` units in the last place of f32 (either sign).
fn nudge(x: f32, ulps: f32) -> f32 {
    let ulp = f32::from_bits(x.abs().to_bits() + 1) - x.abs();
    x + ulps * ulp
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: transform_spread SCENE PATH WIDTHxHEIGHT");
        std::process::exit(2);
    }
    let scene = trisort_scene::load(std::path::Path::new(&args[1])).expect("scene");
    let timeline = trisort_paths::load(&args[2], &scene, &Default::default()).expect("path");
    let (w, h) = args[3]
        .split_once('x')
        .map(|(a, b)| {
            (
                a.parse::<u32>().expect("width"),
                b.parse::<u32>().expect("height"),
            )
        })
        .expect("size WIDTHxHEIGHT");
    let half = [w as f64 / 2.0, h as f64 / 2.0];
    let g = &scene.geometry;
    let mut worst = [0f64; 2];
    let mut corners = 0u64;
    let mut spreads: Vec<f64> = Vec::new();
    for frame in &timeline.frames {
        let proj = frame.camera.projection(w as f64 / h as f64).as_mat4();
        let nodes = node_view_matrices(&g.nodes, frame);
        for v in &g.vertices {
            let n = &nodes[v.node as usize];
            let p = Vec4::new(v.position[0], v.position[1], v.position[2], 1.0);
            // The exact result of the same f32 inputs.
            let exact: DVec4 = proj.as_dmat4() * (n.as_dmat4() * p.as_dvec4());
            if exact.w <= 1e-6 {
                continue;
            }
            let ndc = [exact.x / exact.w, exact.y / exact.w];
            if ndc[0].abs() > 1.0
                || ndc[1].abs() > 1.0
                || !(0.0..=1.0).contains(&(exact.z / exact.w))
            {
                continue;
            }
            corners += 1;
            let mut spread = 0f64;
            for reversed in [false, true] {
                for fused in [false, true] {
                    let eye = product(n, p, reversed, fused);
                    let clip = product(&proj, eye, reversed, fused);
                    for ulps in [-2.5f32, 0.0, 2.5] {
                        for axis in 0..2 {
                            let q = nudge(clip[axis] / clip.w, ulps) as f64;
                            let d = (q - ndc[axis]).abs() * half[axis];
                            worst[axis] = worst[axis].max(d);
                            spread = spread.max(d);
                        }
                    }
                }
            }
            spreads.push(spread);
        }
    }
    spreads.sort_by(f64::total_cmp);
    let at = |q: f64| {
        spreads
            .get(((spreads.len() as f64 - 1.0) * q) as usize)
            .copied()
            .unwrap_or(0.0)
    };
    println!(
        "scene {} ({} vertices), path {} ({} frames), {w}x{h}: {corners} corners in view",
        scene.name,
        g.vertices.len(),
        args[2],
        timeline.frames.len()
    );
    println!(
        "largest distance from the exact corner, px: x {:.3e}, y {:.3e} (median {:.3e}, 99.99th percentile {:.3e}); two devices: at most twice that, {:.3e}",
        worst[0],
        worst[1],
        at(0.5),
        at(0.9999),
        2.0 * worst[0].max(worst[1])
    );
}
