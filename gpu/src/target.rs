//! The offscreen frame target shared by every renderer that draws like the player: the
//! headless player, the exact reference, the 8-bit deployment player and the window viewer.
//! A colour attachment (multisampled and resolved to one sample by the render pass when
//! `samples > 1`), an optional depth attachment, and an optional staging buffer to read the
//! resolved frame back.

use trisort_format::Mode;

use crate::pipeline::texture_2d;
use crate::readback::{halves, quantize_rgba16f};
use crate::GpuError;
#[cfg(not(target_arch = "wasm32"))]
use crate::{readback::poll_ready, Gpu};

/// The background every frame is drawn over: a dark grey, linear RGB.
pub const BACKGROUND: [f32; 3] = [0.03, 0.03, 0.03];

/// Format of the frame's colour attachment: linear, so blending is exact to f16 and the one
/// quantisation to 8-bit sRGB happens at readback ([`quantize_rgba16f`]).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the frame's depth attachment (`depth` mode only).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// What a [`FrameTarget`] holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TargetConfig {
    /// Size in pixels (zero is taken as one).
    pub size: (u32, u32),
    /// MSAA samples (zero is taken as one); above one the colour is resolved by the pass.
    pub samples: u32,
    /// Colour format.
    pub format: wgpu::TextureFormat,
    /// Whether there is a [`DEPTH_FORMAT`] attachment.
    pub depth: bool,
    /// Whether there is a staging buffer to read the resolved frame back.
    pub readback: bool,
}

impl TargetConfig {
    /// A [`COLOR_FORMAT`] frame read back after the pass, with depth in `depth` mode: what the
    /// headless player and the reference render into.
    pub fn readback(size: (u32, u32), samples: u32, mode: Mode) -> TargetConfig {
        TargetConfig {
            size,
            samples,
            format: COLOR_FORMAT,
            depth: mode == Mode::Depth,
            readback: true,
        }
    }
}

