//! The per-frame `Frame` uniform (projection, light, view size, view-to-world rotation), the
//! `Lighting` uniform of a scene's light, and every frame's uniforms and camera-relative node
//! matrices laid out at the device's dynamic-offset strides.

use trisort_format::gpu_layout::{node_count, node_matrices};
use trisort_format::{FrameState, Geometry, Shading};

use super::budget::SceneBudget;
use super::View;
pub use trisort_format::gpu_layout::{
    frame_uniform, projection, subpixel_shift, FrameUniform, Lighting, LightingUniform, LIGHT,
};

/// The pipeline-overridable constants that specialise a pipeline's surface function to
/// `shading` (`SHADING_MODEL` in `shaders/common/common.wgsl`), so it compiles only this model's code; for
/// the fragment stage of pipelines whose module includes the common WGSL. Without them the
/// model is chosen at run time from the lighting uniform.
pub fn shading_constants(shading: Shading) -> &'static [(&'static str, f64)] {
    match shading {
        Shading::Basic => &[("SHADING_MODEL", 0.0)],
        Shading::Pbr => &[("SHADING_MODEL", 1.0)],
    }
}

/// Every frame's uniform and node matrices, each frame at its stride (the device's dynamic
/// offset alignments).
pub(crate) struct FrameData {
    pub(crate) frame_bytes: Vec<u8>,
    pub(crate) node_bytes: Vec<u8>,
    pub(crate) frame_stride: u64,
    pub(crate) node_stride: u64,
    pub(crate) node_count: u64,
}

/// Computes [`FrameData`] at the budget's strides: camera-relative node matrices in f64, cast
/// once.
pub(super) fn frame_data(
    geometry: &Geometry,
    frames: &[FrameState],
    view: View,
    budget: &SceneBudget,
) -> FrameData {
    let (frame_stride, node_stride) = (budget.frame_stride, budget.node_stride);
    let node_count = node_count(geometry) as u64;
    let nframes = frames.len().max(1) as u64;
    let mut frame_bytes = vec![0u8; (frame_stride * nframes) as usize];
    let mut node_bytes = vec![0u8; (node_stride * nframes) as usize];
    for (f, state) in frames.iter().enumerate() {
        let u = frame_uniform(state, view);
        frame_bytes[f * frame_stride as usize..][..std::mem::size_of::<FrameUniform>()]
            .copy_from_slice(bytemuck::bytes_of(&u));
        let m = node_matrices(geometry, state);
        let b: &[u8] = bytemuck::cast_slice(&m);
        node_bytes[f * node_stride as usize..][..b.len()].copy_from_slice(b);
    }
    FrameData {
        frame_bytes,
        node_bytes,
        frame_stride,
        node_stride,
        node_count,
    }
}
