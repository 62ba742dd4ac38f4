//! GPU resources of a scene shared by every pipeline: the vertex buffer, the materials, the
//! texture arrays (sRGB and linear, with mips), the environment light, and per-frame uniforms
//! and camera-relative node matrices bound by dynamic offset (group 0 of [`crate::COMMON`]).
//!
//! [`SceneGpu`] owns them; its parts live in submodules and are re-exported here:
//! the uniforms the shaders read (`uniforms`, `materials`), how group 0 carries them on each
//! binding tier (`bindings`), the texture arrays and the environment (`textures`,
//! `environment`), the peel passes' shared layout (`peel`) and the render pipeline builder
//! over the scene's vertex buffer (`pipeline`).

mod bindings;
pub mod budget;
mod environment;
mod materials;
mod peel;
mod pipeline;
mod textures;
mod uniforms;

pub use bindings::{bind_group_layout, bind_group_layout_for, Bindings, DATA_WIDTH};
pub(crate) use bindings::{sized_buffer_entry, surface_entries, MaterialStore, SharedBindings};
pub use budget::{scene_budget, ArrayUpload, BudgetConfig, GpuBytes, GpuKind, SceneBudget};
pub use materials::MaterialGpu;
pub use peel::{begin_peel_pass, previous_key_entries};
pub use pipeline::{vertex_layout, ScenePipeline, VERTEX_ATTRIBUTES};
pub use trisort_format::{Shading, ToneMap};
pub(crate) use uniforms::FrameData;
pub use uniforms::{
    frame_uniform, shading_constants, subpixel_shift, FrameUniform, Lighting, LightingUniform,
    LIGHT,
};

use bindings::storage_bind_group;
use budget::sized_buffer;
use environment::upload_environment;
use materials::material_table;
use textures::{upload_textures, TexturePlace};
use trisort_format::{FrameState, Geometry, Material};
use uniforms::{frame_data, projection};

pub use trisort_format::gpu_layout::View;

/// What [`SceneGpu::upload`] puts on the GPU, and how: the scene and its frames at a view, the
/// binding tier and the light.
struct Upload<'a> {
    geometry: &'a Geometry,
    frames: &'a [FrameState],
    view: View,
    bindings: Bindings,
    lighting: Lighting<'a>,
    /// Only what decides visibility is read ([`SceneGpu::for_visibility`]): the linear texture
    /// array can stay one white texel.
    visibility_only: bool,
    /// [`SceneOptions::decode_textures`].
    decode_textures: bool,
}

