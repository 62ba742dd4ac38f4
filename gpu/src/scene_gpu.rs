//! GPU resources of a scene shared by every pipeline: the vertex buffer, the materials, the
//! texture arrays (sRGB and linear, with mips), the environment light, and per-frame uniforms
//! and camera-relative node matrices bound by dynamic offset (group 0 of [`crate::COMMON`]).

use bytemuck::{Pod, Zeroable};
use trisort_format::{
    AlphaMode, Environment, FrameState, Geometry, Material, TextureTransform, Vertex,
};
pub use trisort_format::{Shading, ToneMap};
use wgpu::util::DeviceExt;

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

/// The `Frame` uniform of the shared WGSL.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniform {
    /// Projection matrix.
    pub proj: [[f32; 4]; 4],
    /// View-space light direction (xyz) and ambient (w) of [`Shading::Basic`].
    pub light: [f32; 4],
    /// Glass opacity, width, height, sample count.
    pub params: [f32; 4],
    /// Columns (xyz) of the view-to-world rotation: environment lookups are in world space.
    pub view_to_world: [[f32; 4]; 3],
}

/// The `MaterialGpu` struct of the shared WGSL.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MaterialGpu {
    base_color: [f32; 4],
    emissive: [f32; 4],
    params: [f32; 4],
    pbr: [f32; 4],
    coat: [f32; 4],
    /// Base colour, metallic-roughness, normal, occlusion, emissive: u row, v row, scale.
    slots: [[[f32; 4]; 3]; 5],
}

/// The `Lighting` uniform of the shared WGSL (binding 7).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightingUniform {
    /// Irradiance / π, spherical harmonics (rgb).
    pub sh: [[f32; 4]; 9],
    /// World direction towards the sun (xyz), 1 with a sun (w).
    pub sun_direction: [f32; 4],
    /// Sun radiance.
    pub sun_color: [f32; 4],
    /// Exposure, shading (0 basic, 1 pbr), tone map (0 neutral, 1 ACES), last mip level.
    pub params: [f32; 4],
}

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

/// How a scene is lit: the surface model, the tone map and the environment (a baked file's
/// [`trisort_format::Baked::environment`], so every player of it lights alike).
#[derive(Clone, Copy, Debug)]
pub struct Lighting<'a> {
    /// Surface model.
    pub shading: Shading,
    /// Tone map (for [`Shading::Pbr`]).
    pub tone_map: ToneMap,
    /// Environment and sun.
    pub environment: &'a Environment,
}

impl Default for Lighting<'static> {
    /// [`Shading::Pbr`], [`ToneMap::Neutral`], under a uniform environment of radiance 1 and no
    /// sun (`Environment::uniform(1.0)`, what a bake without another environment stores).
    fn default() -> Lighting<'static> {
        static UNIFORM: std::sync::LazyLock<Environment> =
            std::sync::LazyLock::new(|| Environment::uniform(1.0));
        Lighting {
            shading: Shading::Pbr,
            tone_map: ToneMap::Neutral,
            environment: &UNIFORM,
        }
    }
}

impl<'a> Lighting<'a> {
    /// [`Shading::Pbr`] with [`ToneMap::Neutral`] under `environment`.
    pub fn pbr(environment: &'a Environment) -> Lighting<'a> {
        Lighting {
            shading: Shading::Pbr,
            tone_map: ToneMap::Neutral,
            environment,
        }
    }
}

impl LightingUniform {
    /// The uniform for `lighting`, whose prefiltered radiance was uploaded with `levels` mip
    /// levels.
    pub fn new(lighting: &Lighting<'_>, levels: u32) -> LightingUniform {
        let env = lighting.environment;
        let mut sh = [[0.0; 4]; 9];
        for (d, s) in sh.iter_mut().zip(&env.sh) {
            *d = [s[0], s[1], s[2], 0.0];
        }
        let (sun_direction, sun_color) = match &env.sun {
            Some(sun) => {
                let d = glam::Vec3::from(sun.direction).normalize_or_zero();
                (
                    [d.x, d.y, d.z, if d == glam::Vec3::ZERO { 0.0 } else { 1.0 }],
                    [sun.color[0], sun.color[1], sun.color[2], 0.0],
                )
            }
            None => ([0.0; 4], [0.0; 4]),
        };
        LightingUniform {
            sh,
            sun_direction,
            sun_color,
            params: [
                env.exposure,
                match lighting.shading {
                    Shading::Basic => 0.0,
                    Shading::Pbr => 1.0,
                },
                match lighting.tone_map {
                    ToneMap::Neutral => 0.0,
                    ToneMap::Aces => 1.0,
                },
                levels.saturating_sub(1) as f32,
            ],
        }
    }
}

/// The view-space light of [`Shading::Basic`]: towards upper left behind the viewer; ambient
/// 0.35.
pub const LIGHT: [f32; 4] = [-0.3, 0.6, 0.75, 0.35];

/// How frames are drawn: image size, sample count and glass opacity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// MSAA samples.
    pub samples: u32,
    /// Opacity of transmissive glass.
    pub glass_opacity: f32,
}

