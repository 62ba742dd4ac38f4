//! Group 0's binding tiers: storage buffers, or data textures where the vertex stage has no
//! storage buffers (GLES 3.0 / WebGL2); the layouts both share and the storage tier's bind
//! group.

use trisort_format::Geometry;

use super::budget::{sized_buffer, GpuBytes, GpuKind, SceneBudget};
use super::materials::MaterialGpu;
use super::uniforms::{FrameData, FrameUniform, LightingUniform};

/// The material table on the GPU: a storage buffer, or the texture tier's data texture.
pub(crate) enum MaterialStore {
    /// Storage tier: binding 2 (and binding 1's node matrices).
    Buffer(wgpu::Buffer, wgpu::Buffer),
    /// Texture tier: the Rgba32Float texture of binding 2, [`DATA_WIDTH`] texels a row.
    Texture(wgpu::Texture),
}

/// How group 0 carries node matrices and materials (bindings 1, 2 and 5): the binding prelude
/// a shader is composed with ([`crate::compose_with`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Bindings {
    /// Storage buffers read in the vertex stage (`shaders/common/storage.wgsl`).
    #[default]
    Storage,
    /// Rgba32Float data textures read with `textureLoad`, and a per-frame uniform naming the
    /// frame's first node (`shaders/common/textures.wgsl`): GLES 3.0 / WebGL2, which have no storage
    /// buffers in the vertex stage.
    Textures,
}

impl Bindings {
    /// The tier a device's limits allow: [`Bindings::Storage`] where the vertex stage has the
    /// two storage buffers it needs, else [`Bindings::Textures`].
    pub fn for_limits(limits: &wgpu::Limits) -> Bindings {
        if limits.max_storage_buffers_per_shader_stage >= 2 {
            Bindings::Storage
        } else {
            Bindings::Textures
        }
    }

    /// A short name (`storage`, `textures`).
    pub fn name(self) -> &'static str {
        match self {
            Bindings::Storage => "storage",
            Bindings::Textures => "textures",
        }
    }

    /// Whether `frames` frames of `geometry` fit this tier on a device with `limits`: on
    /// [`Bindings::Textures`], the node matrices of every frame (4 texels a node) and the
    /// materials must fit in data textures [`DATA_WIDTH`] texels wide and at most
    /// `max_texture_dimension_2d` rows (2,048 on WebGL2's minimum). The error says what
    /// does not fit and by how much.
    pub fn check_fits(
        self,
        limits: &wgpu::Limits,
        geometry: &Geometry,
        frames: usize,
    ) -> Result<(), String> {
        if self == Bindings::Storage {
            return Ok(());
        }
        let max = limits.max_texture_dimension_2d as u64;
        if (DATA_WIDTH as u64) > max {
            return Err(format!(
                "the device's largest texture is {max} texels wide; the data textures need {DATA_WIDTH}"
            ));
        }
        let rows = |texels: u64| texels.div_ceil(DATA_WIDTH as u64).max(1);
        let nodes = geometry.nodes.len().max(1) as u64;
        let node_rows = rows(frames.max(1) as u64 * nodes * 4);
        if node_rows > max {
            return Err(format!(
                "{frames} frames of {nodes} node matrices need {node_rows} rows of node data and \
                 the device allows {max}: play a shorter path per file (record --frames), or \
                 fewer animated nodes"
            ));
        }
        let material_texels = (std::mem::size_of::<MaterialGpu>() as u64 / 16)
            * geometry.materials.len().max(1) as u64;
        if rows(material_texels) > max {
            return Err(format!(
                "{} materials need {} rows of material data and the device allows {max}",
                geometry.materials.len(),
                rows(material_texels)
            ));
        }
        Ok(())
    }
}

/// Texels per row of the data textures of [`Bindings::Textures`] (`DATA_WIDTH` in the WGSL).
pub use trisort_format::gpu_layout::DATA_WIDTH;

