//! `trisort inspect FILE`: a scene, a recording or a baked file.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;
use serde_json::json;
use trisort_format::{FileKind, Recording};

use crate::common::{load_scene, print_json};
use trisort_gpu::scene_gpu::budget::{PORTABLE_MAX_TEXTURE_DIMENSION, PORTABLE_OFFSET_ALIGNMENT};
use trisort_gpu::scene_gpu::{Bindings, GpuBytes};
use trisort_player::GpuBudget;

/// GPU bytes as JSON: `textures`, `buffers`, `total`, and by kind `buffers_by_kind` and
/// `textures_by_kind` (`play --json`'s `gpu_bytes_allocated`, and each tier of `inspect`'s
/// `gpu_bytes`).
pub(crate) fn gpu_bytes_json(bytes: &GpuBytes) -> serde_json::Value {
    let kinds = |it: &mut dyn Iterator<Item = (trisort_gpu::scene_gpu::GpuKind, u64)>| {
        it.map(|(k, b)| (k.name().to_string(), json!(b)))
            .collect::<serde_json::Map<_, _>>()
    };
    json!({
        "textures": bytes.textures(),
        "buffers": bytes.buffers(),
        "total": bytes.total(),
        "buffers_by_kind": kinds(&mut bytes.buffer_kinds()),
        "textures_by_kind": kinds(&mut bytes.texture_kinds()),
    })
}

/// `inspect BAKED`'s `gpu_bytes`: what a player allocates on a device with WebGPU's default
/// limits, on the storage tier (the three totals) and per tier (`tiers.storage`,
/// `tiers.textures`: by kind, the index format, the texture arrays), with what it assumes.
/// Block-compressed textures count at their stored size (a device with the compression
/// feature); `textures_decoded` is the texture bytes of `decoded`, the same budgets on a
/// device without it.
fn budget_json(budgets: &[GpuBudget; 2], decoded: &[GpuBudget; 2]) -> serde_json::Value {
    let tier = |b: &GpuBudget, d: &GpuBudget| {
        let mut v = gpu_bytes_json(&b.bytes);
        v["textures_decoded"] = json!(d.bytes.textures());
        let array = |k: usize| {
            let (width, height, levels) = b.arrays[k];
            json!({
                "width": width, "height": height, "levels": levels, "layers": b.layers[k],
                "format": b.texture_uploads[k].name(),
            })
        };
        v["index_format"] = json!(match b.index_format {
            wgpu::IndexFormat::Uint16 => "u16",
            wgpu::IndexFormat::Uint32 => "u32",
        });
        // `format`: both arrays' where they agree (`rgba8` for a file without blocks).
        let [srgb, linear] = b.texture_uploads.clone().map(|u| u.name());
        let format = if srgb == linear {
            srgb
        } else {
            format!("srgb {srgb}, linear {linear}")
        };
        v["texture_arrays"] = json!({"srgb": array(0), "linear": array(1), "format": format});
        v
    };
    let storage = &budgets[0].bytes;
    json!({
        "textures": storage.textures(),
        // A device without the compression feature of the file's blocks decodes them to RGBA8.
        "textures_decoded": decoded[0].bytes.textures(),
        "buffers": storage.buffers(),
        "total": storage.total(),
        "tier": "storage",
        "tiers": {
            "storage": tier(&budgets[0], &decoded[0]),
            "textures": tier(&budgets[1], &decoded[1]),
        },
        "assumes": {
            "max_texture_dimension_2d": PORTABLE_MAX_TEXTURE_DIMENSION,
            "offset_alignment": PORTABLE_OFFSET_ALIGNMENT,
            "gl": false,
            // Block-compressed textures are sampled as stored (`textures`), not decoded.
            "texture_compression": ["bc", "etc2", "astc"],
        },
    })
}

