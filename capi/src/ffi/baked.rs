//! Opening a baked file and copying out its geometry and its frames: index buffers, draw
//! ranges, vertices, cameras and node matrices.

use std::ffi::c_char;
use std::path::Path;

use glam::DMat4;
use trisort_format::{container, Baked, FileKind};

use super::boundary::*;
use super::types::*;

pub(super) fn open_baked(bytes: &[u8], path: &Path) -> Result<Box<TrisortBaked>, Failure> {
    let baked: Baked = container::decode(FileKind::Baked, bytes, path)?;
    baked.check_structure().map_err(|problem| {
        Failure(
            TrisortStatus::Format,
            format!("{}: inconsistent baked file: {problem}", path.display()),
        )
    })?;
    Ok(Box::new(TrisortBaked {
        baked,
        path: path.to_path_buf(),
    }))
}

/// Opens the baked file at `path` (NUL-terminated UTF-8) and stores its handle in `*out`.
/// The file is read, checked (magic, version, checksum, structure) and kept in memory.
///
/// # Safety
/// `path` is a NUL-terminated string; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_open_path(
    path: *const c_char,
    out: *mut *mut TrisortBaked,
) -> TrisortStatus {
    guard(|| {
        let (bytes, path) = read_path(path)?;
        let h = open_baked(&bytes, &path)?;
        store(out, Box::into_raw(h), "out")
    })
}

/// Opens a baked file from `len` bytes at `data` (copied; the host may free them after the
/// call) and stores its handle in `*out`.
///
/// # Safety
/// `data` is valid for `len` byte reads; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_open_bytes(
    data: *const u8,
    len: usize,
    out: *mut *mut TrisortBaked,
) -> TrisortStatus {
    guard(|| {
        let bytes = host_bytes(data, len)?;
        let h = open_baked(bytes, Path::new("<bytes>"))?;
        store(out, Box::into_raw(h), "out")
    })
}

/// Closes a handle from `trisort_open_*` (null is ignored). The handle is invalid afterwards.
///
/// # Safety
/// `h` is null or a handle not closed before.
#[no_mangle]
pub unsafe extern "C" fn trisort_close(h: *mut TrisortBaked) {
    close_handle(h)
}

/// Stores the file's figures in `*out`.
///
/// # Safety
/// `h` is an open handle; `out` is valid for one write.
#[no_mangle]
pub unsafe extern "C" fn trisort_info(
    h: *const TrisortBaked,
    out: *mut TrisortInfo,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let g = &b.geometry;
        let info = TrisortInfo {
            frame_count: b.frames.len() as u32,
            width: b.settings.width,
            height: b.settings.height,
            samples: b.settings.samples,
            vertex_count: g.vertices.len() as u32,
            triangle_count: g.triangles.len() as u32,
            index_triangle_count: b.copies.len() as u32,
            draw_count: b.draws.len() as u32,
            node_count: g.nodes.len() as u32,
            material_count: g.materials.len() as u32,
            texture_count: g.textures.len() as u32,
            glass_opacity: b.settings.glass_opacity,
            fits_u16: b.fits_u16(),
            depth_only: b.merge.depth_only,
            split_intersections: b.settings.split_intersections,
            recommended_mode: if b.merge.depth_only {
                TrisortMode::Depth
            } else {
                TrisortMode::Blend
            },
        };
        store(out, info, "out")
    })
}

/// The index buffer's triangles (G-local triangle ids) in front-to-back order, or reversed.
pub(super) fn ordered_copies(b: &Baked, back_to_front: bool) -> Vec<u32> {
    let mut copies = b.copies.clone();
    if back_to_front {
        copies.reverse();
    }
    copies
}

/// Copies the sorted index buffer as u32 indices into the vertex streams: front to back, or
/// reversed (`back_to_front`, what `TRISORT_MODE_BLEND` draws; use the same flag for the
/// frame ranges). `len` counts indices.
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the copy convention (top of this header).
#[no_mangle]
pub unsafe extern "C" fn trisort_indices_u32(
    h: *const TrisortBaked,
    back_to_front: bool,
    out: *mut u32,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let idx: Vec<u32> = ordered_copies(b, back_to_front)
            .iter()
            .flat_map(|&c| b.geometry.triangles[c as usize])
            .collect();
        copy_out(&idx, out, cap, len)
    })
}

