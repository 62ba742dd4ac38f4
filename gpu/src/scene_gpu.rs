//! GPU resources of a scene shared by every pipeline: the vertex buffer, the materials, the
//! base-colour texture array, and per-frame uniforms and camera-relative node matrices bound by
//! dynamic offset (group 0 of [`crate::COMMON`]).

use bytemuck::{Pod, Zeroable};
use trisort_format::{AlphaMode, FrameState, Geometry, Material, Vertex};
use wgpu::util::DeviceExt;

/// Vertex buffer layout of [`Vertex`] (locations 0–4 of `VertexIn`).
pub const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 5] = wgpu::vertex_attr_array![
    0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Uint32, 4 => Uint32
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
    /// View-space light direction (xyz) and ambient (w).
    pub light: [f32; 4],
    /// Glass opacity, width, height, sample count.
    pub params: [f32; 4],
}

/// The `MaterialGpu` struct of the shared WGSL.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MaterialGpu {
    base_color: [f32; 4],
    emissive: [f32; 4],
    params: [f32; 4],
    uv_scale: [f32; 4],
}

/// The view-space light of every pipeline: towards upper left behind the viewer; ambient 0.35.
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
    /// Per texture, its uv scale in the array (for rewriting the material table).
    uv_scales: Vec<[f32; 2]>,
    /// Number of materials uploaded.
    material_count: usize,
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
    /// Storage buffers read in the vertex stage (`wgsl/storage.wgsl`).
    #[default]
    Storage,
    /// Rgba32Float data textures read with `textureLoad`, and a per-frame uniform naming the
    /// frame's first node (`wgsl/textures.wgsl`): GLES 3.0 / WebGL2, which have no storage
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
    let base_colour = base_colour_entries();
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
            base_colour[0],
            base_colour[1],
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

/// Bindings 3 and 4 of every tier's scene group: the base-colour texture array and its
/// filtering sampler, read by the fragment stage.
pub(crate) fn base_colour_entries() -> [wgpu::BindGroupLayoutEntry; 2] {
    [
        wgpu::BindGroupLayoutEntry {
            binding: 3,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false,
            },
            count: None,
        },
        wgpu::BindGroupLayoutEntry {
            binding: 4,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        },
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
        wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(16),
            },
            count: None,
        },
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
    /// storage tier ([`SceneGpu::with_bindings`] with [`Bindings::Storage`]).
    ///
    /// Textures share one array: each layer is as large as the largest texture, and a
    /// texture smaller than that fills the top-left corner (its uv scaled to fit), so one bind
    /// group serves every material. Node matrices are computed in f64 and cast once.
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
        let (texture_view, uv_scales) = upload_textures(device, queue, geometry);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("base colour"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let materials = material_table(&geometry.materials, &uv_scales);
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
        let shared = SharedBindings {
            frame: wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &frame_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<FrameUniform>() as u64),
                }),
            },
            texture: wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::TextureView(&texture_view),
            },
            sampler: wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::Sampler(&sampler),
            },
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
            uv_scales,
            material_count: geometry.materials.len(),
        }
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
        let table = material_table(materials, &self.uv_scales);
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
    FrameUniform {
        proj: proj.to_cols_array_2d(),
        light: LIGHT,
        params: [
            view.glass_opacity,
            view.width as f32,
            view.height as f32,
            view.samples as f32,
        ],
    }
}

/// Uploads the base-colour textures into one array (each layer as large as the largest
/// texture, clamped to the device's limit; smaller textures fill the top-left corner) and
/// returns its view and each texture's uv scale. A scene without textures gets one white
/// texel. On GL the array has two layers at least (see the comment inside).
fn upload_textures(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    geometry: &Geometry,
) -> (wgpu::TextureView, Vec<[f32; 2]>) {
    let limits = device.limits();
    let (tw, th) = geometry
        .textures
        .iter()
        .fold((1u32, 1u32), |(w, h), t| (w.max(t.width), h.max(t.height)));
    let max_dim = limits.max_texture_dimension_2d;
    let (tw, th) = (tw.min(max_dim), th.min(max_dim));
    // wgpu's GL backend picks the GL texture target when the texture is made, from its
    // layer count alone: one layer becomes TEXTURE_2D, which a `texture_2d_array` binding
    // (sampler2DArray) then samples as an incomplete texture, black. Two layers at least on
    // GL make it TEXTURE_2D_ARRAY; the spare layer is never addressed.
    let min_layers = if device.adapter_info().backend == wgpu::Backend::Gl {
        2
    } else {
        1
    };
    let layers = geometry.textures.len().max(min_layers) as u32;
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("base colour textures"),
        size: wgpu::Extent3d {
            width: tw,
            height: th,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let mut uv_scales = Vec::new();
    for (layer, t) in geometry.textures.iter().enumerate() {
        let (w, h) = (t.width.min(tw), t.height.min(th));
        // Rows beyond the device limit are cropped (documented limitation).
        let mut data = Vec::with_capacity((w * h * 4) as usize);
        for y in 0..h as usize {
            data.extend_from_slice(&t.rgba8[y * t.width as usize * 4..][..w as usize * 4]);
        }
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: layer as u32,
                },
                aspect: wgpu::TextureAspect::All,
            },
            &data,
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
        uv_scales.push([w as f32 / tw as f32, h as f32 / th as f32]);
    }
    if geometry.textures.is_empty() {
        queue.write_texture(
            texture.as_image_copy(),
            &[255u8; 4],
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4),
                rows_per_image: Some(1),
            },
            wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
    }
    let texture_view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    (texture_view, uv_scales)
}

/// The materials as the shaders read them (one zeroed material where the scene has none).
fn material_table(materials: &[Material], uv_scales: &[[f32; 2]]) -> Vec<MaterialGpu> {
    let mut mats: Vec<MaterialGpu> = materials
        .iter()
        .map(|m| {
            let mode = match m.alpha_mode {
                AlphaMode::Opaque => 0.0,
                AlphaMode::Mask => 1.0,
                AlphaMode::Blend => 2.0,
            };
            let (layer, scale) = match m.base_color_texture {
                Some(t) if (t as usize) < uv_scales.len() => (t as f32, uv_scales[t as usize]),
                _ => (-1.0, [1.0, 1.0]),
            };
            MaterialGpu {
                base_color: m.base_color,
                emissive: [m.emissive[0], m.emissive[1], m.emissive[2], m.transmission],
                params: [
                    mode,
                    m.alpha_cutoff,
                    if m.double_sided { 1.0 } else { 0.0 },
                    layer,
                ],
                uv_scale: [scale[0], scale[1], 0.0, 0.0],
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

/// Bind group entries both tiers share: the frame uniform (0), the base-colour texture array
/// (3) and its sampler (4).
pub(crate) struct SharedBindings<'a> {
    pub(crate) frame: wgpu::BindGroupEntry<'a>,
    pub(crate) texture: wgpu::BindGroupEntry<'a>,
    pub(crate) sampler: wgpu::BindGroupEntry<'a>,
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
            shared.frame,
            sized_buffer_entry(1, &node_buffer, data.node_count * 64),
            wgpu::BindGroupEntry {
                binding: 2,
                resource: materials.as_entire_binding(),
            },
            shared.texture,
            shared.sampler,
        ],
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
    /// Creates the pipeline.
    pub fn build(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
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
                compilation_options: Default::default(),
                targets: &[Some(self.target.clone())],
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}
