//! Presenting frames in a window: the surface configuration the window viewer uses and the
//! blit from the player's linear `Rgba16Float` frame to the surface ([`Blit`], shader
//! `shaders/play/blit.wgsl`). The window shows the pixels of the PNG frames (within rounding of the
//! GPU's `pow`): the blit encodes sRGB itself and writes through a non-sRGB view where the
//! surface allows one.

use trisort_format::Mode;

use crate::readback::poll_ready;
use crate::{blit_shader, Gpu, GpuError, BACKGROUND};

/// A surface configured for the viewer and the format the blit writes through.
pub struct SurfaceSetup {
    /// The configuration (size, format, view formats, present and alpha modes).
    pub config: wgpu::SurfaceConfiguration,
    /// The format of the view the blit renders to: the surface format without its sRGB suffix
    /// where the backend offers that view, else the surface format itself.
    pub view_format: wgpu::TextureFormat,
}

/// Configures `surface` at `size` for `gpu`: the adapter's default format, viewed without its
/// sRGB suffix where possible (so the encoding and rounding are the ones `play --out-dir`
/// applies on the CPU, not the hardware's approximation: lavapipe's sRGB stores differ from
/// the exact transfer function by one step on most pixels), `Fifo` presentation and an opaque
/// alpha mode where offered.
pub fn configure_surface(
    gpu: &Gpu,
    surface: &wgpu::Surface<'_>,
    size: (u32, u32),
) -> Result<SurfaceSetup, GpuError> {
    let caps = surface.get_capabilities(&gpu.adapter);
    let mut config = surface
        .get_default_config(&gpu.adapter, size.0.max(1), size.1.max(1))
        .ok_or_else(|| {
            GpuError::Wgpu(format!("{} cannot present to this window", gpu.info.name))
        })?;
    let mut view_format = config.format.remove_srgb_suffix();
    if view_format != config.format {
        config.view_formats = vec![view_format];
    }
    if caps.present_modes.contains(&wgpu::PresentMode::Fifo) {
        config.present_mode = wgpu::PresentMode::Fifo;
    }
    if caps.alpha_modes.contains(&wgpu::CompositeAlphaMode::Opaque) {
        config.alpha_mode = wgpu::CompositeAlphaMode::Opaque;
    }
    let configure = |config: &wgpu::SurfaceConfiguration| {
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        surface.configure(&gpu.device, config);
        poll_ready(scope.pop()).flatten()
    };
    if let Some(e) = configure(&config) {
        if config.view_formats.is_empty() {
            return Err(GpuError::Wgpu(format!(
                "configuring the window's surface: {e}"
            )));
        }
        // Some backends (GL) offer no other view of the surface: write through its own sRGB
        // format and let the hardware encode.
        config.view_formats.clear();
        view_format = config.format;
        if let Some(e) = configure(&config) {
            return Err(GpuError::Wgpu(format!(
                "configuring the window's surface: {e}"
            )));
        }
    }
    Ok(SurfaceSetup {
        config,
        view_format,
    })
}

/// The full-screen copy of a frame to a surface view.
pub struct Blit {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

impl Blit {
    /// The blit to a view of `view_format` for frames played in `mode` (`saturate` puts the
    /// background under the accumulated colour). Float surfaces (scRGB) take linear values;
    /// the others get sRGB-encoded values.
    pub fn new(device: &wgpu::Device, view_format: wgpu::TextureFormat, mode: Mode) -> Blit {
        let encode = !view_format.is_srgb()
            && !matches!(
                view_format,
                wgpu::TextureFormat::Rgba16Float | wgpu::TextureFormat::Rgba32Float
            );
        let source = blit_shader(mode == Mode::Saturate, encode, BACKGROUND);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("trisort window blit"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("trisort window blit"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let pipeline = crate::pipeline::fullscreen(
            device,
            "trisort window blit",
            &[&layout],
            &module,
            ("vs_blit", "fs_blit"),
            wgpu::ColorTargetState {
                format: view_format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            },
            1,
        );
        Blit { layout, pipeline }
    }

    /// The bind group that reads `frame` (a resolved, single-sample `Rgba16Float` view).
    pub fn bind(
        &self,
        device: &wgpu::Device,
        frame: &wgpu::TextureView,
    ) -> Result<wgpu::BindGroup, GpuError> {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("trisort window blit"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(frame),
            }],
        });
        match poll_ready(scope.pop()) {
            Some(Some(e)) => Err(GpuError::Wgpu(e.to_string())),
            _ => Ok(group),
        }
    }

    /// Records the copy of the frame bound in `group` to `target` (cleared first).
    pub fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        group: &wgpu::BindGroup,
    ) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("trisort window blit"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
    }
}