/// How [`SceneGpu::with_options`] uploads a scene besides its geometry, frames and view.
#[derive(Clone, Copy, Debug)]
pub struct SceneOptions<'a> {
    /// How node matrices and materials are bound.
    pub bindings: Bindings,
    /// The light.
    pub lighting: Lighting<'a>,
    /// Upload block-compressed textures decoded, as RGBA8, even where the device samples
    /// their blocks (`play --decode-textures`): what a device without the compression
    /// feature draws, for comparison.
    pub decode_textures: bool,
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
    /// [`SceneGpu::budget`].
    budget: SceneBudget,
    /// [`SceneGpu::allocated`].
    allocated: GpuBytes,
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
    /// may panic. Every buffer and texture is sized by [`scene_budget`] for the device and
    /// tier ([`SceneGpu::budget`]), and counted as it is created ([`SceneGpu::allocated`]).
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
        let upload = Upload {
            geometry,
            frames,
            view,
            bindings: Bindings::Storage,
            lighting: Lighting::default(),
            visibility_only: true,
            decode_textures: false,
        };
        SceneGpu::upload(device, queue, upload)
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
        let options = SceneOptions {
            bindings,
            lighting,
            decode_textures: false,
        };
        SceneGpu::with_options(device, queue, geometry, frames, view, options)
    }

    /// [`SceneGpu::with_lighting`] with every option of `options`. Each material texture array
    /// is uploaded in its members' block format where every member is stored as blocks of one
    /// family and the device has that format's compression feature, unless
    /// [`SceneOptions::decode_textures`]; else as RGBA8 texels, decoded from the blocks
    /// ([`SceneBudget::uploads`] says which). The two sample alike: a conforming device decodes
    /// ETC2 and BC7 blocks to the texels the file's decoder gives.
    pub fn with_options(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
        options: SceneOptions<'_>,
    ) -> SceneGpu {
        let upload = Upload {
            geometry,
            frames,
            view,
            bindings: options.bindings,
            lighting: options.lighting,
            visibility_only: false,
            decode_textures: options.decode_textures,
        };
        SceneGpu::upload(device, queue, upload)
    }

    /// [`SceneGpu::with_lighting`], or with [`Upload::visibility_only`]
    /// [`SceneGpu::for_visibility`]'s smaller texture upload.
    fn upload(device: &wgpu::Device, queue: &wgpu::Queue, upload: Upload<'_>) -> SceneGpu {
        let Upload {
            geometry,
            frames,
            view,
            bindings,
            lighting,
            visibility_only,
            decode_textures,
        } = upload;
        let mut config = BudgetConfig::for_device(device, bindings);
        config.visibility_only = visibility_only;
        if decode_textures {
            config = config.decoded();
        }
        let budget = scene_budget(geometry, frames.len(), lighting.environment, config);
        let mut allocated = GpuBytes::default();
        let vertex_bytes: &[u8] = bytemuck::cast_slice(&geometry.vertices);
        let vertices = sized_buffer(
            device,
            "vertices",
            budget.bytes.buffer(GpuKind::Vertices),
            vertex_bytes,
            wgpu::BufferUsages::VERTEX,
        );
        allocated.count_buffer(GpuKind::Vertices, &vertices);
        let textures = upload_textures(device, queue, geometry, &budget, &mut allocated);
        let sampler =
            trilinear_sampler(device, "material textures", wgpu::AddressMode::ClampToEdge);
        let env = upload_environment(device, queue, lighting.environment, &budget, &mut allocated);
        // The environment wraps around in longitude (u) and stops at the poles (v).
        let environment_sampler =
            trilinear_sampler(device, "environment", wgpu::AddressMode::Repeat);
        let lighting_uniform = LightingUniform::new(&lighting, env.levels);
        let lighting_buffer = sized_buffer(
            device,
            "lighting",
            budget.bytes.buffer(GpuKind::Lighting),
            bytemuck::bytes_of(&lighting_uniform),
            wgpu::BufferUsages::UNIFORM,
        );
        allocated.count_buffer(GpuKind::Lighting, &lighting_buffer);
        let materials = material_table(&geometry.materials, &textures.places);
        let data = frame_data(geometry, frames, view, &budget);
        let frame_buffer = sized_buffer(
            device,
            "frame uniforms",
            budget.bytes.buffer(GpuKind::FrameUniforms),
            &data.frame_bytes,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        allocated.count_buffer(GpuKind::FrameUniforms, &frame_buffer);
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
            Bindings::Storage => {
                storage_bind_group(device, shared, &data, &materials, &budget, &mut allocated)
            }
            Bindings::Textures => crate::data_textures::bind_group(
                device,
                queue,
                shared,
                crate::data_textures::TierData {
                    data: &data,
                    material_bytes: bytemuck::cast_slice(&materials),
                    frames: frames.len(),
                    budget: &budget,
                    allocated: &mut allocated,
                },
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
            budget,
            allocated,
        }
    }

    /// The budget the scene was created from ([`scene_budget`] for this device and tier): its
    /// strides, texture arrays and bytes by kind.
    pub fn budget(&self) -> &SceneBudget {
        &self.budget
    }

    /// Bytes of every buffer and texture the scene created, by kind, counted from the wgpu
    /// objects as they were created (buffer sizes, texture extents × levels × format): equal
    /// to [`SceneGpu::budget`]'s bytes unless the two disagree.
    pub fn allocated(&self) -> &GpuBytes {
        &self.allocated
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
            MaterialStore::Buffer(buffer, _) => queue.write_buffer(buffer, 0, bytes),
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
    /// pattern of each frame would cost time quadratic in the path's length).
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

    /// Replaces frame `f`'s camera and node poses with `state` (uniforms and camera-relative
    /// node matrices of `geometry`, the scene uploaded): a free camera draws through one frame
    /// slot. Storage tier only; `false` (nothing written) on the data-texture tier or for a
    /// frame beyond those uploaded. Takes effect for commands submitted after it.
    pub fn set_frame(
        &mut self,
        queue: &wgpu::Queue,
        geometry: &Geometry,
        f: u32,
        state: &FrameState,
    ) -> bool {
        let MaterialStore::Buffer(_, nodes) = &self.material_store else {
            return false;
        };
        let Some(slot) = self.uniforms.get_mut(f as usize) else {
            return false;
        };
        *slot = (
            frame_uniform(state, self.view),
            projection(state, self.view),
        );
        queue.write_buffer(
            &self.frame_buffer,
            f as u64 * self.frame_stride,
            bytemuck::bytes_of(&slot.0),
        );
        let m = trisort_format::gpu_layout::node_matrices(geometry, state);
        queue.write_buffer(nodes, f as u64 * self.node_stride, bytemuck::cast_slice(&m));
        true
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

/// A trilinear sampler that clamps v to the edge and addresses u with `address_mode_u`.
fn trilinear_sampler(
    device: &wgpu::Device,
    label: &str,
    address_mode_u: wgpu::AddressMode,
) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some(label),
        address_mode_u,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}
