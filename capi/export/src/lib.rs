//! trisort's order-only export, the part of the C API that needs the glTF importer.
//!
//! `libtrisort_export` is the player library (`libtrisort`, crate trisort-capi: every
//! function of `trisort.h`) plus [`trisort_export_order`] (header `trisort_export.h`). The
//! player-only library stays free of the importer and its C++ runtime (meshoptimizer); a host
//! that writes ORDER files links this one *instead of* `libtrisort`, never both.
//!
//! [`export`] builds the ORDER file of a baked file (docs/FORMAT.md § ORDER): the baked file
//! names its triangles by scene id, and which glTF triangle a scene id is follows from the
//! importer's documented id order, so the scene file is read again. `trisort export-order`
//! calls it too.
#![deny(missing_docs)]

use std::ffi::c_char;
use std::path::{Path, PathBuf};

use trisort_capi::ffi::boundary::{c_path, guard, Failure};
use trisort_capi::ffi::TrisortStatus;
use trisort_capi::{Order, OrderError, OrderRange, OrderSource};
use trisort_format::{Baked, FormatError, Hash};
use trisort_scene::TriangleSource;

// The player library's entry points are this library's too.
pub use trisort_capi::ffi;

/// Why an order could not be built or written. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// Writing the ORDER file failed.
    #[error(transparent)]
    Order(#[from] OrderError),
    /// The baked file could not be read.
    #[error(transparent)]
    Format(#[from] FormatError),
    /// The baked file decodes but its parts do not fit together.
    #[error("{path}: malformed baked file: {problem}")]
    MalformedBaked {
        /// The baked file.
        path: PathBuf,
        /// What is wrong.
        problem: trisort_format::StructureError,
    },
    /// The glTF scene could not be imported.
    #[error(transparent)]
    Scene(#[from] trisort_scene::SceneError),
    /// The scene is not the one the baked file was made from.
    #[error(
        "{scene}: not the scene {baked} was baked from (scene hash {found}, the baked file \
         says {expected}); give the .glb/.gltf file it was baked from"
    )]
    WrongScene {
        /// The scene file.
        scene: PathBuf,
        /// The baked file.
        baked: PathBuf,
        /// The scene's hash (hex prefix).
        found: String,
        /// The baked file's (hex prefix).
        expected: String,
    },
}

/// Reads the baked file at `baked_path`, checks its structure, builds its order over the glTF
/// file `scene` ([`from_baked`]) and writes it to `out` atomically: what
/// `trisort export-order` and the C API's `trisort_export_order` both do.
pub fn export(baked_path: &Path, scene: &Path, out: &Path) -> Result<Order, ExportError> {
    let baked: Baked = trisort_format::read_file(trisort_format::FileKind::Baked, baked_path)?;
    baked
        .check_structure()
        .map_err(|problem| ExportError::MalformedBaked {
            path: baked_path.to_path_buf(),
            problem,
        })?;
    let order = from_baked(&baked, baked_path, scene)?;
    order.write(out)?;
    Ok(order)
}

/// The order of `baked`, whose scene is the glTF file `scene`: imports it with the source of
/// every triangle, splits it as the recording did when the bake split intersections, checks
/// its hash against the baked file's, and names each index-buffer triangle by the source of
/// the scene triangle it is (or is a piece of).
pub fn from_baked(baked: &Baked, baked_path: &Path, scene: &Path) -> Result<Order, ExportError> {
    let (mut imported, sources) = trisort_scene::load_with_sources(scene)?;
    let hex = |h: &Hash| trisort_format::hash_hex(h)[..16].to_string();
    let wrong = |found: &Hash| ExportError::WrongScene {
        scene: scene.to_path_buf(),
        baked: baked_path.to_path_buf(),
        found: hex(found),
        expected: hex(&baked.scene_hash),
    };
    // The split needs the baked poses to name the scene's nodes: another scene may have
    // fewer.
    let nodes = imported.geometry.nodes.len();
    if (baked.frame_states.iter().enumerate())
        .any(|(f, s)| trisort_format::camera::check_frame_state(f, s, Some(nodes)).is_err())
    {
        return Err(wrong(&imported.hash()));
    }
    let mut origin: Option<Vec<u32>> = None;
    if let Some(split) = trisort_intersect::working_geometry(
        &imported.geometry,
        &baked.frame_states,
        &baked.settings,
    ) {
        *imported.geometry_mut() = split.geometry;
        origin = Some(split.origin);
    }
    let hash = imported.hash();
    if hash != baked.scene_hash {
        return Err(wrong(&hash));
    }
    let source_of = |scene_id: u32| -> TriangleSource {
        let id = origin.as_ref().map_or(scene_id, |o| o[scene_id as usize]);
        sources[id as usize]
    };
    let triangles = baked
        .copies
        .iter()
        .map(|&c| {
            let s = source_of(baked.scene_ids[c as usize]);
            OrderSource {
                mesh: s.mesh,
                primitive: s.primitive,
                triangle: s.triangle,
                node: s.node,
            }
        })
        .collect();
    Ok(Order {
        split: baked.settings.split_intersections,
        scene_hash: baked.scene_hash,
        frames: baked
            .frames
            .iter()
            .map(|w| OrderRange {
                first: w.first,
                count: w.count,
            })
            .collect(),
        ranges: baked
            .draws
            .iter()
            .map(|d| OrderRange {
                first: d.first_index / 3,
                count: d.index_count / 3,
            })
            .collect(),
        triangles,
    })
}

impl From<ExportError> for Failure {
    fn from(e: ExportError) -> Self {
        let status = match e {
            ExportError::Order(e) => return e.into(),
            ExportError::Format(e) => return e.into(),
            ExportError::MalformedBaked { .. } | ExportError::Scene(_) => TrisortStatus::Format,
            ExportError::WrongScene { .. } => TrisortStatus::Unsupported,
        };
        Failure(status, e.to_string())
    }
}

/// Builds the order-only export of the baked file at `baked_path`, whose scene is the glTF
/// file `scene_path`, and writes it to `out_path` (atomically). The same as
/// `trisort export-order BAKED --scene SCENE -o OUT`. On failure, `trisort_last_error()`
/// names the file and the problem: `TRISORT_STATUS_FORMAT` for a malformed baked or glTF
/// file, `TRISORT_STATUS_UNSUPPORTED` for a scene that is not the one baked,
/// `TRISORT_STATUS_IO` when a file cannot be read or written.
///
/// # Safety
/// The three paths are NUL-terminated UTF-8 strings.
#[no_mangle]
pub unsafe extern "C" fn trisort_export_order(
    baked_path: *const c_char,
    scene_path: *const c_char,
    out_path: *const c_char,
) -> TrisortStatus {
    guard(|| {
        let baked_path = c_path(baked_path, "baked_path")?;
        let scene_path = c_path(scene_path, "scene_path")?;
        let out_path = c_path(out_path, "out_path")?;
        export(&baked_path, &scene_path, &out_path)?;
        Ok(())
    })
}
