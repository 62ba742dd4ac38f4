//! Group 0 on the data-texture tier ([`crate::Bindings::Textures`], `shaders/common/textures.wgsl`): node
//! matrices of every frame and the materials as Rgba32Float texels, [`DATA_WIDTH`] a row, and a
//! per-frame uniform with the frame's first node, bound by dynamic offset where the storage
//! tier binds the frame's matrices. GLES 3.0 / WebGL2 read these in the vertex stage, where
//! they have no storage buffers.

use wgpu::util::DeviceExt;

use crate::scene_gpu::budget::{sized_buffer, GpuBytes, GpuKind, SceneBudget};
use crate::scene_gpu::{FrameData, SharedBindings, DATA_WIDTH};

/// The bind group layout of group 0 on the texture tier.
pub(crate) fn texture_tier_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let surface = crate::scene_gpu::surface_entries();
    let vf = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
    let uniform = |binding, size: u64| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: vf,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: wgpu::BufferSize::new(size),
        },
        count: None,
    };
    let data = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: vf,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("trisort scene (data textures)"),
        entries: &[
            uniform(
                0,
                std::mem::size_of::<crate::scene_gpu::FrameUniform>() as u64,
            ),
            uniform(1, 16),
            data(2),
            surface[0],
            surface[1],
            data(5),
            surface[2],
            surface[3],
            surface[4],
            surface[5],
        ],
    })
}

/// `bytes` (a whole number of 16-byte texels) as an Rgba32Float texture [`DATA_WIDTH`] texels
/// wide, the last row padded with zeros.
fn data_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    bytes: &[u8],
) -> (wgpu::Texture, wgpu::TextureView) {
    let (padded, rows) = trisort_format::gpu_layout::data_texture_bytes(bytes);
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: DATA_WIDTH,
                height: rows,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            // COPY_DST: material variants rewrite the material texels.
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &padded,
    );
    let view = texture.create_view(&Default::default());
    (texture, view)
}

/// Rewrites the first texels of a data texture made by `data_texture` with `bytes` (a whole
/// number of 16-byte texels, no more than it holds), the last row padded with zeros.
pub(crate) fn write_data_texture(queue: &wgpu::Queue, texture: &wgpu::Texture, bytes: &[u8]) {
    let (padded, rows) = trisort_format::gpu_layout::data_texture_bytes(bytes);
    queue.write_texture(
        texture.as_image_copy(),
        &padded,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(DATA_WIDTH * 16),
            rows_per_image: Some(rows),
        },
        wgpu::Extent3d {
            width: DATA_WIDTH,
            height: rows,
            depth_or_array_layers: 1,
        },
    );
}

/// What [`bind_group`] uploads besides the shared bindings, and where it counts what it
/// creates.
pub(crate) struct TierData<'a> {
    pub(crate) data: &'a FrameData,
    pub(crate) material_bytes: &'a [u8],
    pub(crate) frames: usize,
    pub(crate) budget: &'a SceneBudget,
    pub(crate) allocated: &'a mut GpuBytes,
}

/// The texture tier's layout and bind group, and the stride of its per-frame node uniform
/// (the frame uniform's); the first-node uniforms sized by the budget, everything counted.
pub(crate) fn bind_group(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    shared: SharedBindings<'_>,
    tier: TierData<'_>,
) -> (
    wgpu::BindGroupLayout,
    wgpu::BindGroup,
    u64,
    crate::scene_gpu::MaterialStore,
) {
    let TierData {
        data,
        material_bytes,
        frames,
        budget,
        allocated,
    } = tier;
    debug_assert_eq!(data.node_stride, data.node_count * 64);
    let stride = data.frame_stride as usize;
    let mut base = vec![0u8; stride * frames.max(1)];
    for f in 0..frames {
        let first = (f as u64 * data.node_count) as u32;
        base[f * stride..][..4].copy_from_slice(&first.to_le_bytes());
    }
    let base_buffer = sized_buffer(
        device,
        "first node of each frame",
        budget.bytes.buffer(GpuKind::FirstNodes),
        &base,
        wgpu::BufferUsages::UNIFORM,
    );
    let (material_texture, materials) =
        data_texture(device, queue, "material texels", material_bytes);
    let (node_texture, nodes) = data_texture(device, queue, "node matrix texels", &data.node_bytes);
    allocated.count_buffer(GpuKind::FirstNodes, &base_buffer);
    allocated.count_texture(GpuKind::Materials, &material_texture);
    allocated.count_texture(GpuKind::NodeMatrices, &node_texture);
    let layout = texture_tier_layout(device);
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("trisort scene (data textures)"),
        layout: &layout,
        entries: &[
            [
                shared.frame,
                crate::scene_gpu::sized_buffer_entry(1, &base_buffer, 16),
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&materials),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::TextureView(&nodes),
                },
            ]
            .as_slice(),
            &shared.surface,
        ]
        .concat(),
    });
    (
        layout,
        bind_group,
        data.frame_stride,
        crate::scene_gpu::MaterialStore::Texture(material_texture),
    )
}
