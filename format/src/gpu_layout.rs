//! What a player uploads to the GPU, byte for byte, with no GPU API: the `Frame` and `Lighting`
//! uniforms, the material table (`MaterialGpu`), the camera-relative node matrices, the two
//! material texture arrays (sRGB and linear, with their mips) and the prefiltered environment,
//! as `shaders/common/common.wgsl` reads them.
//!
//! trisort's GPU crate uploads exactly these bytes, and the C API copies them out for hosts
//! that draw with the player's exported shaders (`trisort export-shaders`), so a host's frames
//! can equal the player's. Nothing here depends on a device except the largest texture size
//! (`max_dim`), which the caller passes.

use bytemuck::{Pod, Zeroable};

use crate::blocks::{BlockFormat, OPAQUE_EAC_BLOCK};
use crate::{
    AlphaMode, Environment, FrameState, Geometry, Material, Shading, Texture, TextureSlot,
    TextureTransform, ToneMap,
};

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

/// The `Frame` uniform of the shared WGSL (144 bytes, std140 and WGSL uniform layout alike).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniform {
    /// Projection matrix (clip depth 0 to 1).
    pub proj: [[f32; 4]; 4],
    /// View-space light direction (xyz) and ambient (w) of [`Shading::Basic`].
    pub light: [f32; 4],
    /// Glass opacity, width, height, sample count.
    pub params: [f32; 4],
    /// Columns (xyz) of the view-to-world rotation: environment lookups are in world space.
    pub view_to_world: [[f32; 4]; 3],
}

impl FrameUniform {
    /// The uniform's bytes, as uploaded.
    pub fn bytes(&self) -> &[u8] {
        bytemuck::bytes_of(self)
    }
}

/// The `Lighting` uniform of the shared WGSL (binding 7; 192 bytes).
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

/// How a scene is lit: the surface model, the tone map and the environment (a baked file's
/// [`crate::Baked::environment`], so every player of it lights alike).
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
    /// The uniform's bytes, as uploaded.
    pub fn bytes(&self) -> &[u8] {
        bytemuck::bytes_of(self)
    }

    /// The uniform for `lighting`, whose prefiltered radiance was uploaded with `levels` mip
    /// levels ([`environment_levels`]).
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

