//! The GPU memory a scene takes, worked out before anything is created ([`scene_budget`]) and
//! counted as it is created ([`GpuBytes::count_buffer`], [`GpuBytes::count_texture`]).
//!
//! [`SceneGpu`](super::SceneGpu) sizes every buffer and texture from its [`SceneBudget`]: the
//! strides, the texture arrays' plan, the environment's levels and each buffer's size come from
//! here, so a report made from [`scene_budget`] without a device (`inspect BAKED`) gives the
//! bytes a player allocates on any device whose limits [`BudgetConfig`] describes. The
//! uploader also counts what it created, from the wgpu objects themselves
//! ([`SceneGpu::allocated`](super::SceneGpu::allocated)), so a test can hold the two together.

use std::collections::BTreeMap;

use trisort_format::gpu_layout::{
    environment_levels, node_count, plan_texture_arrays, TextureArray, TextureArrays, DATA_WIDTH,
};
use trisort_format::{BlockFormat, Environment, Geometry, Material, Vertex};

use super::bindings::Bindings;
use super::materials::MaterialGpu;
use super::uniforms::{FrameUniform, LightingUniform};

/// The dynamic-offset stride every device accepts: WebGPU's default (and largest allowed)
/// `min_uniform_buffer_offset_alignment` and `min_storage_buffer_offset_alignment`. Strides
/// are at least this on every device, so per-frame data takes the same bytes everywhere.
pub const PORTABLE_OFFSET_ALIGNMENT: u64 = 256;

/// WebGPU's default `max_texture_dimension_2d`: what [`BudgetConfig::portable`] assumes.
pub const PORTABLE_MAX_TEXTURE_DIMENSION: u32 = 8192;

/// What a GPU allocation holds, for the budget's per-kind figures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum GpuKind {
    /// The vertex buffer.
    Vertices,
    /// The sorted index buffer (the player's).
    Indices,
    /// The indirect draws of every frame (the player's).
    Indirect,
    /// The per-frame `Frame` uniforms, one stride a frame.
    FrameUniforms,
    /// The texture tier's per-frame uniform naming the frame's first node.
    FirstNodes,
    /// Camera-relative node matrices of every frame (a storage buffer, or the texture tier's
    /// data texture).
    NodeMatrices,
    /// The material table (a storage buffer, or the texture tier's data texture).
    Materials,
    /// The `Lighting` uniform.
    Lighting,
    /// Texture array layers holding base-colour textures, with their mips.
    BaseColour,
    /// Layers holding metallic-roughness textures (an occlusion map packed with them counts
    /// here).
    MetallicRoughness,
    /// Layers holding normal maps.
    Normal,
    /// Layers holding occlusion maps.
    Occlusion,
    /// Layers holding emissive textures.
    Emissive,
    /// Layers no material samples: an empty array's white texel, GL's spare layer, textures
    /// no material names, and the linear array's textures skipped by a visibility-only upload.
    UnusedLayers,
    /// The prefiltered environment (`Rgba16Float`, with its levels).
    Environment,
}

impl GpuKind {
    /// The name reports use (`vertices`, `base_colour`, ...).
    pub fn name(self) -> &'static str {
        match self {
            GpuKind::Vertices => "vertices",
            GpuKind::Indices => "indices",
            GpuKind::Indirect => "indirect",
            GpuKind::FrameUniforms => "frame_uniforms",
            GpuKind::FirstNodes => "first_nodes",
            GpuKind::NodeMatrices => "node_matrices",
            GpuKind::Materials => "materials",
            GpuKind::Lighting => "lighting",
            GpuKind::BaseColour => "base_colour",
            GpuKind::MetallicRoughness => "metallic_roughness",
            GpuKind::Normal => "normal",
            GpuKind::Occlusion => "occlusion",
            GpuKind::Emissive => "emissive",
            GpuKind::UnusedLayers => "unused_layers",
            GpuKind::Environment => "environment",
        }
    }
}

/// Bytes of GPU memory by kind, buffers and textures apart: a budget, or a count of what was
/// created.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GpuBytes {
    buffers: BTreeMap<GpuKind, u64>,
    textures: BTreeMap<GpuKind, u64>,
}

