//! Which triangles a SwiftShader-like rasterizer puts at one pixel of a baked frame: a CPU
//! emulation of the rules the envelope bound allows for (BENCHMARKS.md § Exactness across
//! rasterizers), for finding what makes a hole in the browser's self-check.
//!
//! ```sh
//! cargo run -p trisort-format --example swiftshader_pixel -- BAKED FRAME X Y
//! ```
//!
//! Rules emulated (SwiftShader's `SetupRoutine`, `QuadRasterizer`, `PixelRoutine`, as read
//! from its source): corners snapped to 1/16 px (rounded, pixel centres on whole numbers);
//! coverage per sample at the Vulkan 4× positions on the snapped corners (ties counted as
//! covered); facing from the snapped area; depth from the plane through the snapped corners
//! and the corners' own depths, taken at the sample mirrored about the pixel centre in x
//! (`z_mirror_x`; older versions mirror in x and y: `z_mirror_xy`) and, for comparison, at
//! the sample itself. Back faces of single-sided materials are culled; triangles reaching
//! behind the camera are skipped (SwiftShader clips them). For each of the pixel's four
//! samples it lists the nearest triangles by `z_mirror_x` and whether the frame draws them
//! (`drawn`): a triangle not drawn in front of every drawn one is a hole there.

use glam::{Mat4, Vec4};
use std::collections::HashSet;
use std::path::Path;
use trisort_format::camera::node_view_matrices;
use trisort_format::{read_file, Baked, FileKind};

/// Sample offsets from the pixel centre in 1/16 px (Vulkan's standard 4× pattern).
const SAMPLES: [(i64, i64); 4] = [(-2, -6), (6, -2), (-6, 2), (2, 6)];