/// Creates the bind group layout of group 0 on the storage tier.
pub fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    bind_group_layout_for(device, Bindings::Storage)
}

/// Creates the bind group layout of group 0 for `bindings`.
pub fn bind_group_layout_for(device: &wgpu::Device, bindings: Bindings) -> wgpu::BindGroupLayout {
    let surface = surface_entries();
    let vf = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
    if bindings == Bindings::Textures {
        return crate::data_textures::texture_tier_layout(device);
    }
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("trisort scene"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: vf,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(
                        std::mem::size_of::<FrameUniform>() as u64
                    ),
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: vf,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: true,
                    min_binding_size: None,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: vf,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            surface[0],
            surface[1],
            surface[2],
            surface[3],
            surface[4],
            surface[5],
        ],
    })
}

/// A bind-group entry that binds the first `size` bytes of `buffer` (a dynamic offset moves
/// the window per frame).
pub(crate) fn sized_buffer_entry(
    binding: u32,
    buffer: &wgpu::Buffer,
    size: u64,
) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer,
            offset: 0,
            size: wgpu::BufferSize::new(size),
        }),
    }
}

/// Bindings 3, 4 and 6–9 of every tier's scene group, read by the fragment stage: the sRGB
/// texture array (3), the material sampler (4), the linear texture array (6), the `Lighting`
/// uniform (7), the prefiltered environment (8) and its sampler (9).
pub(crate) fn surface_entries() -> [wgpu::BindGroupLayoutEntry; 6] {
    let texture = |binding, view_dimension| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension,
            multisampled: false,
        },
        count: None,
    };
    let sampler = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    };
    [
        texture(3, wgpu::TextureViewDimension::D2Array),
        sampler(4),
        texture(6, wgpu::TextureViewDimension::D2Array),
        wgpu::BindGroupLayoutEntry {
            binding: 7,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: wgpu::BufferSize::new(
                    std::mem::size_of::<LightingUniform>() as u64
                ),
            },
            count: None,
        },
        texture(8, wgpu::TextureViewDimension::D2),
        sampler(9),
    ]
}

/// Bind group entries both tiers share: the frame uniform (0) and the surface bindings of
/// [`surface_entries`] (3, 4, 6–9).
pub(crate) struct SharedBindings<'a> {
    pub(crate) frame: wgpu::BindGroupEntry<'a>,
    pub(crate) surface: [wgpu::BindGroupEntry<'a>; 6],
}

/// The storage tier's layout and bind group, and its node-matrix stride per frame; the
/// buffers sized by `budget` and counted into `allocated`.
pub(super) fn storage_bind_group(
    device: &wgpu::Device,
    shared: SharedBindings<'_>,
    data: &FrameData,
    materials: &[MaterialGpu],
    budget: &SceneBudget,
    allocated: &mut GpuBytes,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup, u64, MaterialStore) {
    let materials = sized_buffer(
        device,
        "materials",
        budget.bytes.buffer(GpuKind::Materials),
        bytemuck::cast_slice(materials),
        // COPY_DST: material variants rewrite it (`SceneGpu::set_materials`).
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    );
    let node_buffer = sized_buffer(
        device,
        "node matrices",
        budget.bytes.buffer(GpuKind::NodeMatrices),
        &data.node_bytes,
        // COPY_DST: a free camera rewrites a frame's matrices (`SceneGpu::set_frame`).
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    );
    allocated.count_buffer(GpuKind::Materials, &materials);
    allocated.count_buffer(GpuKind::NodeMatrices, &node_buffer);
    let layout = bind_group_layout(device);
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("trisort scene"),
        layout: &layout,
        entries: &[
            [
                shared.frame,
                sized_buffer_entry(1, &node_buffer, data.node_count * 64),
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: materials.as_entire_binding(),
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
        data.node_stride,
        MaterialStore::Buffer(materials, node_buffer),
    )
}