/// `trisort_indices_u32()` as u16 indices; `TRISORT_STATUS_UNSUPPORTED` when the file has
/// more than 65,536 vertices (see the info's `fits_u16`).
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the copy convention (top of this header).
#[no_mangle]
pub unsafe extern "C" fn trisort_indices_u16(
    h: *const TrisortBaked,
    back_to_front: bool,
    out: *mut u16,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        if !b.fits_u16() {
            return Err(Failure(
                TrisortStatus::Unsupported,
                format!(
                    "{} vertices do not fit u16 indices: use trisort_indices_u32",
                    b.geometry.vertices.len()
                ),
            ));
        }
        let idx: Vec<u16> = ordered_copies(b, back_to_front)
            .iter()
            .flat_map(|&c| b.geometry.triangles[c as usize].map(|v| v as u16))
            .collect();
        copy_out(&idx, out, cap, len)
    })
}

/// Frame `frame`'s draws in drawing order over the index buffer of the same `back_to_front`.
pub(super) fn frame_ranges(b: &Baked, frame: usize, back_to_front: bool) -> Vec<TrisortRange> {
    let n = b.copies.len() as u32 * 3;
    let mut out: Vec<TrisortRange> = b
        .frame_draws(frame)
        .iter()
        .map(|d| TrisortRange {
            first: if back_to_front {
                n - d.first_index - d.index_count
            } else {
                d.first_index
            },
            count: d.index_count,
        })
        .collect();
    if back_to_front {
        out.reverse();
    }
    out
}

/// Copies frame `frame`'s draw ranges, in drawing order, over the index buffer of the same
/// `back_to_front` (`trisort_indices_u32()`). `len` counts ranges.
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the copy convention (top of this header).
#[no_mangle]
pub unsafe extern "C" fn trisort_frame_ranges(
    h: *const TrisortBaked,
    frame: u32,
    back_to_front: bool,
    out: *mut TrisortRange,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let f = frame_index(b.frames.len(), frame)?;
        copy_out(&frame_ranges(b, f, back_to_front), out, cap, len)
    })
}

/// Copies frame `frame`'s draws as indirect-draw arguments (the same draws as
/// `trisort_frame_ranges()`, ready for `glMultiDrawElementsIndirect`/`vkCmdDrawIndexedIndirect`).
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the copy convention (top of this header).
#[no_mangle]
pub unsafe extern "C" fn trisort_frame_draws(
    h: *const TrisortBaked,
    frame: u32,
    back_to_front: bool,
    out: *mut TrisortDrawIndexedIndirectArgs,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let f = frame_index(b.frames.len(), frame)?;
        let draws: Vec<TrisortDrawIndexedIndirectArgs> = frame_ranges(b, f, back_to_front)
            .iter()
            .map(|r| TrisortDrawIndexedIndirectArgs {
                index_count: r.count,
                instance_count: 1,
                first_index: r.first,
                base_vertex: 0,
                first_instance: 0,
            })
            .collect();
        copy_out(&draws, out, cap, len)
    })
}

/// Copies the vertex streams of G, interleaved (64 bytes per vertex).
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the copy convention (top of this header).
#[no_mangle]
pub unsafe extern "C" fn trisort_vertices(
    h: *const TrisortBaked,
    out: *mut TrisortVertex,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let v: Vec<TrisortVertex> = b
            .geometry
            .vertices
            .iter()
            .map(|v| TrisortVertex {
                position: v.position,
                normal: v.normal,
                uv: v.uv,
                material: v.material,
                node: v.node,
                tangent: v.tangent,
                uv1: v.uv1,
            })
            .collect();
        copy_out(&v, out, cap, len)
    })
}