impl GpuBytes {
    /// Adds `bytes` of buffer memory holding `kind`.
    pub fn add_buffer(&mut self, kind: GpuKind, bytes: u64) {
        *self.buffers.entry(kind).or_default() += bytes;
    }

    /// Adds `bytes` of texture memory holding `kind`.
    pub fn add_texture(&mut self, kind: GpuKind, bytes: u64) {
        *self.textures.entry(kind).or_default() += bytes;
    }

    /// Counts a created buffer: its size as wgpu reports it.
    pub fn count_buffer(&mut self, kind: GpuKind, buffer: &wgpu::Buffer) {
        self.add_buffer(kind, buffer.size());
    }

    /// Counts a created texture: [`texture_allocation_bytes`].
    pub fn count_texture(&mut self, kind: GpuKind, texture: &wgpu::Texture) {
        self.add_texture(kind, texture_allocation_bytes(texture));
    }

    /// Counts a created texture array whose layer `l` holds `layer_kinds[l]` (layers past the
    /// list: [`GpuKind::UnusedLayers`]), each layer an equal share of
    /// [`texture_allocation_bytes`].
    pub fn count_texture_layers(&mut self, texture: &wgpu::Texture, layer_kinds: &[GpuKind]) {
        let layers = texture.depth_or_array_layers().max(1) as u64;
        let per_layer = texture_allocation_bytes(texture) / layers;
        for l in 0..layers as usize {
            let kind = layer_kinds.get(l).copied().unwrap_or(GpuKind::UnusedLayers);
            self.add_texture(kind, per_layer);
        }
    }

    /// Adds every figure of `other`.
    pub fn add(&mut self, other: &GpuBytes) {
        for (&k, &b) in &other.buffers {
            self.add_buffer(k, b);
        }
        for (&k, &b) in &other.textures {
            self.add_texture(k, b);
        }
    }

    /// Buffer bytes by kind, in [`GpuKind`] order (kinds with no buffer left out).
    pub fn buffer_kinds(&self) -> impl Iterator<Item = (GpuKind, u64)> + '_ {
        self.buffers.iter().map(|(&k, &b)| (k, b))
    }

    /// Texture bytes by kind, in [`GpuKind`] order (kinds with no texture left out).
    pub fn texture_kinds(&self) -> impl Iterator<Item = (GpuKind, u64)> + '_ {
        self.textures.iter().map(|(&k, &b)| (k, b))
    }

    /// All buffer bytes.
    pub fn buffers(&self) -> u64 {
        self.buffers.values().sum()
    }

    /// All texture bytes.
    pub fn textures(&self) -> u64 {
        self.textures.values().sum()
    }

    /// Buffers and textures.
    pub fn total(&self) -> u64 {
        self.buffers() + self.textures()
    }

    /// The bytes of buffers of `kind` (0 when none).
    pub fn buffer(&self, kind: GpuKind) -> u64 {
        self.buffers.get(&kind).copied().unwrap_or(0)
    }

    /// The bytes of textures of `kind` (0 when none).
    pub fn texture(&self, kind: GpuKind) -> u64 {
        self.textures.get(&kind).copied().unwrap_or(0)
    }
}

/// Bytes a created texture takes: every mip level of every layer at its format's block size
/// (read from the wgpu object, not from any plan).
pub fn texture_allocation_bytes(texture: &wgpu::Texture) -> u64 {
    let format = texture.format();
    let block = format.block_copy_size(None).unwrap_or(0) as u64;
    let (bw, bh) = format.block_dimensions();
    let (w, h) = (texture.width(), texture.height());
    let level_bytes: u64 = (0..texture.mip_level_count())
        .map(|k| {
            let (lw, lh) = ((w >> k).max(1), (h >> k).max(1));
            lw.div_ceil(bw) as u64 * lh.div_ceil(bh) as u64 * block
        })
        .sum();
    level_bytes * texture.depth_or_array_layers() as u64
}