/// A frame's projection in f64 at a view's aspect ratio.
pub fn projection(state: &FrameState, view: View) -> glam::DMat4 {
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

/// Node matrices a frame uploads: the geometry's node count, at least one (a geometry without
/// nodes gets one zero matrix).
pub fn node_count(geometry: &Geometry) -> usize {
    geometry.nodes.len().max(1)
}

/// Frame `state`'s camera-relative node matrices (view × world, in f64, cast once), columns
/// first, [`node_count`] of them (zeros past the geometry's nodes).
pub fn node_matrices(geometry: &Geometry, state: &FrameState) -> Vec<[f32; 16]> {
    let mut m: Vec<[f32; 16]> = crate::camera::node_view_matrices(&geometry.nodes, state)
        .iter()
        .map(|m| m.to_cols_array())
        .collect();
    m.resize(node_count(geometry), [0.0; 16]);
    m
}

/// Texels per row of the data textures of the GLES 3.0 / WebGL2 tier (`DATA_WIDTH` in
/// `shaders/common/textures.wgsl`).
pub const DATA_WIDTH: u32 = 1024;

/// Rgba32Float texels a material takes in the material data texture (`MATERIAL_TEXELS`).
pub const MATERIAL_TEXELS: u32 = 20;

/// `bytes` (a whole number of 16-byte texels) padded with zeros to whole rows of
/// [`DATA_WIDTH`] texels (one row at least): a data texture's contents, and its row count.
pub fn data_texture_bytes(bytes: &[u8]) -> (Vec<u8>, u32) {
    let row = DATA_WIDTH as usize * 16;
    let rows = bytes.len().div_ceil(row).max(1);
    let mut padded = bytes.to_vec();
    padded.resize(rows * row, 0);
    (padded, rows as u32)
}

/// `texels` (RGBA32F, 4 floats each) padded with zeros to whole rows of [`DATA_WIDTH`] texels
/// (one row at least), as floats.
fn padded_texels(texels: &[f32]) -> Vec<f32> {
    let row = DATA_WIDTH as usize * 4;
    let rows = texels.len().div_ceil(row).max(1);
    let mut out = texels.to_vec();
    out.resize(rows * row, 0.0);
    out
}

/// The node data texture's contents ([`all_node_matrices`], padded to whole rows), as floats.
pub fn node_texels(geometry: &Geometry, frames: &[FrameState]) -> Vec<f32> {
    padded_texels(bytemuck::cast_slice(&all_node_matrices(geometry, frames)))
}

/// The material data texture's contents (`table`, padded to whole rows), as floats.
pub fn material_texels(table: &[MaterialGpu]) -> Vec<f32> {
    padded_texels(bytemuck::cast_slice(table))
}

/// The node data texture's texels before padding: every frame's [`node_matrices`] in frame
/// order, [`node_count`] × 4 texels a frame (frame `f` starts at node `f × node_count`, the
/// `node_base.x` of its uniform).
pub fn all_node_matrices(geometry: &Geometry, frames: &[FrameState]) -> Vec<[f32; 16]> {
    frames
        .iter()
        .flat_map(|state| node_matrices(geometry, state))
        .collect()
}

/// The `MaterialGpu` struct of the shared WGSL (320 bytes: 20 vec4).
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

/// Where a texture lies on the GPU: its array (sRGB or linear), layer, and the uv scale of the
/// corner it fills at level 0 (see [`plan_texture_arrays`] for the approximation this makes
/// at coarser levels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexturePlace {
    /// In the linear array (else the sRGB one).
    pub linear: bool,
    /// Layer in its array.
    pub layer: u32,
    /// The uv scale of the layer's corner the texture fills.
    pub scale: [f32; 2],
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

/// The materials as the shaders read them, textures placed by `places`
/// ([`TextureArrays::places`]); one zeroed material where the scene has none.
pub fn material_table(materials: &[Material], places: &[TexturePlace]) -> Vec<MaterialGpu> {
    let mut mats: Vec<MaterialGpu> = materials
        .iter()
        .map(|m| {
            let mode = match m.alpha_mode {
                AlphaMode::Opaque => 0.0,
                AlphaMode::Mask => 1.0,
                AlphaMode::Blend => 2.0,
            };
            let slot = |s: &Option<TextureSlot>| match s {
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

/// Number of mip levels of a full chain for a `w` × `h` level 0, level 0 included.
pub fn chain_levels(w: u32, h: u32) -> u32 {
    Texture::mip_count(w, h) as u32 + 1
}

/// One material texture array: its size, levels and which textures are its layers.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureArray {
    /// The linear array (`Rgba8Unorm`, or the unorm block format of
    /// [`TextureArray::block_format`]); else the sRGB one (`Rgba8UnormSrgb`, or the sRGB block
    /// format).
    pub linear: bool,
    /// Level 0 width of every layer: the largest member's, clamped to `max_dim`.
    pub width: u32,
    /// Level 0 height of every layer.
    pub height: u32,
    /// Mip levels (a full chain of `width` × `height`).
    pub levels: u32,
    /// The geometry's textures in layer order (empty: one white texel at layer 0).
    pub members: Vec<usize>,
}

impl TextureArray {
    /// Layers the array has: one per member, at least one.
    pub fn layers(&self) -> u32 {
        self.members.len().max(1) as u32
    }

    /// The size of level `level`.
    pub fn level_size(&self, level: u32) -> (u32, u32) {
        (
            self.width.checked_shr(level).unwrap_or(0).max(1),
            self.height.checked_shr(level).unwrap_or(0).max(1),
        )
    }

    /// Level `level` of layer `layer` as uploaded: RGBA8 rows top to bottom, the member's own
    /// level of the same index repeated from the top-left corner over the level ([`tiled`]);
    /// for an array without members, its one white texel (layer 0, level 0). `None` when the
    /// layer or level is out of range.
    pub fn level_bytes(&self, geometry: &Geometry, layer: u32, level: u32) -> Option<Vec<u8>> {
        if level >= self.levels || layer >= self.layers() {
            return None;
        }
        let Some(&i) = self.members.get(layer as usize) else {
            return Some(vec![255u8; 4]);
        };
        let t = geometry.textures.get(i)?;
        let (size, bytes) = texture_level(t, level as usize);
        Some(tiled(bytes, size, self.level_size(level)))
    }
}

impl TextureArray {
    /// The block format every layer can be uploaded in, with no decoding: where every member
    /// stores blocks ([`Texture::blocks`]) of one family and the array's level 0 is a whole
    /// number of blocks (a multiple of 4 texels each way). ETC2 RGB8 members with ETC2 RGBA8
    /// ones make an [`BlockFormat::Etc2Rgba8`] array (each RGB8 block after
    /// [`OPAQUE_EAC_BLOCK`]). `None` for an array without members, with a member stored as
    /// RGBA8 only, with members of two families, or smaller than a block (all members 2×2, say).
    pub fn block_format(&self, geometry: &Geometry) -> Option<BlockFormat> {
        if self.members.is_empty()
            || !self.width.is_multiple_of(4)
            || !self.height.is_multiple_of(4)
        {
            return None;
        }
        let mut format: Option<BlockFormat> = None;
        for &i in &self.members {
            let f = geometry.textures.get(i)?.blocks.as_ref()?.format;
            format = Some(match format {
                None => f,
                Some(g) if g == f => g,
                Some(g) if g.family() == "etc2" && f.family() == "etc2" => BlockFormat::Etc2Rgba8,
                Some(_) => return None,
            });
        }
        format
    }

    /// Level `level` of layer `layer` as uploaded in block format `format` (the array's
    /// [`TextureArray::block_format`]): rows of blocks covering the level, top to bottom
    /// (`ceil(w / 4)` × `ceil(h / 4)` blocks, the level's physical size), each block
    /// `(bx, by)` the member's block `(bx mod mbw, by mod mbh)` of its own level of the same
    /// index (`mbw` × `mbh` its blocks; its last, 1×1, level beyond its chain), ETC2 RGB8
    /// blocks of an ETC2 RGBA8 array after [`OPAQUE_EAC_BLOCK`] ([`tiled_blocks`]).
    ///
    /// Decoded, these are [`TextureArray::level_bytes`] texel for texel (cropped to the
    /// level's size): members are powers of two and levels narrower than a block are stored
    /// tiled to fill it, so repeating blocks repeats texels. `None` when the layer or level is
    /// out of range, or the member has no blocks that `format` holds.
    pub fn level_blocks(
        &self,
        geometry: &Geometry,
        format: BlockFormat,
        layer: u32,
        level: u32,
    ) -> Option<Vec<u8>> {
        if level >= self.levels {
            return None;
        }
        let t = geometry.textures.get(*self.members.get(layer as usize)?)?;
        let blocks = t.blocks.as_ref()?;
        let k = (level as usize).min(blocks.levels.len().checked_sub(1)?);
        let (mw, mh) = Texture::level_size(t.width, t.height, k as u32);
        let member = &blocks.levels[k];
        let widened;
        let member: &[u8] = match (blocks.format, format) {
            (f, g) if f == g => member,
            (BlockFormat::Etc2Rgb8, BlockFormat::Etc2Rgba8) => {
                widened = member
                    .chunks_exact(8)
                    .flat_map(|b| OPAQUE_EAC_BLOCK.iter().chain(b))
                    .copied()
                    .collect::<Vec<u8>>();
                &widened
            }
            _ => return None,
        };
        let (aw, ah) = self.level_size(level);
        Some(tiled_blocks(
            member,
            format.block_bytes(),
            (mw.div_ceil(4), mh.div_ceil(4)),
            (aw.div_ceil(4), ah.div_ceil(4)),
        ))
    }
}

/// Rows of `mbw` × `mbh` blocks of `block_bytes` each, repeated over `abw` × `abh` blocks from
/// the top-left block (cropped where the member is larger): block `(bx, by)` of the result is
/// block `(bx mod mbw, by mod mbh)` of `blocks`. [`tiled`] for block-compressed levels.
pub fn tiled_blocks(
    blocks: &[u8],
    block_bytes: usize,
    (mbw, mbh): (u32, u32),
    (abw, abh): (u32, u32),
) -> Vec<u8> {
    let row = mbw as usize * block_bytes;
    let mut data = Vec::with_capacity(abw as usize * abh as usize * block_bytes);
    for by in 0..abh {
        let member_row = &blocks[(by % mbh) as usize * row..][..row];
        let mut bx = 0;
        while bx < abw {
            let n = (abw - bx).min(mbw);
            data.extend_from_slice(&member_row[..n as usize * block_bytes]);
            bx += n;
        }
    }
    data
}

/// The two material texture arrays and where each texture lies in them.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureArrays {
    /// The sRGB array (base colour and emissive textures, as their colour space says).
    pub srgb: TextureArray,
    /// The linear array (metallic-roughness, normal, occlusion).
    pub linear: TextureArray,
    /// Per texture of the geometry.
    pub places: Vec<TexturePlace>,
}

/// Level `k` of `t` as its size and RGBA8 bytes: level 0, a level of its stored chain
/// ([`Texture::mips`], full as [`Geometry::check_structure`] requires), or for a level beyond
/// the chain (the array's largest texture has more levels) its last, 1×1 level again, which
/// is what averaging a 1×1 level would give.
fn texture_level(t: &Texture, k: usize) -> ((u32, u32), &[u8]) {
    let k = k.min(t.mips.len());
    let size = Texture::level_size(t.width, t.height, k as u32);
    let bytes = if k == 0 { &t.rgba8 } else { &t.mips[k - 1] };
    (size, bytes)
}

/// A `w` × `h` RGBA8 level of `size` repeated over a layer level of `layer` texels from the
/// top-left corner (cropped where the texture is larger: texels beyond the device limit, a
/// documented limitation). Filtering across the right and bottom edges of the texture's corner
/// (linear filtering at level 0, and every coarser level's footprint) then reads the texels
/// its repeat would, not the unused rest of the layer.
pub fn tiled(level: &[u8], (w, h): (u32, u32), (lw, lh): (u32, u32)) -> Vec<u8> {
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

/// Plans the two material texture arrays, sRGB and linear, each texture in the array of its
/// [`Texture::srgb`] flag. A layer is as large as its array's largest texture (clamped to
/// `max_dim`), with a full mip chain; a smaller texture fills the top-left corner of every
/// level with its own level of the same index, repeated over the rest of the level
/// ([`tiled`]). With `visibility_only` the linear array is left empty (its textures placed at
/// its layer 0, the white texel) unless a material's base-colour texture is linear.
///
/// One uv scale serves every level, which is exact at level 0 (and so for the alpha that
/// decides visibility, always sampled there) but only approximate at a coarser level `k` of a
/// texture `w` texels wide in a layer `tw` wide: the shader maps uv ∈ [0, 1) onto
/// `P = (w / tw)·(tw >> k)` texels of the layer's level, while the texture's own level repeats
/// there every `max(1, w >> k)` texels. Both lie in `(w / 2^k − 1, w / 2^k]`, so across one
/// repeat the sampled point drifts from the texture's by less than one texel *of level k*, and
/// steps back by as much where uv wraps. It is zero when `2^k` divides both `w` and `tw`: a
/// power-of-two texture in a power-of-two layer, and the array's largest texture, are exact
/// at every level.
pub fn plan_texture_arrays(
    geometry: &Geometry,
    max_dim: u32,
    visibility_only: bool,
) -> TextureArrays {
    let mut places = vec![
        TexturePlace {
            linear: false,
            layer: 0,
            scale: [1.0, 1.0]
        };
        geometry.textures.len()
    ];
    // What `surface_base` samples: base-colour textures, in the array of their colour space.
    let linear_base = geometry.materials.iter().any(|m| {
        m.base_color_texture
            .and_then(|t| geometry.textures.get(t as usize))
            .is_some_and(|t| !t.srgb)
    });
    let mut arrays = Vec::with_capacity(2);
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
        let (tw, th) = members.iter().fold((1u32, 1u32), |(w, h), &i| {
            let t = &geometry.textures[i];
            (w.max(t.width), h.max(t.height))
        });
        let (tw, th) = (tw.min(max_dim.max(1)), th.min(max_dim.max(1)));
        for (layer, &i) in members.iter().enumerate() {
            let t = &geometry.textures[i];
            places[i] = TexturePlace {
                linear,
                layer: layer as u32,
                scale: [
                    t.width.min(tw) as f32 / tw as f32,
                    t.height.min(th) as f32 / th as f32,
                ],
            };
        }
        arrays.push(TextureArray {
            linear,
            width: tw,
            height: th,
            levels: chain_levels(tw, th),
            members,
        });
    }
    let linear = arrays.pop().expect("two arrays");
    let srgb = arrays.pop().expect("two arrays");
    TextureArrays {
        srgb,
        linear,
        places,
    }
}

/// One level of the prefiltered environment as uploaded.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentLevel {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// RGBA binary16 bits, rows from the zenith down.
    pub texels: Vec<u16>,
}

/// The prefiltered radiance as uploaded (an `Rgba16Float` texture): one mip level per stored
/// level, as many as a full chain of the first level's size holds; levels larger than
/// `max_dim` are left out from the top, and a level whose texel count does not match its size
/// is skipped. One white texel when nothing is left.
pub fn environment_levels(env: &Environment, max_dim: u32) -> Vec<EnvironmentLevel> {
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
    stored
        .iter()
        .take(levels as usize)
        .enumerate()
        .map(|(k, &(sw, sh, texels))| {
            // A level's size is that of the chain (`max(1, w0 >> k)`): the file's sizes agree.
            let (w, h) = (sw.min((w0 >> k).max(1)), sh.min((h0 >> k).max(1)));
            let row = w as usize * 4;
            let mut data: Vec<u16> = Vec::with_capacity(row * h as usize);
            for y in 0..h as usize {
                data.extend_from_slice(&texels[y * sw as usize * 4..][..row]);
            }
            EnvironmentLevel {
                width: w,
                height: h,
                texels: data,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_sizes_match_the_wgsl() {
        assert_eq!(std::mem::size_of::<FrameUniform>(), 144);
        assert_eq!(std::mem::size_of::<LightingUniform>(), 192);
        assert_eq!(
            std::mem::size_of::<MaterialGpu>(),
            MATERIAL_TEXELS as usize * 16
        );
    }

    #[test]
    fn data_textures_pad_to_whole_rows() {
        let (bytes, rows) = data_texture_bytes(&[1u8; 32]);
        assert_eq!((bytes.len(), rows), (DATA_WIDTH as usize * 16, 1));
        assert_eq!(&bytes[..32], &[1u8; 32]);
        assert!(bytes[32..].iter().all(|&b| b == 0));
    }

    #[test]
    fn an_empty_array_is_one_white_texel() {
        let g = Geometry::default();
        let a = plan_texture_arrays(&g, 8192, false);
        assert_eq!((a.srgb.width, a.srgb.levels, a.srgb.layers()), (1, 1, 1));
        assert_eq!(a.srgb.level_bytes(&g, 0, 0), Some(vec![255u8; 4]));
        assert_eq!(a.srgb.level_bytes(&g, 1, 0), None);
    }

    #[test]
    fn the_uniform_environment_is_one_level() {
        let levels = environment_levels(&Environment::uniform(1.0), 8192);
        assert!(!levels.is_empty());
        assert_eq!(
            levels[0].texels.len(),
            (levels[0].width * levels[0].height * 4) as usize
        );
    }
}