/// Scene resources on the GPU.
pub struct SceneGpu {
    /// Vertex buffer.
    pub vertices: wgpu::Buffer,
    /// Number of vertices.
    pub vertex_count: u32,
    /// Bind group layout of group 0.
    pub layout: wgpu::BindGroupLayout,
    /// Bind group 0 (bind with [`SceneGpu::offsets`]).
    pub bind_group: wgpu::BindGroup,
    frame_stride: u64,
    node_stride: u64,
    frames: u32,
    /// The frame uniforms (binding 0), rewritten by [`SceneGpu::set_subpixel_offset`].
    frame_buffer: wgpu::Buffer,
    /// Per frame: the uniform as uploaded with no offset, and its projection in f64.
    uniforms: Vec<(FrameUniform, glam::DMat4)>,
    view: View,
    /// Where the material table lives (rewritten by [`SceneGpu::set_materials`]).
    material_store: MaterialStore,
    /// Per texture, where it lies in the arrays (for rewriting the material table).
    texture_places: Vec<TexturePlace>,
    /// Number of materials uploaded.
    material_count: usize,
    /// [`SceneGpu::texture_bytes`].
    texture_bytes: u64,
}

/// The material table on the GPU: a storage buffer, or the texture tier's data texture.
pub(crate) enum MaterialStore {
    /// Storage tier: binding 2.
    Buffer(wgpu::Buffer),
    /// Texture tier: the Rgba32Float texture of binding 2, [`DATA_WIDTH`] texels a row.
    Texture(wgpu::Texture),
}