/// The size of a buffer made to hold `len` bytes: rounded up to `wgpu::COPY_BUFFER_ALIGNMENT`,
/// one such unit at least ([`sized_buffer`] makes buffers of this size).
pub fn buffer_size(len: u64) -> u64 {
    len.div_ceil(wgpu::COPY_BUFFER_ALIGNMENT).max(1) * wgpu::COPY_BUFFER_ALIGNMENT
}

/// A buffer of `size` bytes (a size from a budget, [`buffer_size`] of its contents at least)
/// holding `contents` from its start, zeros after.
pub fn sized_buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    contents: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    assert!(
        contents.len() as u64 <= size && size.is_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT),
        "{label}: {} bytes do not fit the budgeted {size}",
        contents.len()
    );
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage,
        mapped_at_creation: true,
    });
    buffer
        .get_mapped_range_mut(..)
        .expect("a buffer mapped at creation")
        .slice(..contents.len())
        .copy_from_slice(contents);
    buffer.unmap();
    buffer
}

/// The device features that sample block-compressed textures: BC, ETC2 and ASTC (LDR).
pub const TEXTURE_COMPRESSION: wgpu::Features = wgpu::Features::TEXTURE_COMPRESSION_BC
    .union(wgpu::Features::TEXTURE_COMPRESSION_ETC2)
    .union(wgpu::Features::TEXTURE_COMPRESSION_ASTC);

/// The device feature that samples `format`.
pub fn compression_feature(format: BlockFormat) -> wgpu::Features {
    match format {
        BlockFormat::Bc7 => wgpu::Features::TEXTURE_COMPRESSION_BC,
        BlockFormat::Etc2Rgb8 | BlockFormat::Etc2Rgba8 => wgpu::Features::TEXTURE_COMPRESSION_ETC2,
        BlockFormat::Astc4x4 => wgpu::Features::TEXTURE_COMPRESSION_ASTC,
    }
}

/// How a material texture array is uploaded: in its members' block format, or as RGBA8
/// texels (decoded from the file's blocks where its members have them).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ArrayUpload {
    /// RGBA8 texels (`Rgba8UnormSrgb` or `Rgba8Unorm`): the file's, or, for members stored
    /// as blocks, those blocks decoded (as reading the file decodes them).
    Rgba8 {
        /// The block families (`bc7`, `etc2`, `astc`) of the members stored as blocks,
        /// sorted; empty where no member is.
        decoded_from: Vec<&'static str>,
    },
    /// Every member's blocks in this format ([`TextureArray::level_blocks`]).
    Blocks(BlockFormat),
}

impl ArrayUpload {
    /// How `array` of `geometry` is uploaded on a device with the compression features of
    /// `features`: in [`TextureArray::block_format`] where the device has its feature
    /// ([`compression_feature`]), else RGBA8.
    pub fn choose(geometry: &Geometry, array: &TextureArray, features: wgpu::Features) -> Self {
        match array.block_format(geometry) {
            Some(f) if features.contains(compression_feature(f)) => ArrayUpload::Blocks(f),
            _ => {
                let mut decoded_from: Vec<&'static str> = (array.members.iter())
                    .filter_map(|&i| geometry.textures.get(i)?.blocks.as_ref())
                    .map(|b| b.format.family())
                    .collect();
                decoded_from.sort_unstable();
                decoded_from.dedup();
                ArrayUpload::Rgba8 { decoded_from }
            }
        }
    }

    /// The texture format of the array: sRGB or `linear`, RGBA8 or the block format.
    pub fn texture_format(&self, linear: bool) -> wgpu::TextureFormat {
        use wgpu::{AstcBlock, AstcChannel, TextureFormat as F};
        let Self::Blocks(format) = self else {
            return if linear {
                F::Rgba8Unorm
            } else {
                F::Rgba8UnormSrgb
            };
        };
        match (format, linear) {
            (BlockFormat::Etc2Rgb8, true) => F::Etc2Rgb8Unorm,
            (BlockFormat::Etc2Rgb8, false) => F::Etc2Rgb8UnormSrgb,
            (BlockFormat::Etc2Rgba8, true) => F::Etc2Rgba8Unorm,
            (BlockFormat::Etc2Rgba8, false) => F::Etc2Rgba8UnormSrgb,
            (BlockFormat::Astc4x4, _) => F::Astc {
                block: AstcBlock::B4x4,
                channel: if linear {
                    AstcChannel::Unorm
                } else {
                    AstcChannel::UnormSrgb
                },
            },
            (BlockFormat::Bc7, true) => F::Bc7RgbaUnorm,
            (BlockFormat::Bc7, false) => F::Bc7RgbaUnormSrgb,
        }
    }