/// The clear colour of a mode's target: the background with alpha 1 for `blend` and `depth`;
/// transparent for `saturate`, whose background goes under the accumulated colour at the end.
pub fn clear_colour(mode: Mode) -> wgpu::Color {
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

/// Colour (and optional depth) attachments at one size, sample count and format.
pub struct FrameTarget {
    size: (u32, u32),
    bytes_per_pixel: u32,
    msaa: Option<wgpu::TextureView>,
    resolved: wgpu::Texture,
    resolved_view: wgpu::TextureView,
    depth: Option<wgpu::TextureView>,
    row_bytes: u32,
    staging: Option<wgpu::Buffer>,
}

impl FrameTarget {
    /// Creates the attachments (`Depth32Float` when `config.depth`), and a staging buffer when
    /// `config.readback`. The resolved texture can also be sampled (`TEXTURE_BINDING`). Errors
    /// where the adapter cannot multisample the colour or the depth format at the sample
    /// count, or where the colour format has no fixed texel size.
    pub fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        config: TargetConfig,
    ) -> Result<FrameTarget, GpuError> {
        let TargetConfig {
            size,
            samples,
            format,
            depth,
            readback,
        } = config;
        let size = (size.0.max(1), size.1.max(1));
        let samples = samples.max(1);
        for f in std::iter::once(format).chain(depth.then_some(DEPTH_FORMAT)) {
            if !adapter
                .get_texture_format_features(f)
                .flags
                .sample_count_supported(samples)
            {
                return Err(GpuError::SampleCount { format: f, samples });
            }
        }
        let bytes_per_pixel = format.block_copy_size(None).ok_or_else(|| {
            GpuError::Wgpu(format!("{format:?} has no fixed texel size to read back"))
        })?;
        let texture = |label, format, sample_count, usage| {
            texture_2d(device, label, size, sample_count, format, usage)
        };
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let resolved = texture(
            "trisort frame",
            format,
            1,
            attachment | wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let resolved_view = resolved.create_view(&Default::default());
        let msaa = (samples > 1).then(|| {
            texture("trisort frame (MSAA)", format, samples, attachment)
                .create_view(&Default::default())
        });
        let depth = depth.then(|| {
            texture("trisort depth", DEPTH_FORMAT, samples, attachment)
                .create_view(&Default::default())
        });
        let row_bytes = (size.0 * bytes_per_pixel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let staging = readback.then(|| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("trisort frame readback"),
                size: row_bytes as u64 * size.1 as u64,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        Ok(FrameTarget {
            size,
            bytes_per_pixel,
            msaa,
            resolved,
            resolved_view,
            depth,
            row_bytes,
            staging,
        })
    }

    /// The size in pixels.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The resolved single-sample colour view (for sampling it, e.g. a blit to a surface).
    pub fn resolved_view(&self) -> &wgpu::TextureView {
        &self.resolved_view
    }

    /// The resolved single-sample colour texture (what readback copies).
    pub fn resolved(&self) -> &wgpu::Texture {
        &self.resolved
    }

    /// Begins the frame's render pass: colour cleared to `clear` (resolved at the end when
    /// multisampled), depth cleared to 1 and discarded, with optional timestamp writes.
    pub fn begin_pass<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        clear: wgpu::Color,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        self.begin_pass_with(enc, Some(clear), true, timestamp_writes)
    }

    /// Begins a render pass that accumulates over several passes: colour cleared to `clear`
    /// when given (else loaded), and, when multisampled, resolved to the single-sample texture
    /// at the end when `resolve` (else the samples are stored for the next pass); depth as in
    /// [`FrameTarget::begin_pass`].
    pub fn begin_pass_with<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        clear: Option<wgpu::Color>,
        resolve: bool,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        let (view, resolve_target, store) = match &self.msaa {
            Some(msaa) if resolve => (msaa, Some(&self.resolved_view), wgpu::StoreOp::Discard),
            Some(msaa) => (msaa, None, wgpu::StoreOp::Store),
            None => (&self.resolved_view, None, wgpu::StoreOp::Store),
        };
        enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("trisort frame"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target,
                ops: wgpu::Operations {
                    load: clear.map_or(wgpu::LoadOp::Load, wgpu::LoadOp::Clear),
                    store,
                },
            })],
            depth_stencil_attachment: self.depth.as_ref().map(|view| {
                wgpu::RenderPassDepthStencilAttachment {
                    view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }
            }),
            timestamp_writes,
            ..Default::default()
        })
    }

    /// The staging buffer (present when created with `readback`).
    pub fn staging(&self) -> Option<&wgpu::Buffer> {
        self.staging.as_ref()
    }

    /// Records the copy of the resolved frame into the staging buffer. Panics if the target
    /// was created without `readback`.
    pub fn copy_to_staging(&self, enc: &mut wgpu::CommandEncoder) {
        let staging = self
            .staging
            .as_ref()
            .expect("FrameTarget created without readback");
        self.copy_to_buffer(enc, staging);
    }

    /// The bytes a buffer needs to hold the resolved frame ([`FrameTarget::copy_to_buffer`]):
    /// rows padded to wgpu's copy alignment.
    pub fn staging_size(&self) -> u64 {
        self.row_bytes as u64 * self.size.1 as u64
    }

    /// Records the copy of the resolved frame into `buffer` (`COPY_DST`, at least
    /// [`FrameTarget::staging_size`] bytes): for a caller that maps it itself, e.g. the web
    /// player, which cannot wait for a mapping.
    pub fn copy_to_buffer(&self, enc: &mut wgpu::CommandEncoder, buffer: &wgpu::Buffer) {
        enc.copy_texture_to_buffer(
            self.resolved.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.row_bytes),
                    rows_per_image: Some(self.size.1),
                },
            },
            self.resolved.size(),
        );
    }

    /// The staging buffer's mapped bytes of an `Rgba16Float` frame as 8-bit sRGB RGBA with
    /// alpha 255, quantized once like every frame trisort compares: in `saturate` mode the
    /// background goes under the accumulated colour first.
    pub fn rgba8(&self, padded: &[u8], mode: Mode) -> Vec<u8> {
        self.layout().rgba8(padded, mode)
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// Runs `encode` in one command encoder, copies the resolved frame to the staging buffer,
    /// submits, waits and returns the resolved texels as tightly packed rows. Errors on a wgpu
    /// validation error. Panics if the target was created without `readback`.
    pub fn read(
        &self,
        gpu: &Gpu,
        encode: impl FnOnce(&mut wgpu::CommandEncoder),
    ) -> Result<Vec<u8>, GpuError> {
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        encode(&mut enc);
        self.copy_to_staging(&mut enc);
        gpu.queue.submit([enc.finish()]);
        if let Some(Some(e)) = poll_ready(scope.pop()) {
            return Err(GpuError::Wgpu(e.to_string()));
        }
        let staging = self
            .staging
            .as_ref()
            .expect("FrameTarget created without readback");
        Ok(self.unpad(&gpu.map_read(staging)))
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// [`FrameTarget::read`] of an `Rgba16Float` frame as 8-bit sRGB RGBA (see
    /// [`FrameTarget::rgba8`]).
    pub fn read_rgba8(
        &self,
        gpu: &Gpu,
        mode: Mode,
        encode: impl FnOnce(&mut wgpu::CommandEncoder),
    ) -> Result<Vec<u8>, GpuError> {
        let texels = self.read(gpu, encode)?;
        Ok(quantize_rgba16f(
            &halves(&texels),
            (mode == Mode::Saturate).then_some(BACKGROUND),
        ))
    }

    /// The staging buffer's mapped bytes as tightly packed rows (drops the row padding).
    pub fn unpad(&self, padded: &[u8]) -> Vec<u8> {
        self.layout().unpad(padded)
    }

    /// How the resolved frame lies in a staging buffer, apart from the target: what a caller
    /// that converts the bytes after the target is out of reach keeps.
    pub fn layout(&self) -> StagingLayout {
        StagingLayout {
            row: self.size.0 * self.bytes_per_pixel,
            row_bytes: self.row_bytes,
            rows: self.size.1,
        }
    }
}

/// The rows of a [`FrameTarget`]'s frame in a staging buffer ([`FrameTarget::layout`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StagingLayout {
    /// Bytes of one row of texels.
    pub row: u32,
    /// Bytes from one row to the next in the buffer (`row` padded to the copy alignment).
    pub row_bytes: u32,
    /// Rows.
    pub rows: u32,
}

impl StagingLayout {
    /// The buffer's bytes as tightly packed rows (drops the row padding).
    pub fn unpad(&self, padded: &[u8]) -> Vec<u8> {
        let row = self.row as usize;
        let mut out = Vec::with_capacity(row * self.rows as usize);
        for y in 0..self.rows as usize {
            out.extend_from_slice(&padded[y * self.row_bytes as usize..][..row]);
        }
        out
    }

    /// An `Rgba16Float` frame's padded bytes as 8-bit sRGB RGBA with alpha 255
    /// ([`FrameTarget::rgba8`]).
    pub fn rgba8(&self, padded: &[u8], mode: Mode) -> Vec<u8> {
        quantize_rgba16f(
            &halves(&self.unpad(padded)),
            (mode == Mode::Saturate).then_some(BACKGROUND),
        )
    }
}
