//! `trisort inspect FILE`: a scene, a recording or a baked file.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;
use serde_json::json;
use trisort_format::{FileKind, Recording};

use crate::common::{load_scene, print_json};

/// Arguments of `inspect`.
#[derive(Args, Debug)]
pub struct InspectArgs {
    /// A .glb/.gltf scene (or `demo[:TRIANGLES]`), a recording or a baked file.
    file: String,
    /// Print as JSON.
    #[arg(long)]
    json: bool,
    /// For a baked file: draw the matrix of cells to this PNG.
    #[arg(long)]
    matrix: Option<PathBuf>,
}

pub fn run(a: InspectArgs) -> Result<ExitCode> {
    let path = PathBuf::from(&a.file);
    let kind = if path.is_file() {
        let mut head = [0u8; 8];
        let n = std::io::Read::read(
            &mut std::fs::File::open(&path).with_context(|| a.file.clone())?,
            &mut head,
        )?;
        FileKind::sniff(&head[..n])
    } else {
        None
    };
    match kind {
        Some(FileKind::Recording) => inspect_recording(&a, &path),
        Some(FileKind::Baked) => inspect_baked(&a, &path),
        None => inspect_scene(&a),
    }
}

/// `inspect` of a recording: its `record --json` keys, or a summary line per frame.
fn inspect_recording(a: &InspectArgs, path: &Path) -> Result<ExitCode> {
    if a.matrix.is_some() {
        anyhow::bail!("{}: --matrix needs a baked file, not a recording", a.file);
    }
    let rec: Recording = crate::cmd::merge::read_recording(path)?;
    let v = trisort_bake::figures::recording_json(&rec, None);
    if a.json {
        print_json(&v);
    } else {
        println!(
            "{}: recording ({:?}) of frames {:?} of {}",
            a.file,
            rec.phase,
            rec.frame_range(),
            rec.frame_states.len()
        );
        println!(
            "  scene triangles {}, |G| {}, size {}x{} at {}x",
            rec.scene_triangles,
            rec.unique_visible.len(),
            rec.settings.width,
            rec.settings.height,
            rec.settings.samples
        );
        println!(
            "  device {} ({}, {})",
            rec.device.adapter, rec.device.backend, rec.device.driver
        );
        println!(
            "  raster profile {}",
            trisort_bake::figures::profile_summary(&rec.settings)
        );
        for f in &rec.frames {
            println!(
                "  frame {:>5}: visible {:>7} covered {:>7} edges {:>8} layers {:?}{}",
                f.frame,
                f.visible.len(),
                f.covered.len(),
                f.edges.len(),
                f.layers,
                if f.truncated { " TRUNCATED" } else { "" }
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// `inspect` of a baked file: its merge figures, and with `--matrix` the picture of its cells.
fn inspect_baked(a: &InspectArgs, path: &Path) -> Result<ExitCode> {
    let baked: trisort_format::Baked = trisort_format::read_file(FileKind::Baked, path)?;
    baked
        .check_structure()
        .map_err(|e| anyhow::anyhow!("{}: malformed baked file: {e}", a.file))?;
    let s = &baked.stats;
    let mut v = json!({
        "strategy": baked.merge.strategy, "layout": baked.merge.layout,
        "index_triangles": s.index_triangles, "source_triangles": s.source_triangles,
        "unique_visible": s.unique_visible, "draws_per_frame_mean": s.draws_per_frame_mean,
        "draws_per_frame_max": s.draws_per_frame_max, "drawn_not_visible_mean": s.drawn_not_visible_mean,
        "unordered_samples": s.unordered_samples, "seconds": s.seconds,
        "exact_components": s.exact_components, "heuristic_components": s.heuristic_components,
        "heuristic_unordered_samples": s.heuristic_unordered_samples,
        "frames": baked.frames.len(),
        // The path's frame rate (null where the recordings did not store one); the material
        // variants' names (as for a scene), and why `play --variant` refuses any of them.
        "fps": baked.fps,
        "variants": baked.geometry.variants.iter().map(|v| &v.name).collect::<Vec<_>>(),
        "variants_refused": baked.geometry.variants.iter().filter_map(|v| {
            let e = baked.geometry.variant_materials(Some(&v.name)).err()?;
            Some((v.name.clone(), serde_json::Value::from(e.to_string())))
        }).collect::<serde_json::Map<_, _>>(),
        "split_intersections": baked.settings.split_intersections,
        // What the bake assumes about the rasterizer that plays it (record --raster-profile).
        "raster_profile": trisort_bake::figures::raster_profile_json(&baked.settings),
        // The light stored in the file (`bake --environment`).
        "environment": trisort_bake::figures::environment_json(&baked.environment),
        // The recording device; `mixed: …` (each device with its frames) when the recordings
        // were merged with `merge --allow-mixed-devices`.
        "device": baked.device.adapter, "driver": baked.device.driver,
        // The edges the merger removed to break depth-order cycles, front → back, as scene
        // ids of the recorded scene (the file stores G-local ids): the samples they weigh are
        // the unordered ones.
        "removed_edges": baked.removed_edges.iter().enumerate().flat_map(|(f, edges)| {
            let id = |t: u32| baked.scene_ids.get(t as usize).copied().unwrap_or(t);
            edges.iter().map(move |e| json!({"frame": f, "from": id(e.from), "to": id(e.to), "weight": e.weight}))
        }).collect::<Vec<_>>(),
    });
    if let Some(png) = &a.matrix {
        let m = draw_matrix(&baked, png)?;
        v["matrix"] = json!({
            "file": png.display().to_string(), "width": m.width, "height": m.height,
            "origin": [MARGIN, MARGIN], "cell_pixels": m.cell_pixels,
            "frames_per_pixel": m.frames_per_pixel, "cells": m.cells,
            "min_triangles": m.min, "max_triangles": m.max,
        });
    }
    if a.json {
        print_json(&v);
    } else {
        println!("{}: baked file, {} frames", a.file, baked.frames.len());
        println!("{}", serde_json::to_string_pretty(&v)?);
    }
    Ok(ExitCode::SUCCESS)
}

/// `inspect` of a scene: counts, materials by alpha mode, animated nodes, bounds, material
/// variants, notes.
fn inspect_scene(a: &InspectArgs) -> Result<ExitCode> {
    if a.matrix.is_some() {
        anyhow::bail!("{}: --matrix needs a baked file", a.file);
    }
    let scene = load_scene(&a.file)?;
    let st = &scene.stats;
    let g = &scene.geometry;
    let count_mode =
        |m: trisort_format::AlphaMode| g.materials.iter().filter(|x| x.alpha_mode == m).count();
    let transmissive = g.materials.iter().filter(|m| m.transmission > 0.0).count();
    let animated: std::collections::BTreeSet<&str> = scene
        .animations
        .iter()
        .flat_map(|an| {
            an.channels
                .iter()
                .map(|c| g.nodes[c.node as usize].name.as_str())
        })
        .collect();
    let bounds = scene
        .bounds()
        .map(|(lo, hi)| json!({"min": lo.to_array(), "max": hi.to_array()}));
    // What `record` would split with every node at rest (a path that moves nodes apart
    // splits only within the groups that stay rigid on it).
    let rest = trisort_format::FrameState {
        camera: trisort_format::Camera {
            view: glam::DMat4::IDENTITY.to_cols_array(),
            yfov: 1.0,
            znear: 0.1,
            zfar: None,
        },
        poses: Vec::new(),
    };
    let split = trisort_intersect::split_intersections(
        g,
        std::slice::from_ref(&rest),
        &trisort_intersect::SplitOptions::default(),
    )
    .report;
    let v = json!({
        "scene": scene.name,
        "triangles": st.triangles, "zero_area_triangles": st.zero_area_triangles,
        "meshes": st.meshes, "primitives": st.primitives, "nodes": st.nodes,
        "materials": st.materials, "textures": st.textures,
        "animations": st.animations, "cameras": st.cameras,
        "materials_by_alpha_mode": {"opaque": count_mode(trisort_format::AlphaMode::Opaque), "mask": count_mode(trisort_format::AlphaMode::Mask), "blend": count_mode(trisort_format::AlphaMode::Blend)},
        "transmissive_materials": transmissive,
        "animated_nodes": animated,
        "bounds": bounds,
        "notes": scene.notes,
        "variants": scene.variants,
        "intersections_split": split.pairs_split + split.pairs_split_across_groups,
        "intersections_split_across_groups": split.pairs_split_across_groups,
        "triangles_added": split.triangles_added,
        "intersections_left": split.pairs_skipped_sliver,
    });
    if a.json {
        print_json(&v);
    } else {
        println!("{}: scene {:?}", a.file, scene.name);
        println!(
            "  triangles {} (zero-area {}), meshes {}, primitives {}, nodes {}",
            st.triangles, st.zero_area_triangles, st.meshes, st.primitives, st.nodes
        );
        println!(
            "  materials {} (opaque {}, mask {}, blend {}, transmissive {}), textures {}",
            st.materials,
            count_mode(trisort_format::AlphaMode::Opaque),
            count_mode(trisort_format::AlphaMode::Mask),
            count_mode(trisort_format::AlphaMode::Blend),
            transmissive,
            st.textures
        );
        println!(
            "  triangles passing through each other at rest: {} pairs (record splits them: +{} \
             triangles; {} pairs would leave slivers)",
            split.pairs_split, split.triangles_added, split.pairs_skipped_sliver
        );
        println!(
            "  animations {} (moving {} nodes: {}), cameras {}",
            st.animations,
            animated.len(),
            animated.iter().cloned().collect::<Vec<_>>().join(", "),
            st.cameras
        );
        if let Some((lo, hi)) = scene.bounds() {
            println!("  bounds {:.3?} .. {:.3?}", lo.to_array(), hi.to_array());
        }
        if !scene.variants.is_empty() {
            println!("  material variants: {}", scene.variants.join(", "));
        }
        for n in &scene.notes {
            println!("  note: {n}");
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Margin around the matrix and the legend, in pixels.
const MARGIN: u32 = 8;
/// Largest side of the matrix area before frames are binned into pixels.
const MATRIX_PIXELS: u32 = 512;
/// Empty cells of the upper triangle.
const EMPTY: [u8; 3] = [228, 228, 228];
/// The lower triangle and the background.
const BACKGROUND: [u8; 3] = [255, 255, 255];
/// Legend text and ticks.
const INK: [u8; 3] = [0, 0, 0];

/// What `draw_matrix` drew.
struct MatrixImage {
    width: u32,
    height: u32,
    /// Side of one cell in pixels (1 when frames are binned).
    cell_pixels: u32,
    /// Frames per pixel row/column (1 unless the path has more than `MATRIX_PIXELS` frames).
    frames_per_pixel: u32,
    cells: usize,
    min: u64,
    max: u64,
}

/// Draws the baked file's matrix like paper 003's Figure 14: an F×F grid whose cell (i, j),
/// row i (first frame) from the top and column j (last frame) from the left, is coloured by
/// its triangle count on a log scale (viridis, dark = few); empty cells of the upper triangle
/// are light grey, the lower triangle white. A colour bar with the counts at its ends and at
/// the powers of ten between stands to the right. Paths longer than `MATRIX_PIXELS` frames
/// are binned: a pixel then sums the cells of `frames_per_pixel`² frame pairs.
fn draw_matrix(baked: &trisort_format::Baked, png: &std::path::Path) -> Result<MatrixImage> {
    let frames = (baked.frames.len() as u32).max(1);
    let (cell, bin) = if frames <= MATRIX_PIXELS {
        (MATRIX_PIXELS / frames, 1)
    } else {
        (1, frames.div_ceil(MATRIX_PIXELS))
    };
    let side = frames.div_ceil(bin); // grid cells per side
    let grid = side * cell;
    // Counts per grid cell (binned pairs summed).
    let mut counts = std::collections::HashMap::<(u32, u32), u64>::new();
    let cells = trisort_merger::cell_counts(baked);
    for &(i, j, n) in &cells {
        *counts.entry((i / bin, j / bin)).or_default() += n as u64;
    }
    let min = counts
        .values()
        .copied()
        .filter(|&n| n > 0)
        .min()
        .unwrap_or(1);
    let max = counts.values().copied().max().unwrap_or(1).max(min);
    let scale = |n: u64| -> f64 {
        if max == min {
            1.0
        } else {
            ((n as f64).ln() - (min as f64).ln()) / ((max as f64).ln() - (min as f64).ln())
        }
    };
    let bar_x = MARGIN + grid + 16;
    let bar_w = 16;
    let label_x = bar_x + bar_w + 6;
    let width = label_x + max.to_string().len() as u32 * DIGIT_ADVANCE + MARGIN;
    let bar_h = grid.max(120);
    let height = MARGIN + bar_h + MARGIN;
    let mut img = image::RgbImage::from_pixel(width, height, image::Rgb(BACKGROUND));
    for r in 0..side {
        for c in r..side {
            let colour = match counts.get(&(r, c)) {
                Some(&n) if n > 0 => viridis(scale(n)),
                _ => EMPTY,
            };
            fill(
                &mut img,
                MARGIN + c * cell,
                MARGIN + r * cell,
                cell,
                cell,
                colour,
            );
        }
    }
    // Colour bar: top = max, bottom = min.
    for y in 0..bar_h {
        let t = 1.0 - y as f64 / (bar_h - 1).max(1) as f64;
        fill(&mut img, bar_x, MARGIN + y, bar_w, 1, viridis(t));
    }
    let y_of = |n: u64| MARGIN + ((1.0 - scale(n)) * (bar_h - 1) as f64).round() as u32;
    let mut ticks = vec![max, min];
    let mut p = 10u64;
    while p < max {
        if p > min {
            ticks.push(p);
        }
        p = p.saturating_mul(10);
    }
    let mut taken: Vec<u32> = Vec::new();
    for (k, &n) in ticks.iter().enumerate() {
        let y = y_of(n);
        // Powers of ten that would overlap the end labels are ticked but not labelled.
        let free = taken.iter().all(|&t| t.abs_diff(y) >= DIGIT_HEIGHT + 2);
        fill(&mut img, bar_x + bar_w, y, 4, 1, INK);
        if k < 2 || free {
            let top = y
                .saturating_sub(DIGIT_HEIGHT / 2)
                .clamp(MARGIN, height - MARGIN - DIGIT_HEIGHT);
            draw_number(&mut img, label_x, top, n);
            taken.push(y);
        }
    }
    img.save_with_format(png, image::ImageFormat::Png)
        .with_context(|| format!("writing {}", png.display()))?;
    Ok(MatrixImage {
        width,
        height,
        cell_pixels: cell,
        frames_per_pixel: bin,
        cells: cells.len(),
        min,
        max,
    })
}

fn fill(img: &mut image::RgbImage, x: u32, y: u32, w: u32, h: u32, c: [u8; 3]) {
    for yy in y..(y + h).min(img.height()) {
        for xx in x..(x + w).min(img.width()) {
            img.put_pixel(xx, yy, image::Rgb(c));
        }
    }
}

/// The viridis colour map at `t` in [0, 1], interpolated between five of its colours.
fn viridis(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let k = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - k as f64;
    let mut out = [0u8; 3];
    for (c, o) in out.iter_mut().enumerate() {
        *o = (STOPS[k][c] + (STOPS[k + 1][c] - STOPS[k][c]) * f).round() as u8;
    }
    out
}

/// Pixel scale of the 3×5 digit glyphs.
const DIGIT_SCALE: u32 = 2;
const DIGIT_HEIGHT: u32 = 5 * DIGIT_SCALE;
const DIGIT_ADVANCE: u32 = 4 * DIGIT_SCALE;

/// Writes `n` in 3×5 pixel digits (scaled) with its top-left corner at (x, y).
fn draw_number(img: &mut image::RgbImage, x: u32, y: u32, n: u64) {
    // Rows of each digit, three bits each (most significant = left column).
    const GLYPHS: [[u8; 5]; 10] = [
        [7, 5, 5, 5, 7],
        [2, 6, 2, 2, 7],
        [7, 1, 7, 4, 7],
        [7, 1, 7, 1, 7],
        [5, 5, 7, 1, 1],
        [7, 4, 7, 1, 7],
        [7, 4, 7, 5, 7],
        [7, 1, 2, 2, 2],
        [7, 5, 7, 5, 7],
        [7, 5, 7, 1, 7],
    ];
    for (k, d) in n.to_string().bytes().enumerate() {
        let glyph = GLYPHS[(d - b'0') as usize];
        let x0 = x + k as u32 * DIGIT_ADVANCE;
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..3u32 {
                if bits >> (2 - col) & 1 == 1 {
                    fill(
                        img,
                        x0 + col * DIGIT_SCALE,
                        y + row as u32 * DIGIT_SCALE,
                        DIGIT_SCALE,
                        DIGIT_SCALE,
                        INK,
                    );
                }
            }
        }
    }
}