    /// Bytes of a `w` × `h` level: whole blocks, or 4 a texel.
    pub fn level_bytes(&self, w: u32, h: u32) -> u64 {
        match self {
            Self::Blocks(format) => format.level_bytes(w, h) as u64,
            Self::Rgba8 { .. } => w as u64 * h as u64 * 4,
        }
    }

    /// What reports print (`play --json`'s `texture_upload`): the block format (`bc7`,
    /// `etc2-rgb8`, `etc2-rgba8`, `astc-4x4`), `rgba8`, or `rgba8 (decoded from etc2)` where
    /// members stored as blocks were decoded.
    pub fn name(&self) -> String {
        match self {
            Self::Blocks(format) => format.to_string(),
            Self::Rgba8 { decoded_from } if decoded_from.is_empty() => "rgba8".to_string(),
            Self::Rgba8 { decoded_from } => {
                format!("rgba8 (decoded from {})", decoded_from.join(", "))
            }
        }
    }
}

/// What decides a scene's GPU sizes besides the file: the binding tier and the device's limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BudgetConfig {
    /// The binding tier.
    pub bindings: Bindings,
    /// The device's `max_texture_dimension_2d` (texture arrays and the environment are clamped
    /// to it).
    pub max_texture_dimension: u32,
    /// Stride alignment of per-frame uniforms: the device's
    /// `min_uniform_buffer_offset_alignment`, [`PORTABLE_OFFSET_ALIGNMENT`] at least.
    pub uniform_alignment: u64,
    /// Stride alignment of per-frame node matrices on the storage tier: the device's
    /// `min_storage_buffer_offset_alignment`, [`PORTABLE_OFFSET_ALIGNMENT`] at least.
    pub storage_alignment: u64,
    /// Layers a texture array has at least: 2 on wgpu's GL backend (one layer would make it a
    /// plain 2D texture there), else 1.
    pub min_array_layers: u32,
    /// A visibility-only upload ([`SceneGpu::for_visibility`](super::SceneGpu::for_visibility)).
    pub visibility_only: bool,
    /// The texture-compression features ([`TEXTURE_COMPRESSION`]) the device has and the
    /// upload may use: an array whose members are all stored as blocks the device samples is
    /// uploaded as those blocks ([`ArrayUpload::choose`]). Empty: every texture as RGBA8,
    /// block-compressed ones decoded (`play --decode-textures`).
    pub texture_compression: wgpu::Features,
}

impl BudgetConfig {
    /// A device with WebGPU's default limits ([`PORTABLE_MAX_TEXTURE_DIMENSION`],
    /// [`PORTABLE_OFFSET_ALIGNMENT`]), not on GL, that samples every block format
    /// ([`TEXTURE_COMPRESSION`]): what `inspect` reports. Any device whose largest texture is
    /// at least every texture of the file, that is not GL and that has the compression
    /// feature of the file's blocks, allocates exactly this (without the feature:
    /// [`BudgetConfig::decoded`]).
    pub fn portable(bindings: Bindings) -> BudgetConfig {
        BudgetConfig {
            bindings,
            max_texture_dimension: PORTABLE_MAX_TEXTURE_DIMENSION,
            uniform_alignment: PORTABLE_OFFSET_ALIGNMENT,
            storage_alignment: PORTABLE_OFFSET_ALIGNMENT,
            min_array_layers: 1,
            visibility_only: false,
            texture_compression: TEXTURE_COMPRESSION,
        }
    }

    /// This configuration with every block-compressed texture uploaded decoded, as RGBA8 (a
    /// device without the compression features, or `play --decode-textures`).
    pub fn decoded(self) -> BudgetConfig {
        BudgetConfig {
            texture_compression: wgpu::Features::empty(),
            ..self
        }
    }

