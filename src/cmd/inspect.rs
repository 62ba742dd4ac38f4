//! `trisort inspect FILE`: a scene, a recording or a baked file.

use std::path::PathBuf;
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
        Some(FileKind::Recording) => {
            let rec: Recording = crate::cmd::merge::read_recording(&path)?;
            let v = crate::cmd::record::recording_json(&rec, None);
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
        Some(FileKind::Baked) => {
            let baked: trisort_format::Baked = trisort_format::read_file(FileKind::Baked, &path)?;
            baked
                .check_structure()
                .map_err(|e| anyhow::anyhow!("{}: malformed baked file: {e}", a.file))?;
            let s = &baked.stats;
            let v = json!({
                "strategy": baked.merge.strategy, "layout": baked.merge.layout,
                "index_triangles": s.index_triangles, "source_triangles": s.source_triangles,
                "unique_visible": s.unique_visible, "draws_per_frame_mean": s.draws_per_frame_mean,
                "draws_per_frame_max": s.draws_per_frame_max, "drawn_not_visible_mean": s.drawn_not_visible_mean,
                "unordered_samples": s.unordered_samples, "seconds": s.seconds,
                "frames": baked.frames.len(),
            });
            if a.json {
                print_json(&v);
            } else {
                println!("{}: baked file, {} frames", a.file, baked.frames.len());
                println!("{}", serde_json::to_string_pretty(&v)?);
            }
            Ok(ExitCode::SUCCESS)
        }
        None => {
            let scene = load_scene(&a.file)?;
            let st = &scene.stats;
            let g = &scene.geometry;
            let count_mode = |m: trisort_format::AlphaMode| {
                g.materials.iter().filter(|x| x.alpha_mode == m).count()
            };
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
                    "  animations {} (moving {} nodes: {}), cameras {}",
                    st.animations,
                    animated.len(),
                    animated.iter().cloned().collect::<Vec<_>>().join(", "),
                    st.cameras
                );
                if let Some((lo, hi)) = scene.bounds() {
                    println!("  bounds {:.3?} .. {:.3?}", lo.to_array(), hi.to_array());
                }
                for n in &scene.notes {
                    println!("  note: {n}");
                }
            }
            Ok(ExitCode::SUCCESS)
        }
    }
}
