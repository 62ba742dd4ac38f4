//! An offscreen target like the player's headless one: an MSAA colour attachment (and depth
//! where asked) resolved to one sample by the render pass, then read back.

use trisort_format::{FrameState, Geometry};
use trisort_gpu::scene_gpu::{Bindings, Lighting, SceneGpu, View};
use trisort_gpu::{FrameTarget, Gpu, TargetConfig};
use wgpu::util::DeviceExt;

use crate::ReferenceError;

/// Format of the depth attachment of [`Target`]s that have one (the headless player's).
pub(crate) use trisort_gpu::DEPTH_FORMAT;

/// The player's [`FrameTarget`] with a readback, rendered through one call.
pub(crate) struct Target(FrameTarget);

impl Target {
    /// Creates the attachments; errors where the adapter cannot multisample `format` (or the
    /// depth format) at `samples`.
    pub fn new(
        gpu: &Gpu,
        size: (u32, u32),
        samples: u32,
        format: wgpu::TextureFormat,
        depth: bool,
    ) -> Result<Target, ReferenceError> {
        let config = TargetConfig {
            size,
            samples,
            format,
            depth,
            readback: true,
        };
        FrameTarget::new(&gpu.adapter, &gpu.device, config)
            .map(Target)
            .map_err(|e| ReferenceError::Unsupported(format!("{}: {e}", gpu.describe())))
    }

    /// Runs one render pass cleared to `clear` (depth to 1), lets `draw` record into it,
    /// resolves, and returns the resolved texels as tightly packed rows.
    pub fn render(
        &self,
        gpu: &Gpu,
        clear: wgpu::Color,
        draw: impl FnOnce(&mut wgpu::RenderPass<'_>) -> Result<(), ReferenceError>,
    ) -> Result<Vec<u8>, ReferenceError> {
        let mut drawn = Ok(());
        let texels = self.0.read(gpu, |enc| {
            let mut pass = self.0.begin_pass(enc, clear, None);
            drawn = draw(&mut pass);
        })?;
        drawn?;
        Ok(texels)
    }
}

/// Rejects an empty size or a sample count other than 1 or 4 (the exact reference's and the
/// peeling renderer's patterns).
pub(crate) fn check_pattern(size: (u32, u32), samples: u32) -> Result<(), ReferenceError> {
    if size.0 == 0 || size.1 == 0 || !(samples == 1 || samples == 4) {
        return Err(ReferenceError::Invalid(format!(
            "{}x{} at {samples} samples: sizes must be positive and samples 1 or 4",
            size.0, size.1
        )));
    }
    Ok(())
}

/// The scene uploaded for a reference renderer: on the storage tier its shaders are composed
/// for ([`trisort_gpu::compose`]), lit as `lighting` says (the baked file's environment, as
/// the player lights it).
pub(crate) fn lit_scene(
    gpu: &Gpu,
    geometry: &Geometry,
    frames: &[FrameState],
    view: View,
    lighting: Lighting<'_>,
) -> SceneGpu {
    SceneGpu::with_lighting(
        &gpu.device,
        &gpu.queue,
        geometry,
        frames,
        view,
        Bindings::Storage,
        lighting,
    )
}

/// An index buffer of every triangle of `geometry` in scene order, so that `primitive_index`
/// is the scene id (one degenerate triangle where the scene has none: no empty buffers).
pub(crate) fn scene_index(device: &wgpu::Device, geometry: &Geometry, label: &str) -> wgpu::Buffer {
    let mut indices: Vec<u32> = geometry.triangles.iter().flatten().copied().collect();
    if indices.is_empty() {
        indices.extend_from_slice(&[0, 0, 0]);
    }
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(&indices),
        usage: wgpu::BufferUsages::INDEX,
    })
}