fn align(x: u64, a: u64) -> u64 {
    x.div_ceil(a) * a
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
pub const DATA_WIDTH: u32 = 1024;

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

/// Group 1, bindings 0-2, of a peel pass (`peel.wgsl`'s `fs_peel`, `peeling.wgsl`'s
/// `fs_peeling`), read by the fragment stage: 0 the pass's 16-byte uniform at a dynamic
/// offset, 1 the previous pass's depth, 2 its ids (unsigned); both textures multisampled where
/// `samples > 1`. Both peelers build their peel layout from these.
pub fn previous_key_entries(samples: u32) -> [wgpu::BindGroupLayoutEntry; 3] {
    let texture = |binding, sample_type| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: samples > 1,
        },
        count: None,
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

impl SceneGpu {
    /// Uploads the geometry, materials, textures and the uniforms of every frame, on the
    /// storage tier ([`SceneGpu::with_bindings`] with [`Bindings::Storage`]), lit by
    /// [`Shading::Pbr`] under a uniform environment of radiance 1 (for tools that draw without
    /// the file's light; players light with [`SceneGpu::with_lighting`], and the recorder,
    /// which reads only visibility, uploads less with [`SceneGpu::for_visibility`]).
    ///
    /// Textures share two arrays (sRGB and linear, each texture in the array of its colour
    /// space, with its mips): each layer is as large as the array's largest texture, and a
    /// smaller texture fills the top-left corner of every level (its uv scaled to fit), so one
    /// bind group serves every material. Node matrices are computed in f64 and cast once.
    /// Every texture's mips are uploaded as the geometry stores them: the geometry must pass
    /// [`Geometry::check_structure`] (which requires each texture's full chain), else this
    /// may panic.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
    ) -> SceneGpu {
        SceneGpu::with_bindings(device, queue, geometry, frames, view, Bindings::Storage)
    }

    /// [`SceneGpu::new`] with node matrices and materials carried as `bindings` says; the
    /// layout and bind group match shaders composed with [`crate::compose_with`] for it.
    pub fn with_bindings(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
        bindings: Bindings,
    ) -> SceneGpu {
        let lighting = Lighting::default();
        SceneGpu::with_lighting(device, queue, geometry, frames, view, bindings, lighting)
    }

    /// [`SceneGpu::new`] for shaders that read only what decides visibility: `surface_base`'s
    /// alpha and `culled` (the recorder's peel and conservative passes), never a material's
    /// other maps nor the light. The linear texture array, which holds only the
    /// metallic-roughness, normal and occlusion maps such shaders skip, is one white texel
    /// unless some material's base-colour texture is linear (then it is uploaded as
    /// [`SceneGpu::new`] uploads it). The sRGB array, every texture's place (layer and uv
    /// scale), the material table, frames and the 1×1 uniform environment are those of
    /// [`SceneGpu::new`], so such shaders draw the same bytes with a smaller upload
    /// ([`SceneGpu::texture_bytes`]). A shader that shades through it reads that white texel
    /// for every linear map.
    pub fn for_visibility(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
    ) -> SceneGpu {
        SceneGpu::upload(
            device,
            queue,
            geometry,
            frames,
            view,
            Bindings::Storage,
            Lighting::default(),
            true,
        )
    }

    /// [`SceneGpu::with_bindings`] lit as `lighting` says (the player and the reference pass
    /// the baked file's environment, so both light alike).
    pub fn with_lighting(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
        bindings: Bindings,
        lighting: Lighting<'_>,
    ) -> SceneGpu {
        SceneGpu::upload(
            device, queue, geometry, frames, view, bindings, lighting, false,
        )
    }

    /// [`SceneGpu::with_lighting`], or with `visibility_only` [`SceneGpu::for_visibility`]'s
    /// smaller texture upload.
    #[allow(clippy::too_many_arguments)]
    fn upload(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
        bindings: Bindings,
        lighting: Lighting<'_>,
        visibility_only: bool,
    ) -> SceneGpu {
        let limits = device.limits();
        let vertex_bytes: &[u8] = if geometry.vertices.is_empty() {
            &[0u8; std::mem::size_of::<Vertex>()]
        } else {
            bytemuck::cast_slice(&geometry.vertices)
        };
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("vertices"),
            contents: vertex_bytes,
            usage: wgpu::BufferUsages::VERTEX,
        });
        let textures = upload_textures(device, queue, geometry, visibility_only);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("material textures"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let env = upload_environment(device, queue, lighting.environment);
        let environment_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("environment"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let lighting_uniform = LightingUniform::new(&lighting, env.levels);
        let lighting_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("lighting"),
            contents: bytemuck::bytes_of(&lighting_uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let materials = material_table(&geometry.materials, &textures.places);
        // The texture tier packs every frame's matrices contiguously (64 bytes a node).
        let node_align = match bindings {
            Bindings::Storage => limits.min_storage_buffer_offset_alignment as u64,
            Bindings::Textures => 64,
        };
        let data = frame_data(&limits, geometry, frames, view, node_align);
        let frame_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("frame uniforms"),
            contents: &data.frame_bytes,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let view_entry = |binding, view| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        };
        let sampler_entry = |binding, sampler| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::Sampler(sampler),
        };
        let shared = SharedBindings {
            frame: wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &frame_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<FrameUniform>() as u64),
                }),
            },
            surface: [
                view_entry(3, &textures.srgb),
                sampler_entry(4, &sampler),
                view_entry(6, &textures.linear),
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: lighting_buffer.as_entire_binding(),
                },
                view_entry(8, &env.view),
                sampler_entry(9, &environment_sampler),
            ],
        };
        let (layout, bind_group, node_stride, material_store) = match bindings {
            Bindings::Storage => storage_bind_group(device, shared, &data, &materials),
            Bindings::Textures => crate::data_textures::bind_group(
                device,
                queue,
                shared,
                &data,
                bytemuck::cast_slice(&materials),
                frames.len(),
            ),
        };
        SceneGpu {
            vertices,
            vertex_count: geometry.vertices.len() as u32,
            layout,
            bind_group,
            frame_stride: data.frame_stride,
            node_stride,
            frames: frames.len() as u32,
            uniforms: frames
                .iter()
                .map(|state| (frame_uniform(state, view), projection(state, view)))
                .collect(),
            frame_buffer,
            view,
            material_store,
            texture_places: textures.places,
            material_count: geometry.materials.len(),
            texture_bytes: textures.bytes + env.bytes,
        }
    }

    /// Bytes of GPU memory the scene's textures take: both material texture arrays with every
    /// mip level of every layer (unused corners included), and the prefiltered environment.
    pub fn texture_bytes(&self) -> u64 {
        self.texture_bytes
    }

    /// Rewrites the material table with `materials` in place of the uploaded ones (a material
    /// variant: slot k draws as `materials[k]`; textures are those uploaded, named by index).
    /// Takes effect for commands submitted after it. Panics unless `materials` has as many
    /// entries as the geometry uploaded.
    pub fn set_materials(&self, queue: &wgpu::Queue, materials: &[Material]) {
        assert_eq!(
            materials.len(),
            self.material_count,
            "a material table replaces one of the same length"
        );
        let table = material_table(materials, &self.texture_places);
        let bytes: &[u8] = bytemuck::cast_slice(&table);
        match &self.material_store {
            MaterialStore::Buffer(buffer) => queue.write_buffer(buffer, 0, bytes),
            MaterialStore::Texture(texture) => {
                crate::data_textures::write_data_texture(queue, texture, bytes)
            }
        }
    }

    /// Shifts every frame's projection by `offset` pixels (x right, y down) at this scene's
    /// view size, or back to the recorded projection with `[0.0, 0.0]`: the image moves by
    /// `offset`, as if the sample pattern moved by `-offset`. A test aid that stands for
    /// another rasterizer's vertex snapping (`play --subpixel-offset`), and the recorder's
    /// jittered patterns (`record --robust N`). Applied in f64 before the one cast, so the
    /// zero offset rasterizes exactly what [`SceneGpu::new`] uploads. Takes effect for
    /// commands submitted after it.
    pub fn set_subpixel_offset(&self, queue: &wgpu::Queue, offset: [f64; 2]) {
        self.set_subpixel_offset_of(queue, offset, 0..self.uniforms.len() as u32);
    }

    /// [`SceneGpu::set_subpixel_offset`] for the frames of `frames` only (the recorder's
    /// jittered patterns move one frame at a time: rewriting every frame's uniforms for each
    /// pattern of each frame grew with the square of the path's length).
    pub fn set_subpixel_offset_of(
        &self,
        queue: &wgpu::Queue,
        offset: [f64; 2],
        frames: std::ops::Range<u32>,
    ) {
        let frames = frames.start as usize..(frames.end as usize).min(self.uniforms.len());
        for (f, (u, proj)) in self
            .uniforms
            .iter()
            .enumerate()
            .skip(frames.start)
            .take(frames.len())
        {
            let mut u = *u;
            u.proj = (subpixel_shift(offset, self.view) * *proj)
                .as_mat4()
                .to_cols_array_2d();
            queue.write_buffer(
                &self.frame_buffer,
                f as u64 * self.frame_stride,
                bytemuck::bytes_of(&u),
            );
        }
    }

    /// Number of frames uploaded.
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// The dynamic offsets that bind frame `f`'s uniforms and node matrices.
    pub fn offsets(&self, f: u32) -> [u32; 2] {
        assert!(f < self.frames.max(1), "frame {f} out of range");
        [
            (f as u64 * self.frame_stride) as u32,
            (f as u64 * self.node_stride) as u32,
        ]
    }
}

