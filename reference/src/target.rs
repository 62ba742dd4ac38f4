//! An offscreen target like the player's headless one: an MSAA colour attachment (and depth
//! where asked) resolved to one sample by the render pass, then read back.

use trisort_shaders::gpu::Gpu;

use crate::ReferenceError;

/// Format of the depth attachment of [`Target`]s that have one (the headless player's).
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Colour (and optional depth) attachments at one size, sample count and format.
pub(crate) struct Target {
    size: (u32, u32),
    bytes_per_pixel: u32,
    msaa_view: Option<wgpu::TextureView>,
    resolved: wgpu::Texture,
    resolved_view: wgpu::TextureView,
    depth_view: Option<wgpu::TextureView>,
    row_bytes: u32,
    staging: wgpu::Buffer,
}

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
        let mut formats = vec![format];
        if depth {
            formats.push(DEPTH_FORMAT);
        }
        for f in formats {
            if !gpu
                .adapter
                .get_texture_format_features(f)
                .flags
                .sample_count_supported(samples)
            {
                return Err(ReferenceError::Unsupported(format!(
                    "{} cannot render {f:?} at {samples}x MSAA",
                    gpu.describe()
                )));
            }
        }
        let bytes_per_pixel = format.block_copy_size(None).ok_or_else(|| {
            ReferenceError::Unsupported(format!("{format:?} cannot be read back"))
        })?;
        let device = &gpu.device;
        let extent = wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, sample_count, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: extent,
                mip_level_count: 1,
                sample_count,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let resolved = texture(
            "reference frame",
            format,
            1,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let resolved_view = resolved.create_view(&Default::default());
        let msaa_view = (samples > 1).then(|| {
            texture(
                "reference frame (MSAA)",
                format,
                samples,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            )
            .create_view(&Default::default())
        });
        let depth_view = depth.then(|| {
            texture(
                "reference depth",
                DEPTH_FORMAT,
                samples,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            )
            .create_view(&Default::default())
        });
        let row_bytes = (size.0 * bytes_per_pixel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("reference readback"),
            size: row_bytes as u64 * size.1 as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Target {
            size,
            bytes_per_pixel,
            msaa_view,
            resolved,
            resolved_view,
            depth_view,
            row_bytes,
            staging,
        })
    }

    /// Runs one render pass cleared to `clear` (depth to 1), lets `draw` record into it,
    /// resolves, and returns the resolved texels as tightly packed rows.
    pub fn render(
        &self,
        gpu: &Gpu,
        clear: wgpu::Color,
        draw: impl FnOnce(&mut wgpu::RenderPass<'_>) -> Result<(), ReferenceError>,
    ) -> Result<Vec<u8>, ReferenceError> {
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let (view, resolve_target, store) = match &self.msaa_view {
            Some(msaa) => (msaa, Some(&self.resolved_view), wgpu::StoreOp::Discard),
            None => (&self.resolved_view, None, wgpu::StoreOp::Store),
        };
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("reference frame"),
        });
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("reference frame"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(clear),
                        store,
                    },
                })],
                depth_stencil_attachment: self.depth_view.as_ref().map(|view| {
                    wgpu::RenderPassDepthStencilAttachment {
                        view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Discard,
                        }),
                        stencil_ops: None,
                    }
                }),
                ..Default::default()
            });
            draw(&mut pass)?;
        }
        let (w, h) = self.size;
        enc.copy_texture_to_buffer(
            self.resolved.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.row_bytes),
                    rows_per_image: Some(h),
                },
            },
            self.resolved.size(),
        );
        gpu.queue.submit([enc.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(ReferenceError::Wgpu(e.to_string()));
        }
        let padded = gpu.map_read(&self.staging);
        let row = (w * self.bytes_per_pixel) as usize;
        let mut out = Vec::with_capacity(row * h as usize);
        for y in 0..h as usize {
            out.extend_from_slice(&padded[y * self.row_bytes as usize..][..row]);
        }
        Ok(out)
    }
}

/// Little-endian halves from `Rgba16Float` bytes.
pub(crate) fn halves(bytes: &[u8]) -> Vec<u16> {
    bytes
        .chunks_exact(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
        .collect()
}

/// The clear colour of a mode's target, as the headless player clears it: the background
/// with alpha 1 for `blend` and `depth`, transparent for `saturate` (the background goes under
/// at the end).
pub(crate) fn clear_colour(mode: trisort_player::Mode) -> wgpu::Color {
    use trisort_player::{Mode, BACKGROUND};
    match mode {
        Mode::Saturate => wgpu::Color::TRANSPARENT,
        Mode::Blend | Mode::Depth => wgpu::Color {
            r: BACKGROUND[0] as f64,
            g: BACKGROUND[1] as f64,
            b: BACKGROUND[2] as f64,
            a: 1.0,
        },
    }
}
