//! What the depth peelers (the recorder's and the reference's) share: the previous pass's
//! bindings and how a peel pass begins.

/// Group 1, bindings 0-2, of a peel pass (`peel.wgsl`'s `fs_peel`, `peeling.wgsl`'s
/// `fs_peeling`), read by the fragment stage: 0 the pass's 16-byte uniform at a dynamic
/// offset, 1 the previous pass's depth, 2 its ids (unsigned); both textures multisampled where
/// `samples > 1`. Both peelers build their peel layout from these.
pub fn previous_key_entries(samples: u32) -> [wgpu::BindGroupLayoutEntry; 3] {
    let texture = |binding, sample_type| {
        crate::pipeline::texture_entry(binding, wgpu::ShaderStages::FRAGMENT, sample_type, samples)
    };
    [
        crate::pipeline::uniform_entry(0, wgpu::ShaderStages::FRAGMENT, true, Some(16)),
        texture(1, wgpu::TextureSampleType::Depth),
        texture(2, wgpu::TextureSampleType::Uint),
    ]
}

/// Begins a peel pass: the id target `ids` cleared to 0 (no fragment) and the depth target
/// `depth` cleared to `clear_depth` (1 peeling front to back, 0 back to front), both stored;
/// the pass counts passing samples into `occlusion` where given. The recorder's peeler and
/// the reference's peeling renderer begin their peel passes through this.
pub fn begin_peel_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    ids: &wgpu::TextureView,
    depth: &wgpu::TextureView,
    clear_depth: f32,
    occlusion: Option<&wgpu::QuerySet>,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: ids,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(clear_depth),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        occlusion_query_set: occlusion,
        ..Default::default()
    })
}