/// A frame's projection in f64 at a view's aspect ratio.
fn projection(state: &FrameState, view: View) -> glam::DMat4 {
    let aspect = view.width as f64 / view.height as f64;
    state.camera.projection(aspect)
}

/// The clip-space translation that moves the image by `offset` pixels (x right, y down) at
/// `view`'s size: x_clip += 2·dx/width · w_clip, y_clip −= 2·dy/height · w_clip (NDC y points
/// up, pixel rows down).
pub fn subpixel_shift(offset: [f64; 2], view: View) -> glam::DMat4 {
    glam::DMat4::from_translation(glam::DVec3::new(
        2.0 * offset[0] / view.width.max(1) as f64,
        -2.0 * offset[1] / view.height.max(1) as f64,
        0.0,
    ))
}

/// The `Frame` uniform for one frame at a view.
pub fn frame_uniform(state: &FrameState, view: View) -> FrameUniform {
    let proj = projection(state, view).as_mat4();
    let rotation = glam::DMat3::from_mat4(state.camera.view_matrix());
    let to_world = if rotation.determinant().abs() > 1e-300 {
        rotation.inverse()
    } else {
        glam::DMat3::IDENTITY
    }
    .as_mat3();
    let column = |c: glam::Vec3| [c.x, c.y, c.z, 0.0];
    FrameUniform {
        proj: proj.to_cols_array_2d(),
        light: LIGHT,
        params: [
            view.glass_opacity,
            view.width as f32,
            view.height as f32,
            view.samples as f32,
        ],
        view_to_world: [
            column(to_world.x_axis),
            column(to_world.y_axis),
            column(to_world.z_axis),
        ],
    }
}