/// One triangle covering one sample.
struct Hit {
    z_mirror_x: f64,
    z_mirror_xy: f64,
    z_sample: f64,
    tri: usize,
    drawn: bool,
    front: bool,
    snapped_area: f64,
    area: f64,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, frame, x, y] = args.as_slice() else {
        return Err("usage: swiftshader_pixel BAKED FRAME X Y".into());
    };
    let baked: Baked = read_file(FileKind::Baked, Path::new(path))?;
    let f: usize = frame.parse()?;
    let (px, py): (i64, i64) = (x.parse()?, y.parse()?);
    if f >= baked.frames.len() {
        return Err(format!("{path}: frame {f} of {}", baked.frames.len()).into());
    }
    let (w, h) = (baked.settings.width as f64, baked.settings.height as f64);
    let state = &baked.frame_states[f];
    let proj: Mat4 = state.camera.projection(w / h).as_mat4();
    let nodes = node_view_matrices(&baked.geometry.nodes, state);
    let mut drawn = HashSet::new();
    for d in baked.frame_draws(f) {
        for k in 0..d.index_count / 3 {
            drawn.insert(baked.copies[(d.first_index / 3 + k) as usize]);
        }
    }
    let g = &baked.geometry;
    let (cx, cy) = (px * 16, py * 16);
    let mut hits: Vec<Vec<Hit>> = (0..4).map(|_| Vec::new()).collect();
    'triangles: for (t, tri) in g.triangles.iter().enumerate() {
        let mut snapped = [[0i64; 2]; 3];
        let mut window = [[0f64; 2]; 3];
        let mut z = [0f64; 3];
        for k in 0..3 {
            let v = &g.vertices[tri[k] as usize];
            let [a, b, c] = v.position;
            let clip = proj * (nodes[v.node as usize] * Vec4::new(a, b, c, 1.0));
            if clip.w <= 1e-6 {
                continue 'triangles;
            }
            let (nx, ny) = ((clip.x / clip.w) as f64, (clip.y / clip.w) as f64);
            z[k] = (clip.z / clip.w) as f64;
            window[k] = [(nx + 1.0) * 0.5 * w, (1.0 - ny) * 0.5 * h];
            snapped[k] = [
                ((window[k][0] - 0.5) * 16.0).round() as i64,
                ((window[k][1] - 0.5) * 16.0).round() as i64,
            ];
        }
        let (lo_x, hi_x) = (
            snapped.iter().map(|p| p[0]).min().unwrap_or(0),
            snapped.iter().map(|p| p[0]).max().unwrap_or(0),
        );
        let (lo_y, hi_y) = (
            snapped.iter().map(|p| p[1]).min().unwrap_or(0),
            snapped.iter().map(|p| p[1]).max().unwrap_or(0),
        );
        if hi_x < cx - 16 || lo_x > cx + 16 || hi_y < cy - 16 || lo_y > cy + 16 {
            continue;
        }
        let [s0, s1, s2] = snapped;
        // Twice the area in window coordinates (y down): negative is counter-clockwise in NDC,
        // the front face.
        let area2 = (s1[0] - s0[0]) * (s2[1] - s0[1]) - (s2[0] - s0[0]) * (s1[1] - s0[1]);
        if area2 == 0 {
            continue;
        }
        let [w0, w1, w2] = window;
        let area = ((w1[0] - w0[0]) * (w2[1] - w0[1]) - (w2[0] - w0[0]) * (w1[1] - w0[1])) / 2.0;
        let front = area2 < 0;
        let material = &g.materials[g.vertices[tri[0] as usize].material as usize];
        if !front && !material.double_sided {
            continue;
        }
        let at = |p: [i64; 2]| (p[0] as f64 / 16.0, p[1] as f64 / 16.0);
        let (x0, y0) = at(s0);
        let ((x1, y1), (x2, y2)) = (at(s1), at(s2));
        let (x1, y1, x2, y2) = (x1 - x0, y1 - y0, x2 - x0, y2 - y0);
        let (z1, z2) = (z[1] - z[0], z[2] - z[0]);
        let det = x1 * y2 - x2 * y1;
        let (a, b) = ((z1 * y2 - z2 * y1) / det, (x1 * z2 - x2 * z1) / det);
        let depth =
            |qx: i64, qy: i64| z[0] + a * (qx as f64 / 16.0 - x0) + b * (qy as f64 / 16.0 - y0);
        for (q, &(ox, oy)) in SAMPLES.iter().enumerate() {
            let (sx, sy) = (cx + ox, cy + oy);
            let inside = (0..3).all(|k| {
                let (p, r) = (snapped[k], snapped[(k + 1) % 3]);
                let e = (r[0] - p[0]) * (sy - p[1]) - (r[1] - p[1]) * (sx - p[0]);
                if area2 > 0 {
                    e >= 0
                } else {
                    e <= 0
                }
            });
            if inside {
                hits[q].push(Hit {
                    z_mirror_x: depth(cx - ox, cy + oy),
                    z_mirror_xy: depth(cx - ox, cy - oy),
                    z_sample: depth(sx, sy),
                    tri: t,
                    drawn: drawn.contains(&(t as u32)),
                    front,
                    snapped_area: area2.abs() as f64 / 512.0,
                    area: area.abs(),
                });
            }
        }
    }
    println!("{path}: frame {f}, pixel ({px}, {py})");
    for (q, list) in hits.iter_mut().enumerate() {
        list.sort_by(|a, b| a.z_mirror_x.total_cmp(&b.z_mirror_x));
        println!(
            "sample {q} at (+{}, +{}) px:",
            (8 + SAMPLES[q].0) as f64 / 16.0,
            (8 + SAMPLES[q].1) as f64 / 16.0
        );
        for hit in list.iter().take(8) {
            println!(
                "  triangle {:>7}  drawn {:<5}  front {:<5}  area {:.5} px² (snapped {:.5})  z_mirror_x {:.6}  z_mirror_xy {:.6}  z_sample {:.6}",
                hit.tri, hit.drawn, hit.front, hit.area, hit.snapped_area, hit.z_mirror_x, hit.z_mirror_xy, hit.z_sample
            );
        }
    }
    Ok(())
}
