//! The *default pipeline*: what engines do today, as a comparison renderer for `bench`.
//!
//! Every triangle of the scene, with the depth test: first the opaque ones (`OPAQUE` and
//! `MASK` materials) in ascending id order with depth writes, then the transparent ones
//! (`BLEND` materials and transmissive glass) in ascending id order, unsorted, with the depth
//! test on and depth writes off. Both passes use the player's vertex shader, its
//! `fs_player_straight` and its `over` blend state, into the same `Rgba16Float` MSAA target,
//! resolved and quantized once like the player's frames. Its error against the exact
//! reference is what sorting buys.

use trisort_format::{FrameState, Geometry};
use trisort_gpu::scene_gpu::{Lighting, SceneGpu, ScenePipeline, View};
use trisort_gpu::Gpu;
use trisort_gpu::{clear_colour, halves, quantize_rgba16f, COLOR_FORMAT};
use trisort_player::{blend_state, Mode};
use wgpu::util::DeviceExt;

use crate::target::{lit_scene, Target, DEPTH_FORMAT};
use crate::ReferenceError;

/// Whether a scene triangle is drawn in the transparent pass: its material (that of its first
/// vertex) is `BLEND` or transmissive.
pub fn is_transparent(geometry: &Geometry, triangle: usize) -> bool {
    geometry.needs_order(triangle as u32)
}

/// The default pipeline for one scene at one view.
pub struct DefaultRenderer<'g> {
    gpu: &'g Gpu,
    scene: SceneGpu,
    /// The player's shader module its pipelines are built from.
    module: wgpu::ShaderModule,
    opaque_pipeline: wgpu::RenderPipeline,
    transparent_pipeline: wgpu::RenderPipeline,
    opaque: (wgpu::Buffer, u32),
    transparent: (wgpu::Buffer, u32),
    target: Target,
}

impl<'g> DefaultRenderer<'g> {
    /// Uploads the whole scene for rendering at `view`, lit as `lighting` says. Errors where the adapter cannot
    /// multisample the targets.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
        lighting: Lighting<'_>,
    ) -> Result<DefaultRenderer<'g>, ReferenceError> {
        let device = &gpu.device;
        let target = Target::new(
            gpu,
            (view.width, view.height),
            view.samples,
            COLOR_FORMAT,
            true,
        )?;
        let shading = lighting.shading;
        let scene = lit_scene(gpu, geometry, frames, view, lighting);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("default pipeline"),
            source: wgpu::ShaderSource::Wgsl(trisort_gpu::compose(&[], trisort_gpu::PLAYER).into()),
        });
        let pipeline = |write: bool| {
            ScenePipeline {
                label: if write {
                    "default pipeline (opaque)"
                } else {
                    "default pipeline (transparent)"
                },
                layouts: &[&scene.layout],
                module: &module,
                vertex: "vs_player",
                fragment: trisort_player::fragment_entry_point(Mode::Blend),
                target: wgpu::ColorTargetState {
                    format: COLOR_FORMAT,
                    blend: Some(blend_state(Mode::Blend)),
                    write_mask: wgpu::ColorWrites::ALL,
                },
                depth: Some((DEPTH_FORMAT, wgpu::CompareFunction::Less, write)),
                samples: view.samples,
            }
            .build_shaded(device, shading)
        };
        let opaque_pipeline = pipeline(true);
        let transparent_pipeline = pipeline(false);
        let mut lists = [Vec::new(), Vec::new()];
        for (t, tri) in geometry.triangles.iter().enumerate() {
            lists[is_transparent(geometry, t) as usize].extend_from_slice(tri);
        }
        let upload = |indices: &Vec<u32>| {
            let n = indices.len() as u32;
            let data: &[u32] = if indices.is_empty() { &[0; 3] } else { indices };
            let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("default pipeline indices"),
                contents: bytemuck::cast_slice(data),
                usage: wgpu::BufferUsages::INDEX,
            });
            (buffer, n)
        };
        Ok(DefaultRenderer {
            gpu,
            opaque: upload(&lists[0]),
            transparent: upload(&lists[1]),
            scene,
            module,
            opaque_pipeline,
            transparent_pipeline,
            target,
        })
    }

    /// Number of triangles drawn per frame (opaque, transparent).
    pub fn triangles(&self) -> (u32, u32) {
        (self.opaque.1 / 3, self.transparent.1 / 3)
    }

    /// Records frame `frame` into `pass`, whose attachments must match the view (an
    /// `Rgba16Float` colour and a `Depth32Float` depth at its sample count): the opaque draw,
    /// then the transparent one.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, frame: u32) {
        self.draw_with(pass, frame, (&self.transparent.0, self.transparent.1));
    }

    /// [`DefaultRenderer::draw`] with the transparent pass drawing `transparent` (an index
    /// buffer and its index count) instead of the ascending ids: a renderer that orders the
    /// transparent triangles itself (the occlusion-query sort of paper 004).
    pub fn draw_with(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        frame: u32,
        transparent: (&wgpu::Buffer, u32),
    ) {
        pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
        pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
        for (pipeline, (index, count)) in [
            (&self.opaque_pipeline, (&self.opaque.0, self.opaque.1)),
            (&self.transparent_pipeline, transparent),
        ] {
            if count == 0 {
                continue;
            }
            pass.set_pipeline(pipeline);
            pass.set_index_buffer(index.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..count, 0, 0..1);
        }
    }

    /// Renders frame `frame` over the player's background and returns it as 8-bit sRGB RGBA
    /// (quantized once, like the player's frames).
    pub fn render(&self, frame: u32) -> Result<Vec<u8>, ReferenceError> {
        self.render_with(frame, (&self.transparent.0, self.transparent.1))
    }

    /// [`DefaultRenderer::render`] with [`DefaultRenderer::draw_with`]'s transparent draw.
    pub fn render_with(
        &self,
        frame: u32,
        transparent: (&wgpu::Buffer, u32),
    ) -> Result<Vec<u8>, ReferenceError> {
        let bytes = self
            .target
            .render(self.gpu, clear_colour(Mode::Blend), |pass| {
                self.draw_with(pass, frame, transparent);
                Ok(())
            })?;
        Ok(quantize_rgba16f(&halves(&bytes), None))
    }

    /// The uploaded scene (its layout, bind group and vertices), for pipelines that draw it
    /// beside this renderer's.
    pub fn scene(&self) -> &SceneGpu {
        &self.scene
    }

    /// The player's shader module (`vs_player` and its fragment stages), for pipelines that
    /// draw the scene beside this renderer's.
    pub fn module(&self) -> &wgpu::ShaderModule {
        &self.module
    }
}