/// Where a texture lies on the GPU: its array (sRGB or linear), layer, and the uv scale of the
/// corner it fills at level 0.
///
/// One scale serves every level, which is exact at level 0 (and so for the alpha that decides
/// visibility, always sampled there) but only approximate at a coarser level `k` of a texture
/// `w` texels wide in a layer `tw` wide: the shader maps uv ∈ [0, 1) onto
/// `P = (w / tw)·(tw >> k)` texels of the layer's level, while the texture's own level repeats
/// there ([`tiled`]) every `max(1, w >> k)` texels. Both lie in `(w / 2^k − 1, w / 2^k]`, so
/// across one repeat the sampled point drifts from the texture's by less than one texel *of
/// level k* (growing linearly from uv 0), and steps back by as much where uv wraps
/// (likewise along v with the heights). Level k is chosen where a pixel spans about one of
/// its texels, so this misplaces already pixel-sized detail by under about a pixel, and never
/// reads anything but the texture (the repeat fills the whole layer). It is zero when `2^k` divides both `w` and
/// `tw`, and where the texture's level is one texel along an axis (constant along it): a
/// power-of-two texture in a power-of-two layer, and the array's largest texture (`w = tw`),
/// are exact at every level. Example: 300 texels in a 1024 layer are exact to level 2 and
/// drift by up to half a texel at level 3 (37.5 against a period of 37). Exact coarse levels
/// for the rest would need the shader to pick the level itself and scale per level (two
/// `textureSampleLevel` calls instead of one `textureSampleGrad`), or each level resampled
/// onto the stretched period at upload (a blur of its own); neither is worth it for this bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TexturePlace {
    linear: bool,
    layer: u32,
    scale: [f32; 2],
}

/// The two material texture arrays.
struct Textures {
    srgb: wgpu::TextureView,
    linear: wgpu::TextureView,
    /// Per texture of the geometry.
    places: Vec<TexturePlace>,
    /// Bytes both arrays take with every level.
    bytes: u64,
}

/// Number of mip levels of a full chain for a `w` × `h` level 0, level 0 included.
fn chain_levels(w: u32, h: u32) -> u32 {
    trisort_format::Texture::mip_count(w, h) as u32 + 1
}

/// Level `k` of `t` as its size and RGBA8 bytes: level 0, a level of its stored chain
/// ([`trisort_format::Texture::mips`], full as [`Geometry::check_structure`] requires), or for
/// a level beyond the chain (the array's largest texture has more levels) its last, 1×1
/// level again, which is what averaging a 1×1 level would give.
fn texture_level(t: &trisort_format::Texture, k: usize) -> ((u32, u32), &[u8]) {
    let k = k.min(t.mips.len());
    let size = trisort_format::Texture::level_size(t.width, t.height, k as u32);
    let bytes = if k == 0 { &t.rgba8 } else { &t.mips[k - 1] };
    (size, bytes)
}

/// A `w` × `h` RGBA8 level of `size` repeated over a layer level of `layer` texels from the
/// top-left corner (cropped where the texture is larger: texels beyond the device limit, a
/// documented limitation). Filtering across the right and bottom edges of the texture's corner
/// (linear filtering at level 0, and every coarser level's footprint) then reads the texels
/// its repeat would, not the unused rest of the layer.
fn tiled(level: &[u8], (w, h): (u32, u32), (lw, lh): (u32, u32)) -> Vec<u8> {
    let mut data = Vec::with_capacity((lw * lh * 4) as usize);
    for y in 0..lh {
        let row = &level[((y % h) * w * 4) as usize..][..(w * 4) as usize];
        let mut x = 0;
        while x < lw {
            let n = (lw - x).min(w);
            data.extend_from_slice(&row[..(n * 4) as usize]);
            x += n;
        }
    }
    data
}