pub(super) fn write_matrix(m: DMat4, out: *mut f32) -> Result<(), Failure> {
    if out.is_null() {
        return Err(null("out"));
    }
    let cols = m.as_mat4().to_cols_array();
    // SAFETY: the caller promised 16 writable floats.
    unsafe { std::ptr::copy_nonoverlapping(cols.as_ptr(), out, 16) };
    Ok(())
}

/// Writes frame `frame`'s camera view matrix (world to view; right handed, looking down −Z)
/// to `out[0..16]`.
///
/// # Safety
/// `h` is an open handle; `out` is valid for 16 float writes.
#[no_mangle]
pub unsafe extern "C" fn trisort_frame_view(
    h: *const TrisortBaked,
    frame: u32,
    out: *mut f32,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let f = frame_index(b.frames.len(), frame)?;
        write_matrix(b.frame_states[f].camera.view_matrix(), out)
    })
}

/// Writes frame `frame`'s projection matrix for an image of `aspect` (width / height) in the
/// clip-depth convention `depth` (a `TrisortDepthRange` value: `TRISORT_DEPTH_RANGE_ZERO_TO_ONE`
/// or `TRISORT_DEPTH_RANGE_MINUS_ONE_TO_ONE`; another is `TRISORT_STATUS_OUT_OF_RANGE`) to
/// `out[0..16]`, column major. A right-handed perspective (the view looks down −Z): near maps
/// to the low end of the depth range, far (or infinity, for a glTF camera without `zfar`) to
/// the high end. Built in f64 and rounded once, as trisort's own pipelines do.
///
/// # Safety
/// `h` is an open handle; `out` is valid for 16 float writes.
#[no_mangle]
pub unsafe extern "C" fn trisort_frame_projection(
    h: *const TrisortBaked,
    frame: u32,
    aspect: f64,
    depth: u32,
    out: *mut f32,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let f = frame_index(b.frames.len(), frame)?;
        let depth = match depth {
            0 => TrisortDepthRange::ZeroToOne,
            1 => TrisortDepthRange::MinusOneToOne,
            _ => {
                return Err(Failure(
                    TrisortStatus::OutOfRange,
                    format!(
                        "depth range {depth} is not a TrisortDepthRange (0: zero to one, 1: \
                         minus one to one)"
                    ),
                ))
            }
        };
        if !(aspect.is_finite() && aspect > 0.0) {
            return Err(Failure(
                TrisortStatus::OutOfRange,
                format!("aspect {aspect} is not a positive number"),
            ));
        }
        let p = b.frame_states[f].camera.projection(aspect);
        let p = match depth {
            TrisortDepthRange::ZeroToOne => p,
            // z' = 2z − w maps [0, w] onto [−w, w].
            TrisortDepthRange::MinusOneToOne => {
                DMat4::from_cols_array(&[
                    1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, -1.0, 1.0,
                ]) * p
            }
        };
        write_matrix(p, out)
    })
}

/// Copies frame `frame`'s node matrices, 16 floats per node: with `view_relative` the
/// camera-relative view × world matrices trisort's pipelines use (computed in f64, rounded
/// once: precise far from the origin), else the world matrices. `cap` and `len` count floats.
///
/// # Safety
/// `h` is an open handle; `out`, `cap`, `len` as in the copy convention (top of this header).
#[no_mangle]
pub unsafe extern "C" fn trisort_frame_node_matrices(
    h: *const TrisortBaked,
    frame: u32,
    view_relative: bool,
    out: *mut f32,
    cap: usize,
    len: *mut usize,
) -> TrisortStatus {
    guard(|| {
        let b = &handle(h, "handle")?.baked;
        let f = frame_index(b.frames.len(), frame)?;
        let state = &b.frame_states[f];
        let view = if view_relative {
            state.camera.view_matrix()
        } else {
            DMat4::IDENTITY
        };
        let floats: Vec<f32> = trisort_format::world_transforms(&b.geometry.nodes, &state.poses)
            .into_iter()
            .flat_map(|w| (view * w).as_mat4().to_cols_array())
            .collect();
        copy_out(&floats, out, cap, len)
    })
}
