//! `trisort export-order BAKED --scene SCENE -o ORDER`: the order-only export (docs/FORMAT.md
//! § ORDER). Per index-buffer triangle, the glTF mesh, primitive, triangle and node it comes
//! from, and per frame its ranges: enough for a host that loads the glTF into its own buffers
//! to draw in the baked order with its own shaders.
//!
//! The baked file names its triangles by scene id; which glTF triangle a scene id is follows
//! from the importer's documented id order, so the scene file is read again (and checked
//! against the baked file's scene hash, after the same intersection split as the recording).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Result};
use clap::Args;
use serde_json::json;

use crate::common::print_json;

/// Arguments of `export-order`.
#[derive(Args, Debug)]
pub struct ExportOrderArgs {
    /// The baked file.
    baked: PathBuf,
    /// The .glb/.gltf scene it was baked from (the ORDER file names its meshes, primitives,
    /// triangles and nodes).
    #[arg(long)]
    scene: PathBuf,
    /// Where to write the ORDER file.
    #[arg(short, long)]
    output: PathBuf,
    /// Print the figures as JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(a: ExportOrderArgs) -> Result<ExitCode> {
    // `demo` and `demo:TRIANGLES` name the procedural car (as `load_scene` reads them); any
    // other name, `demolition.glb` included, is a file.
    let spec = a.scene.to_string_lossy();
    if (spec == "demo" || spec.starts_with("demo:")) && !a.scene.exists() {
        bail!(
            "--scene {}: the order names glTF meshes and primitives, so it needs the \
             .glb/.gltf file the bake was made from (the procedural demo car has none: export \
             it first, or use the C API's vertex streams)",
            a.scene.display()
        );
    }
    let order = trisort_export::export(&a.baked, &a.scene, &a.output)?;
    let repeated = order.triangles.windows(2).filter(|w| w[0] == w[1]).count();
    if a.json {
        print_json(&json!({
            "frames": order.frames.len(),
            "ranges": order.ranges.len(),
            "triangles": order.triangles.len(),
            "split": order.split,
            "repeated_sources": repeated,
        }));
    } else {
        println!(
            "{}: {} frames, {} ranges, {} triangles{}",
            a.output.display(),
            order.frames.len(),
            order.ranges.len(),
            order.triangles.len(),
            if order.split {
                format!(
                    " (split bake: {repeated} entries repeat the previous source triangle; \
                     bake with --keep-intersections for a one-to-one order)"
                )
            } else {
                String::new()
            }
        );
    }
    Ok(ExitCode::SUCCESS)
}