/// Uploads the material textures into two arrays, sRGB (`Rgba8UnormSrgb`) and linear
/// (`Rgba8Unorm`), each texture in the array of its [`trisort_format::Texture::srgb`] flag. A
/// layer is as large as its array's largest texture (clamped to the device's limit), with a
/// full mip chain; a smaller texture fills the top-left corner of every level with its own
/// level of the same index, repeated over the rest of the level ([`tiled`]). An empty array gets one white texel; on GL an array has two layers
/// at least (see the comment inside). With `visibility_only` ([`SceneGpu::for_visibility`])
/// the linear array is left empty (its textures placed at its layer 0, the white texel) unless
/// a material's base-colour texture is linear.
fn upload_textures(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    geometry: &Geometry,
    visibility_only: bool,
) -> Textures {
    let mut places = vec![
        TexturePlace {
            linear: false,
            layer: 0,
            scale: [1.0, 1.0]
        };
        geometry.textures.len()
    ];
    let mut bytes = 0;
    let mut views = Vec::new();
    // What `surface_base` samples: base-colour textures, in the array of their colour space.
    let linear_base = geometry.materials.iter().any(|m| {
        m.base_color_texture
            .and_then(|t| geometry.textures.get(t as usize))
            .is_some_and(|t| !t.srgb)
    });
    for linear in [false, true] {
        let mut members: Vec<usize> = (0..geometry.textures.len())
            .filter(|&i| geometry.textures[i].srgb != linear)
            .collect();
        if linear && visibility_only && !linear_base {
            for &i in &members {
                places[i] = TexturePlace {
                    linear: true,
                    layer: 0,
                    scale: [1.0, 1.0],
                };
            }
            members.clear();
        }
        let (view, b) = upload_array(device, queue, geometry, &members, linear, &mut places);
        views.push(view);
        bytes += b;
    }
    let linear = views.pop().expect("two arrays");
    let srgb = views.pop().expect("two arrays");
    Textures {
        srgb,
        linear,
        places,
        bytes,
    }
}

/// One array of [`upload_textures`]: the textures `members` of `geometry`; fills their places
/// and returns the view and its bytes.
fn upload_array(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    geometry: &Geometry,
    members: &[usize],
    linear: bool,
    places: &mut [TexturePlace],
) -> (wgpu::TextureView, u64) {
    let limits = device.limits();
    let (tw, th) = members.iter().fold((1u32, 1u32), |(w, h), &i| {
        let t = &geometry.textures[i];
        (w.max(t.width), h.max(t.height))
    });
    let max_dim = limits.max_texture_dimension_2d;
    let (tw, th) = (tw.min(max_dim), th.min(max_dim));
    let levels = chain_levels(tw, th);
    // wgpu's GL backend picks the GL texture target when the texture is made, from its
    // layer count alone: one layer becomes TEXTURE_2D, which a `texture_2d_array` binding
    // (sampler2DArray) then samples as an incomplete texture, black. Two layers at least on
    // GL make it TEXTURE_2D_ARRAY; the spare layer is never addressed.
    let min_layers = if device.adapter_info().backend == wgpu::Backend::Gl {
        2
    } else {
        1
    };
    let layers = members.len().max(min_layers) as u32;
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(if linear {
            "linear textures"
        } else {
            "sRGB textures"
        }),
        size: wgpu::Extent3d {
            width: tw,
            height: th,
            depth_or_array_layers: layers,
        },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: if linear {
            wgpu::TextureFormat::Rgba8Unorm
        } else {
            wgpu::TextureFormat::Rgba8UnormSrgb
        },
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let write = |level: u32, layer: u32, w: u32, h: u32, data: &[u8]| {
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: level,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: layer,
                },
                aspect: wgpu::TextureAspect::All,
            },
            data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * 4),
                rows_per_image: Some(h),
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
    };
    for (layer, &i) in members.iter().enumerate() {
        let t = &geometry.textures[i];
        for k in 0..levels {
            let (size, level) = texture_level(t, k as usize);
            let (aw, ah) = ((tw >> k).max(1), (th >> k).max(1));
            let data = tiled(level, size, (aw, ah));
            write(k, layer as u32, aw, ah, &data);
        }
        places[i] = TexturePlace {
            linear,
            layer: layer as u32,
            scale: [
                t.width.min(tw) as f32 / tw as f32,
                t.height.min(th) as f32 / th as f32,
            ],
        };
    }
    if members.is_empty() {
        write(0, 0, 1, 1, &[255u8; 4]);
    }
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let bytes = (0..levels)
        .map(|k| ((tw >> k).max(1) as u64) * ((th >> k).max(1) as u64) * 4)
        .sum::<u64>()
        * layers as u64;
    (view, bytes)
}

