//! The vertex layout of [`Vertex`] and the render pipeline builder every trisort pipeline over
//! the scene's vertex buffer uses.

use trisort_format::{Shading, Vertex};

use super::uniforms::shading_constants;

/// Vertex buffer layout of [`Vertex`] (locations 0–6 of `VertexIn`: position, normal, uv,
/// material, node, tangent, uv1).
pub const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 7] = wgpu::vertex_attr_array![
    0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Uint32, 4 => Uint32,
    5 => Float32x4, 6 => Float32x2
];

/// The vertex buffer layout for pipelines.
pub fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &VERTEX_ATTRIBUTES,
    }
}

/// A render pipeline over the scene's vertex buffer with the state every trisort pipeline
/// shares: counter-clockwise front faces, no hardware culling (single-sided materials discard
/// back faces in the shader, so one pipeline serves all materials), and the given depth test,
/// MSAA count and colour target.
pub struct ScenePipeline<'a> {
    /// Label.
    pub label: &'a str,
    /// Bind group layouts (group 0 is [`SceneGpu::layout`](super::SceneGpu::layout)).
    pub layouts: &'a [&'a wgpu::BindGroupLayout],
    /// The composed shader module.
    pub module: &'a wgpu::ShaderModule,
    /// Vertex entry point.
    pub vertex: &'a str,
    /// Fragment entry point.
    pub fragment: &'a str,
    /// Colour target.
    pub target: wgpu::ColorTargetState,
    /// Depth format, compare function and whether depth is written; `None`: no depth test.
    pub depth: Option<(wgpu::TextureFormat, wgpu::CompareFunction, bool)>,
    /// MSAA samples.
    pub samples: u32,
}

impl ScenePipeline<'_> {
    /// Creates the pipeline (a surface function, if it shades, choosing its model at run time).
    pub fn build(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        self.build_with(device, &[], true)
    }

    /// Creates the pipeline without its fragment stage and colour target (`fragment` and
    /// `target` are not used): a depth-only pass, for a render pass with no colour attachment
    /// (the occlusion queries of paper 004's sort).
    pub fn build_depth_only(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        self.build_with(device, &[], false)
    }

    /// Creates the pipeline with its surface function specialised to `shading`
    /// ([`shading_constants`]): for pipelines that shade, so they compile what the player's
    /// pipeline compiles.
    pub fn build_shaded(&self, device: &wgpu::Device, shading: Shading) -> wgpu::RenderPipeline {
        self.build_with(device, shading_constants(shading), true)
    }

    fn build_with(
        &self,
        device: &wgpu::Device,
        constants: &[(&str, f64)],
        fragment: bool,
    ) -> wgpu::RenderPipeline {
        let layouts: Vec<Option<&wgpu::BindGroupLayout>> =
            self.layouts.iter().map(|l| Some(*l)).collect();
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(self.label),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
        let targets = [Some(self.target.clone())];
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(self.label),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: self.module,
                entry_point: Some(self.vertex),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_layout())],
            },
            primitive: wgpu::PrimitiveState {
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: self
                .depth
                .map(|(format, compare, write)| wgpu::DepthStencilState {
                    format,
                    depth_write_enabled: Some(write),
                    depth_compare: Some(compare),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
            multisample: wgpu::MultisampleState {
                count: self.samples,
                mask: !0,
                alpha_to_coverage_enabled: false,
            },
            fragment: fragment.then(|| wgpu::FragmentState {
                module: self.module,
                entry_point: Some(self.fragment),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    ..Default::default()
                },
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}