/// The budget in `inspect`'s text: each tier's total, buffers and textures, and the textures
/// by kind.
fn print_budget(budgets: &[GpuBudget; 2], decoded: &[GpuBudget; 2]) {
    let mb = |b: u64| match b {
        0..1_000 => format!("{b} B"),
        1_000..1_000_000 => format!("{:.1} kB", b as f64 / 1e3),
        _ => format!("{:.2} MB", b as f64 / 1e6),
    };
    let tiers: Vec<String> = budgets
        .iter()
        .map(|b| {
            format!(
                "{} tier {} (buffers {}, textures {})",
                b.config.bindings.name(),
                mb(b.bytes.total()),
                mb(b.bytes.buffers()),
                mb(b.bytes.textures())
            )
        })
        .collect();
    println!("  GPU memory a player allocates: {}", tiers.join("; "));
    let kinds: Vec<String> = (budgets[0].bytes.texture_kinds())
        .map(|(k, b)| format!("{} {}", k.name(), mb(b)))
        .collect();
    println!("    storage tier's textures: {}", kinds.join(", "));
    let (textures, unpacked) = (budgets[0].bytes.textures(), decoded[0].bytes.textures());
    if textures != unpacked {
        let [srgb, linear] = budgets[0].texture_uploads.clone().map(|u| u.name());
        println!(
            "    texture arrays sRGB {srgb}, linear {linear}: {} ({} decoded, on a device without the compression feature)",
            mb(textures),
            mb(unpacked)
        );
    }
}

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
        Some(FileKind::Presorted) => super::presort::inspect(&path, a.json),
        None => inspect_scene(&a),
    }
}

/// `inspect` of a recording: its `record --json` keys, or a summary line per frame.
fn inspect_recording(a: &InspectArgs, path: &Path) -> Result<ExitCode> {
    if a.matrix.is_some() {
        anyhow::bail!("{}: --matrix needs a baked file, not a recording", a.file);
    }
    let rec: Recording = trisort_bake::inputs::read_recording(path)?;
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
    let mut v = trisort_bake::figures::baked_file_json(&baked);
    // The camera paths of the file (a bundle has several): DESIGN's `clips[{name, frames,
    // fps}]`, `frames` the clip's count, with where it starts in the file and in its path.
    v["clips"] = trisort_bake::figures::clips_json(&baked);
    let tiers = [Bindings::Storage, Bindings::Textures];
    let budgets = tiers.map(|b| GpuBudget::portable(&baked, b));
    let decoded = tiers.map(|b| GpuBudget::portable_decoded(&baked, b));
    v["gpu_bytes"] = budget_json(&budgets, &decoded);
    if let Some(png) = &a.matrix {
        let m = trisort_bench::matrix::draw_matrix(&baked, png)?;
        let margin = trisort_bench::matrix::MARGIN;
        v["matrix"] = json!({
            "file": png.display().to_string(), "width": m.width, "height": m.height,
            "origin": [margin, margin], "cell_pixels": m.cell_pixels,
            "frames_per_pixel": m.frames_per_pixel, "cells": m.cells,
            "min_triangles": m.min_triangles, "max_triangles": m.max_triangles,
        });
    }
    if a.json {
        print_json(&v);
    } else {
        println!("{}: baked file, {} frames", a.file, baked.frames.len());
        print_clips(&baked.clips);
        print_budget(&budgets, &decoded);
        println!("{}", serde_json::to_string_pretty(&v)?);
    }
    Ok(ExitCode::SUCCESS)
}

/// The clips of a baked file, one line each: name, the file's frames it spans, count, rate,
/// and the frame of its path it starts at where that is not 0.
fn print_clips(clips: &[trisort_format::Clip]) {
    println!("  clips {} (play --clip NAME):", clips.len());
    for c in clips {
        let frames = c.frames();
        let fps = c
            .fps
            .map_or("fps unknown".to_string(), |f| format!("{f} fps"));
        let from = match c.path_first {
            0 => String::new(),
            p => format!(", from frame {p} of its path"),
        };
        let plural = if c.count == 1 { "" } else { "s" };
        println!(
            "    {}: frames {}..{} ({} frame{plural}), {fps}{from}",
            c.name, frames.start, frames.end, c.count
        );
    }
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
    let animated = trisort_bake::figures::animated_nodes(&scene);
    let split = trisort_bake::figures::split_at_rest(&scene);
    let v = trisort_bake::figures::scene_json(&scene, &split);
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