/// The prefiltered environment on the GPU.
struct EnvironmentGpu {
    view: wgpu::TextureView,
    /// Mip levels uploaded.
    levels: u32,
    bytes: u64,
}

/// Uploads an environment's prefiltered radiance as an `Rgba16Float` texture with one mip
/// level per stored level (as many as a full chain of its size holds; levels larger than the
/// device allows are left out from the top).
fn upload_environment(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    env: &Environment,
) -> EnvironmentGpu {
    let max_dim = device.limits().max_texture_dimension_2d;
    let first = (0..env.levels.len())
        .find(|&k| {
            let (w, h) = env.level_size(k);
            w <= max_dim && h <= max_dim
        })
        .unwrap_or(env.levels.len());
    let white = [0x3c00u16; 4];
    let mut stored: Vec<(u32, u32, &[u16])> = (first..env.levels.len())
        .map(|k| {
            let (w, h) = env.level_size(k);
            (w, h, env.levels[k].as_slice())
        })
        .filter(|(w, h, l)| l.len() as u64 == *w as u64 * *h as u64 * 4)
        .collect();
    if stored.is_empty() {
        stored.push((1, 1, &white));
    }
    let (w0, h0) = (stored[0].0, stored[0].1);
    let levels = (stored.len() as u32).min(chain_levels(w0, h0));
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("environment"),
        size: wgpu::Extent3d {
            width: w0,
            height: h0,
            depth_or_array_layers: 1,
        },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba16Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let mut bytes = 0;
    for (k, &(sw, sh, texels)) in stored.iter().take(levels as usize).enumerate() {
        // A level's size is that of the chain (`max(1, w0 >> k)`): the file's sizes agree.
        let (w, h) = (sw.min((w0 >> k).max(1)), sh.min((h0 >> k).max(1)));
        let row = w as usize * 4;
        let mut data: Vec<u16> = Vec::with_capacity(row * h as usize);
        for y in 0..h as usize {
            data.extend_from_slice(&texels[y * sw as usize * 4..][..row]);
        }
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: k as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&data),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * 8),
                rows_per_image: Some(h),
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        bytes += w as u64 * h as u64 * 8;
    }
    EnvironmentGpu {
        view: texture.create_view(&Default::default()),
        levels,
        bytes,
    }
}

/// A texture slot as the shaders read it: transform rows with the layer (< 0: none) and the
/// texture coordinate set, and the layer's uv scale with its array (0 sRGB, 1 linear).
fn slot_gpu(
    texture: Option<u32>,
    tex_coord: u32,
    transform: &TextureTransform,
    places: &[TexturePlace],
) -> [[f32; 4]; 3] {
    let m = transform.matrix();
    let place = texture.and_then(|t| places.get(t as usize));
    let (layer, scale, array) = match place {
        Some(p) => (p.layer as f32, p.scale, if p.linear { 1.0 } else { 0.0 }),
        None => (-1.0, [1.0, 1.0], 0.0),
    };
    [
        [m[0][0], m[0][1], m[0][2], layer],
        [m[1][0], m[1][1], m[1][2], tex_coord.min(1) as f32],
        [scale[0], scale[1], array, 0.0],
    ]
}