    /// The figures of `device` (its limits, backend and texture-compression features) on
    /// tier `bindings`.
    pub fn for_device(device: &wgpu::Device, bindings: Bindings) -> BudgetConfig {
        let limits = device.limits();
        let gl = device.adapter_info().backend == wgpu::Backend::Gl;
        BudgetConfig {
            bindings,
            max_texture_dimension: limits.max_texture_dimension_2d,
            uniform_alignment: PORTABLE_OFFSET_ALIGNMENT
                .max(limits.min_uniform_buffer_offset_alignment as u64),
            storage_alignment: PORTABLE_OFFSET_ALIGNMENT
                .max(limits.min_storage_buffer_offset_alignment as u64),
            min_array_layers: if gl { 2 } else { 1 },
            visibility_only: false,
            texture_compression: device.features() & TEXTURE_COMPRESSION,
        }
    }
}

/// A scene's GPU layout and sizes, before anything is created: what
/// [`SceneGpu`](super::SceneGpu) creates, and what a report says it will.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneBudget {
    /// The configuration it was worked out for.
    pub config: BudgetConfig,
    /// Bytes between frames' `Frame` uniforms (and the texture tier's first-node uniforms).
    pub frame_stride: u64,
    /// Bytes between frames' node matrices.
    pub node_stride: u64,
    /// The two material texture arrays.
    pub arrays: TextureArrays,
    /// Layers of the sRGB and the linear array as created ([`BudgetConfig::min_array_layers`]
    /// at least).
    pub layers: [u32; 2],
    /// What each layer of the sRGB and the linear array holds ([`layer_kinds`]; layers past
    /// the list: [`GpuKind::UnusedLayers`]).
    pub layer_kinds: [Vec<GpuKind>; 2],
    /// How the sRGB and the linear array are uploaded ([`ArrayUpload::choose`] with
    /// [`BudgetConfig::texture_compression`]).
    pub uploads: [ArrayUpload; 2],
    /// Level sizes of the environment texture.
    pub environment_levels: Vec<(u32, u32)>,
    /// Bytes by kind of everything the scene creates.
    pub bytes: GpuBytes,
}

/// Rounds `x` up to a multiple of `a`.
fn align(x: u64, a: u64) -> u64 {
    x.div_ceil(a.max(1)) * a.max(1)
}

/// Bytes of a data texture of the texture tier holding `bytes` ([`DATA_WIDTH`] Rgba32Float
/// texels a row, one row at least).
fn data_texture_size(bytes: u64) -> u64 {
    let row = DATA_WIDTH as u64 * 16;
    bytes.div_ceil(row).max(1) * row
}

/// What each layer of `array` holds, as [`texture_kind`] names it.
pub fn layer_kinds(array: &TextureArray, materials: &[Material]) -> Vec<GpuKind> {
    (array.members.iter())
        .map(|&t| texture_kind(materials, t))
        .collect()
}

/// What texture `t` is used as: the first of base colour, metallic-roughness, normal,
/// occlusion, emissive that a material of `materials` samples it as, else
/// [`GpuKind::UnusedLayers`].
pub fn texture_kind(materials: &[Material], t: usize) -> GpuKind {
    let t = t as u32;
    let slot = |s: &Option<trisort_format::TextureSlot>| s.as_ref().is_some_and(|s| s.texture == t);
    if materials.iter().any(|m| m.base_color_texture == Some(t)) {
        GpuKind::BaseColour
    } else if materials
        .iter()
        .any(|m| slot(&m.metallic_roughness_texture))
    {
        GpuKind::MetallicRoughness
    } else if materials.iter().any(|m| slot(&m.normal_texture)) {
        GpuKind::Normal
    } else if materials.iter().any(|m| slot(&m.occlusion_texture)) {
        GpuKind::Occlusion
    } else if materials.iter().any(|m| slot(&m.emissive_texture)) {
        GpuKind::Emissive
    } else {
        GpuKind::UnusedLayers
    }
}

/// Bytes of an array of `array`'s size and levels with `layers` layers uploaded as `upload`
/// says, by layer kind (layers past `kinds`: [`GpuKind::UnusedLayers`]).
fn add_array(
    bytes: &mut GpuBytes,
    array: &TextureArray,
    upload: &ArrayUpload,
    layers: u32,
    kinds: &[GpuKind],
) {
    let per_layer: u64 = (0..array.levels)
        .map(|k| {
            let (w, h) = array.level_size(k);
            upload.level_bytes(w, h)
        })
        .sum();
    for l in 0..layers as usize {
        let kind = kinds.get(l).copied().unwrap_or(GpuKind::UnusedLayers);
        bytes.add_texture(kind, per_layer);
    }
}

/// The budget of a scene of `geometry` with `frames` frames lit by `environment`, on a device
/// `config` describes: everything [`SceneGpu`](super::SceneGpu) creates (the player adds its
/// index and indirect buffers). The materials that name textures are the geometry's and its
/// variants'.
pub fn scene_budget(
    geometry: &Geometry,
    frames: usize,
    environment: &Environment,
    config: BudgetConfig,
) -> SceneBudget {
    let nframes = frames.max(1) as u64;
    let frame_stride = align(
        std::mem::size_of::<FrameUniform>() as u64,
        config.uniform_alignment,
    );
    let node_count = node_count(geometry) as u64;
    let node_stride = match config.bindings {
        Bindings::Storage => align(node_count * 64, config.storage_alignment),
        // The texture tier packs every frame's matrices contiguously (64 bytes a node).
        Bindings::Textures => node_count * 64,
    };
    let vertex_size = std::mem::size_of::<Vertex>() as u64;
    let material_bytes =
        geometry.materials.len().max(1) as u64 * std::mem::size_of::<MaterialGpu>() as u64;
    let mut bytes = GpuBytes::default();
    bytes.add_buffer(
        GpuKind::Vertices,
        buffer_size(geometry.vertices.len().max(1) as u64 * vertex_size),
    );
    bytes.add_buffer(GpuKind::FrameUniforms, buffer_size(frame_stride * nframes));
    bytes.add_buffer(
        GpuKind::Lighting,
        buffer_size(std::mem::size_of::<LightingUniform>() as u64),
    );
    match config.bindings {
        Bindings::Storage => {
            bytes.add_buffer(GpuKind::NodeMatrices, buffer_size(node_stride * nframes));
            bytes.add_buffer(GpuKind::Materials, buffer_size(material_bytes));
        }
        Bindings::Textures => {
            bytes.add_buffer(GpuKind::FirstNodes, buffer_size(frame_stride * nframes));
            bytes.add_texture(
                GpuKind::NodeMatrices,
                data_texture_size(node_stride * nframes),
            );
            bytes.add_texture(GpuKind::Materials, data_texture_size(material_bytes));
        }
    }
    let arrays = plan_texture_arrays(
        geometry,
        config.max_texture_dimension,
        config.visibility_only,
    );
    let mut materials = geometry.materials.clone();
    for v in &geometry.variants {
        if let Ok(table) = geometry.variant_materials(Some(&v.name)) {
            materials.extend(table);
        }
    }
    let mut layers = [0; 2];
    let layer_kinds = [
        layer_kinds(&arrays.srgb, &materials),
        layer_kinds(&arrays.linear, &materials),
    ];
    let uploads = [&arrays.srgb, &arrays.linear]
        .map(|a| ArrayUpload::choose(geometry, a, config.texture_compression));
    for (k, array) in [&arrays.srgb, &arrays.linear].into_iter().enumerate() {
        layers[k] = array.layers().max(config.min_array_layers);
        add_array(&mut bytes, array, &uploads[k], layers[k], &layer_kinds[k]);
    }
    let environment_levels: Vec<(u32, u32)> =
        environment_levels(environment, config.max_texture_dimension)
            .iter()
            .map(|l| (l.width, l.height))
            .collect();
    let env_bytes = environment_levels
        .iter()
        .map(|&(w, h)| w as u64 * h as u64 * 8)
        .sum();
    bytes.add_texture(GpuKind::Environment, env_bytes);
    SceneBudget {
        config,
        frame_stride,
        node_stride,
        arrays,
        layers,
        layer_kinds,
        uploads,
        environment_levels,
        bytes,
    }
}