/// The materials as the shaders read them (one zeroed material where the scene has none).
fn material_table(materials: &[Material], places: &[TexturePlace]) -> Vec<MaterialGpu> {
    let mut mats: Vec<MaterialGpu> = materials
        .iter()
        .map(|m| {
            let mode = match m.alpha_mode {
                AlphaMode::Opaque => 0.0,
                AlphaMode::Mask => 1.0,
                AlphaMode::Blend => 2.0,
            };
            let slot = |s: &Option<trisort_format::TextureSlot>| match s {
                Some(s) => slot_gpu(Some(s.texture), s.tex_coord, &s.transform, places),
                None => slot_gpu(None, 0, &TextureTransform::default(), places),
            };
            let base = slot_gpu(
                m.base_color_texture,
                m.base_color_tex_coord,
                &m.base_color_transform,
                places,
            );
            MaterialGpu {
                base_color: m.base_color,
                emissive: [m.emissive[0], m.emissive[1], m.emissive[2], m.transmission],
                params: [
                    mode,
                    m.alpha_cutoff,
                    if m.double_sided { 1.0 } else { 0.0 },
                    base[0][3],
                ],
                pbr: [
                    m.metallic,
                    m.roughness,
                    m.normal_scale,
                    m.occlusion_strength,
                ],
                coat: [m.clearcoat, m.clearcoat_roughness, 0.0, 0.0],
                slots: [
                    base,
                    slot(&m.metallic_roughness_texture),
                    slot(&m.normal_texture),
                    slot(&m.occlusion_texture),
                    slot(&m.emissive_texture),
                ],
            }
        })
        .collect();
    if mats.is_empty() {
        mats.push(MaterialGpu::zeroed());
    }
    mats
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

/// Bind group entries both tiers share: the frame uniform (0) and the surface bindings of
/// [`surface_entries`] (3, 4, 6–9).
pub(crate) struct SharedBindings<'a> {
    pub(crate) frame: wgpu::BindGroupEntry<'a>,
    pub(crate) surface: [wgpu::BindGroupEntry<'a>; 6],
}

/// The storage tier's layout and bind group, and its node-matrix stride per frame.
fn storage_bind_group(
    device: &wgpu::Device,
    shared: SharedBindings<'_>,
    data: &FrameData,
    materials: &[MaterialGpu],
) -> (wgpu::BindGroupLayout, wgpu::BindGroup, u64, MaterialStore) {
    let materials = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("materials"),
        contents: bytemuck::cast_slice(materials),
        // COPY_DST: material variants rewrite it (`SceneGpu::set_materials`).
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    });
    let node_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("node matrices"),
        contents: &data.node_bytes,
        usage: wgpu::BufferUsages::STORAGE,
    });
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
        MaterialStore::Buffer(materials),
    )
}

/// Computes [`FrameData`]: camera-relative node matrices in f64, cast once.
fn frame_data(
    limits: &wgpu::Limits,
    geometry: &Geometry,
    frames: &[FrameState],
    view: View,
    node_align: u64,
) -> FrameData {
    let frame_stride = align(
        std::mem::size_of::<FrameUniform>() as u64,
        limits.min_uniform_buffer_offset_alignment as u64,
    );
    let node_count = geometry.nodes.len().max(1) as u64;
    let node_stride = align(node_count * 64, node_align);
    let nframes = frames.len().max(1) as u64;
    let mut frame_bytes = vec![0u8; (frame_stride * nframes) as usize];
    let mut node_bytes = vec![0u8; (node_stride * nframes) as usize];
    for (f, state) in frames.iter().enumerate() {
        let u = frame_uniform(state, view);
        frame_bytes[f * frame_stride as usize..][..std::mem::size_of::<FrameUniform>()]
            .copy_from_slice(bytemuck::bytes_of(&u));
        let mats = trisort_format::camera::node_view_matrices(&geometry.nodes, state);
        let m: Vec<[f32; 16]> = mats.iter().map(|m| m.to_cols_array()).collect();
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

/// A render pipeline over the scene's vertex buffer with the state every trisort pipeline
/// shares: counter-clockwise front faces, no hardware culling (single-sided materials discard
/// back faces in the shader, so one pipeline serves all materials), and the given depth test,
/// MSAA count and colour target.
pub struct ScenePipeline<'a> {
    /// Label.
    pub label: &'a str,
    /// Bind group layouts (group 0 is [`SceneGpu::layout`]).
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
        self.build_with(device, &[])
    }

    /// Creates the pipeline with its surface function specialised to `shading`
    /// ([`shading_constants`]): for pipelines that shade, so they compile what the player's
    /// pipeline compiles.
    pub fn build_shaded(&self, device: &wgpu::Device, shading: Shading) -> wgpu::RenderPipeline {
        self.build_with(device, shading_constants(shading))
    }

    fn build_with(&self, device: &wgpu::Device, constants: &[(&str, f64)]) -> wgpu::RenderPipeline {
        let layouts: Vec<Option<&wgpu::BindGroupLayout>> =
            self.layouts.iter().map(|l| Some(*l)).collect();
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(self.label),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
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
            fragment: Some(wgpu::FragmentState {
                module: self.module,
                entry_point: Some(self.fragment),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    ..Default::default()
                },
                targets: &[Some(self.target.clone())],
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}
