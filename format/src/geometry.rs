//! Scene geometry as the GPU sees it: vertices, triangles, materials, textures and nodes.

use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};

/// One vertex, laid out as the vertex buffer of every pipeline (recorder, player, reference).
///
/// `position`, `normal` and `tangent` are in the local space of `node`: the node whose
/// (possibly animated) world transform moves this vertex. All three vertices of a triangle
/// share `material` and `node`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable, Serialize, Deserialize)]
pub struct Vertex {
    /// Position in the node's local space.
    pub position: [f32; 3],
    /// Unit normal in the node's local space (zero when the source had none and it could not
    /// be derived).
    pub normal: [f32; 3],
    /// First texture coordinate (TEXCOORD_0), for texture slots whose `tex_coord` is 0; zero
    /// where no texture slot samples it or the source has none.
    pub uv: [f32; 2],
    /// Index into [`Geometry::materials`].
    pub material: u32,
    /// Index into [`Geometry::nodes`].
    pub node: u32,
    /// Tangent in the node's local space (xyz, unit) and handedness (w, ±1): the bitangent is
    /// `cross(normal, tangent.xyz) * tangent.w`. From the file's TANGENT, else generated
    /// (MikkTSpace) for materials with a normal texture; zero where there is none.
    pub tangent: [f32; 4],
    /// Second texture coordinate (TEXCOORD_1), for texture slots whose `tex_coord` is 1; zero
    /// where no texture slot samples it or the source has none.
    pub uv1: [f32; 2],
}

/// How a material's alpha is interpreted (glTF `alphaMode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub enum AlphaMode {
    /// Alpha is ignored; the surface is fully opaque.
    #[default]
    Opaque,
    /// Fragments with alpha below the cutoff are discarded, the rest are opaque.
    Mask,
    /// Alpha blends the surface over what lies behind it.
    Blend,
}

/// `KHR_texture_transform` of one texture reference: `uv' = T(offset) · R(rotation) ·
/// S(scale) · uv`, as the extension defines it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureTransform {
    /// Translation, in uv units.
    pub offset: [f32; 2],
    /// Rotation in radians, counter-clockwise in uv space.
    pub rotation: f32,
    /// Scale.
    pub scale: [f32; 2],
}

impl Default for TextureTransform {
    fn default() -> Self {
        TextureTransform {
            offset: [0.0; 2],
            rotation: 0.0,
            scale: [1.0; 2],
        }
    }
}

impl TextureTransform {
    /// The transform as the 2×3 matrix the shaders use, row-major: `u' = m[0]·(u, v, 1)`,
    /// `v' = m[1]·(u, v, 1)`.
    pub fn matrix(&self) -> [[f32; 3]; 2] {
        let (s, c) = self.rotation.sin_cos();
        let [sx, sy] = self.scale;
        let [ox, oy] = self.offset;
        [[c * sx, s * sy, ox], [-s * sx, c * sy, oy]]
    }

    /// Whether every value is finite.
    pub fn is_finite(&self) -> bool {
        self.offset
            .iter()
            .chain(&self.scale)
            .chain([&self.rotation])
            .all(|x| x.is_finite())
    }
}

/// A material's reference to a texture other than its base colour: which texture, which
/// texture coordinate set, and its transform.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureSlot {
    /// Index into [`Geometry::textures`].
    pub texture: u32,
    /// Texture coordinate set: 0 ([`Vertex::uv`]) or 1 ([`Vertex::uv1`]).
    pub tex_coord: u32,
    /// `KHR_texture_transform`.
    pub transform: TextureTransform,
}

/// A material: glTF's metallic-roughness model with the extensions trisort renders
/// (clearcoat, emissive strength, transmission, texture transforms).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Name from the source file (may be empty).
    pub name: String,
    /// Linear RGBA base colour factor.
    pub base_color: [f32; 4],
    /// Index into [`Geometry::textures`] of the base-colour texture (sRGB, sampled at
    /// [`Vertex::uv`]), if any.
    pub base_color_texture: Option<u32>,
    /// Alpha mode.
    pub alpha_mode: AlphaMode,
    /// Alpha cutoff for [`AlphaMode::Mask`] (glTF default 0.5).
    pub alpha_cutoff: f32,
    /// Whether back faces are drawn. Single-sided materials discard back-facing fragments.
    pub double_sided: bool,
    /// Linear RGB emissive colour (factor × strength).
    pub emissive: [f32; 3],
    /// `KHR_materials_transmission` factor: 0 for ordinary materials, > 0 for glass. Glass is
    /// recorded at the recording's glass opacity instead of its alpha.
    pub transmission: f32,
    /// Texture coordinate set (0 or 1) of the base-colour texture.
    pub base_color_tex_coord: u32,
    /// `KHR_texture_transform` of the base-colour texture (it moves the alpha that MASK and
    /// BLEND materials are recorded with, too).
    pub base_color_transform: TextureTransform,
    /// Metallic factor (glTF default 1).
    pub metallic: f32,
    /// Perceptual roughness factor (glTF default 1).
    pub roughness: f32,
    /// Metallic-roughness texture (linear; blue: metallic, green: roughness).
    pub metallic_roughness_texture: Option<TextureSlot>,
    /// Tangent-space normal texture (linear).
    pub normal_texture: Option<TextureSlot>,
    /// Scale of the normal texture's x and y (glTF `normalTexture.scale`, default 1).
    pub normal_scale: f32,
    /// Ambient occlusion texture (linear, red channel).
    pub occlusion_texture: Option<TextureSlot>,
    /// Strength of the occlusion texture (glTF `occlusionTexture.strength`, default 1).
    pub occlusion_strength: f32,
    /// Emissive texture (sRGB), multiplied by [`Material::emissive`].
    pub emissive_texture: Option<TextureSlot>,
    /// `KHR_materials_clearcoat` layer intensity (0: no clearcoat).
    pub clearcoat: f32,
    /// `KHR_materials_clearcoat` layer roughness.
    pub clearcoat_roughness: f32,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: String::new(),
            base_color: [1.0; 4],
            base_color_texture: None,
            alpha_mode: AlphaMode::Opaque,
            alpha_cutoff: 0.5,
            double_sided: false,
            emissive: [0.0; 3],
            transmission: 0.0,
            base_color_tex_coord: 0,
            base_color_transform: TextureTransform::default(),
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            occlusion_texture: None,
            occlusion_strength: 1.0,
            emissive_texture: None,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
        }
    }
}

impl Material {
    /// The opacity this material is recorded and played with when its texture is ignored:
    /// glass (transmission > 0) gets `glass_opacity`, `Opaque` and `Mask` get 1, `Blend` its
    /// base-colour alpha.
    pub fn factor_opacity(&self, glass_opacity: f32) -> f32 {
        if self.transmission > 0.0 {
            glass_opacity
        } else {
            match self.alpha_mode {
                AlphaMode::Opaque | AlphaMode::Mask => 1.0,
                AlphaMode::Blend => self.base_color[3],
            }
        }
    }

    /// Whether every fragment of the material has alpha 1 when recorded and played with
    /// `glass_opacity`: glass only at opacity 1, otherwise `Opaque` and `Mask` (whose cut
    /// fragments are discarded, the rest alpha 1), never `Blend` (its texture may lower alpha).
    pub fn every_fragment_opaque(&self, glass_opacity: f32) -> bool {
        if self.transmission > 0.0 {
            glass_opacity >= 1.0
        } else {
            self.alpha_mode != AlphaMode::Blend
        }
    }
}

/// A decoded texture: tightly packed RGBA8, rows top to bottom, with its mip chain.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Texture {
    /// Name (image name or URI from the source file; may be empty).
    pub name: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `width * height * 4` bytes.
    pub rgba8: Vec<u8>,
    /// Whether the colour channels are sRGB-encoded (base colour, emissive) rather than
    /// linear data (metallic-roughness, normal, occlusion). An image the file uses both ways
    /// is stored twice.
    pub srgb: bool,
    /// Mip levels 1, 2, … down to 1×1 (level k is `max(1, width >> k)` ×
    /// `max(1, height >> k)`, RGBA8), generated at import ([`Texture::with_mips`]). Always the
    /// full chain ([`Texture::mip_count`] levels; empty only for a 1×1 texture):
    /// [`Geometry::check_structure`] requires it, and the GPU upload uses these levels as
    /// stored, so the file is the one source of every texture's mips.
    pub mips: Vec<Vec<u8>>,
}

impl Texture {
    /// The largest width or height [`Texture::with_mips`] stores by default: a bigger image is
    /// stored from its first mip level that fits.
    pub const MAX_SIZE: u32 = 1024;

    /// Width and height of mip level `level` of a `width` × `height` image:
    /// `max(1, width >> level)` × `max(1, height >> level)`.
    pub fn level_size(width: u32, height: u32, level: u32) -> (u32, u32) {
        let shrink = |x: u32| x.checked_shr(level).unwrap_or(0).max(1);
        (shrink(width), shrink(height))
    }

    /// The number of levels below level 0 of a full chain down to 1×1 (0 for a 1×1 image).
    pub fn mip_count(width: u32, height: u32) -> usize {
        let largest = width.max(height).max(1);
        (u32::BITS - 1 - largest.leading_zeros()) as usize
    }

    /// Bytes of level 0 and every stored mip level.
    pub fn byte_len(&self) -> u64 {
        self.rgba8.len() as u64 + self.mips.iter().map(|m| m.len() as u64).sum::<u64>()
    }

    /// A texture from a decoded `width` × `height` RGBA8 image (rows top to bottom), with its
    /// full mip chain ([`Texture::mips`]). Each level is a box filter of the one above it:
    /// texel `(x, y)` averages the texels of the level above that its footprint overlaps (2×2,
    /// or 3 along an odd dimension, 1 along a dimension of size 1), with equal weights. For an
    /// `srgb` texture the colour channels are decoded to linear light, averaged and encoded
    /// again (black and white average to 188, not 128); alpha, and every channel of a linear
    /// texture, is averaged as stored. Rounds to nearest.
    ///
    /// An image wider or taller than `max_size` is stored from its first mip level that fits
    /// (levels above it are computed and dropped); the second value returned is that level
    /// (0 when it fits). `rgba8` must hold `width * height * 4` bytes and both sizes must be at
    /// least 1, else this panics.
    pub fn with_mips(
        name: String,
        width: u32,
        height: u32,
        rgba8: Vec<u8>,
        srgb: bool,
        max_size: u32,
    ) -> (Texture, u32) {
        assert!(width > 0 && height > 0, "an empty image has no mips");
        assert_eq!(
            rgba8.len() as u64,
            width as u64 * height as u64 * 4,
            "RGBA8 byte count of a {width}x{height} image"
        );
        let max_size = max_size.max(1);
        let (mut w, mut h, mut level0) = (width, height, rgba8);
        let mut dropped = 0;
        while w > max_size || h > max_size {
            let (nw, nh) = Texture::level_size(w, h, 1);
            level0 = downsample(&level0, w, h, nw, nh, srgb);
            (w, h) = (nw, nh);
            dropped += 1;
        }
        let mut mips: Vec<Vec<u8>> = Vec::with_capacity(Texture::mip_count(w, h));
        let (mut lw, mut lh) = (w, h);
        for _ in 0..Texture::mip_count(w, h) {
            let (nw, nh) = Texture::level_size(lw, lh, 1);
            let above = mips.last().unwrap_or(&level0);
            let next = downsample(above, lw, lh, nw, nh, srgb);
            mips.push(next);
            (lw, lh) = (nw, nh);
        }
        let texture = Texture {
            name,
            width: w,
            height: h,
            rgba8: level0,
            srgb,
            mips,
        };
        (texture, dropped)
    }
}

/// sRGB-encoded byte to linear light.
fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light in [0, 1] to the nearest sRGB-encoded byte.
fn linear_to_srgb(l: f32) -> u8 {
    let l = l.clamp(0.0, 1.0);
    let c = if l <= 0.0031308 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (c * 255.0).round() as u8
}

/// The `[start, end)` texels of a source dimension of `from` texels that dest texel `i` of
/// `to` overlaps.
fn footprint(i: u32, from: u32, to: u32) -> (usize, usize) {
    let start = (i as u64 * from as u64) / to as u64;
    let end = ((i as u64 + 1) * from as u64).div_ceil(to as u64);
    (start as usize, end as usize)
}

/// One box-filtered level (see [`Texture::with_mips`]).
fn downsample(src: &[u8], w: u32, h: u32, nw: u32, nh: u32, srgb: bool) -> Vec<u8> {
    let decode: Vec<f32> = (0..=255u8)
        .map(|c| {
            if srgb {
                srgb_to_linear(c)
            } else {
                c as f32 / 255.0
            }
        })
        .collect();
    let mut out = Vec::with_capacity(nw as usize * nh as usize * 4);
    for y in 0..nh {
        let (y0, y1) = footprint(y, h, nh);
        for x in 0..nw {
            let (x0, x1) = footprint(x, w, nw);
            let mut sum = [0f32; 4];
            for sy in y0..y1 {
                let row = &src[sy * w as usize * 4..];
                for sx in x0..x1 {
                    let p = &row[sx * 4..sx * 4 + 4];
                    for c in 0..3 {
                        sum[c] += decode[p[c] as usize];
                    }
                    sum[3] += p[3] as f32;
                }
            }
            let n = ((y1 - y0) * (x1 - x0)) as f32;
            for c in sum.iter().take(3) {
                let v = c / n;
                out.push(if srgb {
                    linear_to_srgb(v)
                } else {
                    (v * 255.0).round().clamp(0.0, 255.0) as u8
                });
            }
            out.push((sum[3] / n).round().clamp(0.0, 255.0) as u8);
        }
    }
    out
}

/// A node of the scene hierarchy.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Node {
    /// Node name from the source file (may be empty; names need not be unique).
    pub name: String,
    /// Parent node index; parents always come before their children.
    pub parent: Option<u32>,
    /// Rest (unanimated) local transform, column-major 4×4, f64.
    pub rest: [f64; 16],
}

/// Everything the GPU needs to draw a set of triangles.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Geometry {
    /// Vertex buffer.
    pub vertices: Vec<Vertex>,
    /// Triangles as vertex indices, counter-clockwise front faces (winding already flipped
    /// under negative-determinant transforms). The index of a triangle is its id.
    pub triangles: Vec<[u32; 3]>,
    /// Materials, indexed by [`Vertex::material`].
    pub materials: Vec<Material>,
    /// Textures, indexed by [`Material::base_color_texture`].
    pub textures: Vec<Texture>,
    /// Node hierarchy, indexed by [`Vertex::node`].
    pub nodes: Vec<Node>,
    /// Material variants (glTF `KHR_materials_variants`), in file order: what
    /// [`Geometry::variant_materials`] applies at play time. Empty without the extension.
    pub variants: Vec<MaterialVariant>,
}

/// One material variant: which material each material slot shows under it.
///
/// glTF maps variants per primitive; the importer turns that into one table per variant over
/// [`Geometry::materials`] (giving a primitive a slot of its own where two primitives sharing a
/// material map it differently), so a variant is applied by rewriting the material table alone:
/// vertices keep their [`Vertex::material`] slot.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MaterialVariant {
    /// Name from the file (`""` when unnamed; names need not be unique).
    pub name: String,
    /// Per material slot (same length as [`Geometry::materials`]): the index of the material
    /// drawn in that slot under this variant (the slot itself where the variant leaves it).
    pub materials: Vec<u32>,
}

/// Why a variant cannot be applied to a baked file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum VariantError {
    /// No variant has this name.
    #[error("no material variant {name:?}: {}", list_variants(available))]
    Unknown {
        /// The name asked for.
        name: String,
        /// The variants the file has.
        available: Vec<String>,
    },
    /// The variant changes what decides visibility, so the baked order would not be exact.
    #[error(
        "variant {variant:?} cannot be played on this bake: it replaces material {slot} {from:?} \
         by material {to:?}, which changes its {field}; that decides visibility, so the baked \
         order would not be exact (bake a scene whose default materials are this variant's)"
    )]
    ChangesVisibility {
        /// The variant.
        variant: String,
        /// The material slot.
        slot: u32,
        /// Name of the slot's default material.
        from: String,
        /// Name of the material the variant puts there.
        to: String,
        /// What differs (alpha mode, alpha cutoff, alpha, transmission, ...).
        field: &'static str,
    },
}

fn list_variants(available: &[String]) -> String {
    if available.is_empty() {
        "the file has no variants".to_string()
    } else {
        let names: Vec<String> = available.iter().map(|n| format!("{n:?}")).collect();
        format!("the file's variants are {}", names.join(", "))
    }
}

impl Geometry {
    /// The material of triangle `t` (the material of its first vertex).
    pub fn triangle_material(&self, t: u32) -> u32 {
        self.vertices[self.triangles[t as usize][0] as usize].material
    }

    /// The node that moves triangle `t`.
    pub fn triangle_node(&self, t: u32) -> u32 {
        self.vertices[self.triangles[t as usize][0] as usize].node
    }

    /// Checks the structural consistency a reader relies on before using the geometry:
    /// triangle vertices in range, vertex materials and nodes in range, finite positions,
    /// finite material factors and texture transforms, every texture slot naming an existing
    /// texture and texture coordinate set 0 or 1, every texture non-empty with the right byte
    /// count for level 0 and for each level of its full mip chain down to 1×1, parents before
    /// children, finite rest transforms, variants mapping every material slot to an existing
    /// material. Returns the first problem found.
    pub fn check_structure(&self) -> Result<(), crate::StructureError> {
        let nv = self.vertices.len() as u64;
        for (k, t) in self.triangles.iter().enumerate() {
            if t.iter().any(|&v| v as u64 >= nv) {
                return Err(crate::Part::Geometry
                    .error(format!("triangle {k} refers to a vertex beyond {nv}")));
            }
        }
        for (k, v) in self.vertices.iter().enumerate() {
            if v.material as usize >= self.materials.len() || v.node as usize >= self.nodes.len() {
                return Err(crate::Part::Geometry
                    .error(format!("vertex {k} refers to a missing material or node")));
            }
            if !v.position.iter().all(|x| x.is_finite()) {
                return Err(
                    crate::Part::Geometry.error(format!("vertex {k} has a non-finite position"))
                );
            }
        }
        for (k, m) in self.materials.iter().enumerate() {
            let factors = (m.base_color.iter().chain(&m.emissive)).chain([
                &m.alpha_cutoff,
                &m.transmission,
                &m.metallic,
                &m.roughness,
                &m.normal_scale,
                &m.occlusion_strength,
                &m.clearcoat,
                &m.clearcoat_roughness,
            ]);
            if !factors.into_iter().all(|x| x.is_finite()) {
                return Err(
                    crate::Part::Geometry.error(format!("material {k} has a non-finite factor"))
                );
            }
            let base = m.base_color_texture.map(|texture| TextureSlot {
                texture,
                tex_coord: m.base_color_tex_coord,
                transform: m.base_color_transform,
            });
            let slots = [
                ("base-colour", base),
                ("metallic-roughness", m.metallic_roughness_texture),
                ("normal", m.normal_texture),
                ("occlusion", m.occlusion_texture),
                ("emissive", m.emissive_texture),
            ];
            for (what, slot) in slots {
                let Some(slot) = slot else { continue };
                let t = slot.texture;
                if t as usize >= self.textures.len() {
                    return Err(crate::Part::Geometry.error(format!(
                        "material {k}'s {what} texture refers to missing texture {t}"
                    )));
                }
                if slot.tex_coord > 1 {
                    return Err(crate::Part::Geometry.error(format!(
                        "material {k}'s {what} texture samples texture coordinate set {} \
                         (only 0 and 1 exist)",
                        slot.tex_coord
                    )));
                }
                if !slot.transform.is_finite() {
                    return Err(crate::Part::Geometry.error(format!(
                        "material {k}'s {what} texture transform is not finite"
                    )));
                }
            }
            if m.base_color_tex_coord > 1 {
                return Err(crate::Part::Geometry.error(format!(
                    "material {k}'s base-colour texture coordinate set {} does not exist \
                     (only 0 and 1 do)",
                    m.base_color_tex_coord
                )));
            }
        }
        for (t, tex) in self.textures.iter().enumerate() {
            if tex.width == 0 || tex.height == 0 {
                return Err(crate::Part::Geometry.error(format!(
                    "texture {t} is empty ({}x{})",
                    tex.width, tex.height
                )));
            }
            if tex.rgba8.len() as u64 != tex.width as u64 * tex.height as u64 * 4 {
                return Err(crate::Part::Geometry
                    .error(format!("texture {t} has the wrong number of bytes")));
            }
            let levels = Texture::mip_count(tex.width, tex.height);
            if tex.mips.len() != levels {
                return Err(crate::Part::Geometry.error(format!(
                    "texture {t} {:?} ({}x{}) has {} mip levels, a full chain has {levels} \
                     (levels 1, 2, … down to 1x1, made at import)",
                    tex.name,
                    tex.width,
                    tex.height,
                    tex.mips.len()
                )));
            }
            for (k, mip) in tex.mips.iter().enumerate() {
                let (w, h) = Texture::level_size(tex.width, tex.height, k as u32 + 1);
                if mip.len() as u64 != w as u64 * h as u64 * 4 {
                    return Err(crate::Part::Geometry.error(format!(
                        "texture {t}'s mip level {} has {} bytes, {w}x{h} RGBA8 needs {}",
                        k + 1,
                        mip.len(),
                        w as u64 * h as u64 * 4
                    )));
                }
            }
        }
        for (k, v) in self.variants.iter().enumerate() {
            if v.materials.len() != self.materials.len() {
                return Err(crate::Part::Geometry.error(format!(
                    "material variant {k} maps {} material slots, the geometry has {}",
                    v.materials.len(),
                    self.materials.len()
                )));
            }
            if let Some(m) = v
                .materials
                .iter()
                .find(|&&m| m as usize >= self.materials.len())
            {
                return Err(crate::Part::Geometry.error(format!(
                    "material variant {k} refers to missing material {m}"
                )));
            }
        }
        for (k, n) in self.nodes.iter().enumerate() {
            if n.parent.is_some_and(|p| p as usize >= k) {
                return Err(crate::Part::Geometry
                    .error(format!("node {k} has a parent that does not precede it")));
            }
            if !n.rest.iter().all(|x| x.is_finite()) {
                return Err(
                    crate::Part::Geometry.error(format!("node {k}'s rest transform is not finite"))
                );
            }
        }
        Ok(())
    }

    /// A copy holding only the given triangles (scene ids, ascending, no duplicates), with
    /// only the vertices they use; materials, textures and nodes are kept whole so their
    /// indices stay valid. Triangle k of the result is `ids[k]` of `self`.
    pub fn subset(&self, ids: &[u32]) -> Geometry {
        debug_assert!(ids.windows(2).all(|w| w[0] < w[1]), "ids must ascend");
        let mut remap = vec![u32::MAX; self.vertices.len()];
        let mut vertices = Vec::new();
        let mut triangles = Vec::with_capacity(ids.len());
        for &t in ids {
            let tri = self.triangles[t as usize];
            let mut out = [0u32; 3];
            for (k, &v) in tri.iter().enumerate() {
                if remap[v as usize] == u32::MAX {
                    remap[v as usize] = vertices.len() as u32;
                    vertices.push(self.vertices[v as usize]);
                }
                out[k] = remap[v as usize];
            }
            triangles.push(out);
        }
        Geometry {
            vertices,
            triangles,
            materials: self.materials.clone(),
            textures: self.textures.clone(),
            nodes: self.nodes.clone(),
            variants: self.variants.clone(),
        }
    }

    /// The material table under variant `name` (`None`: the default materials): entry k is
    /// what slot k shows. Refused when the variant is unknown, or when it changes anything
    /// that decides which samples a triangle covers or how opaque it is, for any slot: alpha
    /// mode, double-sidedness, transmission, and for non-glass `Mask` materials the cutoff,
    /// and for non-glass `Mask` and `Blend` materials the alpha factor, the base-colour
    /// texture's alpha channel, and (where that alpha is not 255 everywhere) the base-colour
    /// texture coordinate set and transform. Colour, emissive and opaque textures may change freely.
    pub fn variant_materials(&self, name: Option<&str>) -> Result<Vec<Material>, VariantError> {
        let Some(name) = name else {
            return Ok(self.materials.clone());
        };
        let Some(variant) = self.variants.iter().find(|v| v.name == name) else {
            return Err(VariantError::Unknown {
                name: name.to_string(),
                available: self.variants.iter().map(|v| v.name.clone()).collect(),
            });
        };
        let mut out = Vec::with_capacity(self.materials.len());
        for (slot, from) in self.materials.iter().enumerate() {
            let target = variant.materials.get(slot).copied().unwrap_or(slot as u32);
            let to = self.materials.get(target as usize).unwrap_or(from);
            if let Some(field) = self.visibility_change(from, to) {
                return Err(VariantError::ChangesVisibility {
                    variant: variant.name.clone(),
                    slot: slot as u32,
                    from: from.name.clone(),
                    to: to.name.clone(),
                    field,
                });
            }
            out.push(to.clone());
        }
        Ok(out)
    }

    /// The first property deciding coverage or opacity that differs between `a` and `b`.
    fn visibility_change(&self, a: &Material, b: &Material) -> Option<&'static str> {
        if a.alpha_mode != b.alpha_mode {
            return Some("alpha mode");
        }
        if a.double_sided != b.double_sided {
            return Some("double-sidedness (back faces are culled or not)");
        }
        if a.transmission.to_bits() != b.transmission.to_bits() {
            return Some("transmission");
        }
        // Glass is drawn at the glass opacity whatever its alpha; opaque materials at 1.
        if a.transmission > 0.0 || a.alpha_mode == AlphaMode::Opaque {
            return None;
        }
        if a.alpha_mode == AlphaMode::Mask && a.alpha_cutoff.to_bits() != b.alpha_cutoff.to_bits() {
            return Some("alpha cutoff");
        }
        if a.base_color[3].to_bits() != b.base_color[3].to_bits() {
            return Some("alpha");
        }
        if !self.same_texture_alpha(a.base_color_texture, b.base_color_texture) {
            return Some("base-colour texture's alpha");
        }
        // Where the alpha varies, the coordinates it is sampled at move it.
        if self.texture_alpha_varies(a.base_color_texture)
            || self.texture_alpha_varies(b.base_color_texture)
        {
            if a.base_color_tex_coord != b.base_color_tex_coord {
                return Some("base-colour texture coordinate set (it moves the alpha)");
            }
            let bits = |t: &TextureTransform| {
                [t.offset[0], t.offset[1], t.rotation, t.scale[0], t.scale[1]].map(f32::to_bits)
            };
            if bits(&a.base_color_transform) != bits(&b.base_color_transform) {
                return Some("base-colour texture transform (it moves the alpha)");
            }
        }
        None
    }

    /// Whether texture `t` exists and has a texel with alpha below 255.
    fn texture_alpha_varies(&self, t: Option<u32>) -> bool {
        t.and_then(|t| self.textures.get(t as usize))
            .is_some_and(|t| t.rgba8.iter().skip(3).step_by(4).any(|&a| a != 255))
    }

    /// Whether two base-colour textures (or none, alpha 1) give the same alpha everywhere.
    fn same_texture_alpha(&self, a: Option<u32>, b: Option<u32>) -> bool {
        if a == b {
            return true;
        }
        let texture = |t: Option<u32>| t.and_then(|t| self.textures.get(t as usize));
        let alphas = |t: &Texture| {
            t.rgba8
                .iter()
                .skip(3)
                .step_by(4)
                .copied()
                .collect::<Vec<u8>>()
        };
        match (texture(a), texture(b)) {
            (None, None) => true,
            (Some(t), None) | (None, Some(t)) => alphas(t).iter().all(|&x| x == 255),
            (Some(s), Some(t)) => {
                s.width == t.width && s.height == t.height && alphas(s) == alphas(t)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Slots 0 (opaque red) and 1 (masked, textured), and the materials variants may use:
    /// 2 opaque blue, 3 blend, 4 masked with another cutoff, 5 masked with a texture of the
    /// same alpha, 6 masked with a texture of another alpha, 7 single-sided red, 8 glass.
    fn geometry(variant: Vec<u32>) -> Geometry {
        let m = |name: &str, rgba: [f32; 4], mode: AlphaMode| Material {
            name: name.into(),
            base_color: rgba,
            alpha_mode: mode,
            double_sided: true,
            ..Material::default()
        };
        let texture = |alpha: u8, rgb: u8| {
            let rgba8 = vec![rgb, rgb, rgb, alpha, 0, 0, 0, 255];
            Texture::with_mips(String::new(), 2, 1, rgba8, true, Texture::MAX_SIZE).0
        };
        let masked = |name: &str, t: u32| Material {
            base_color_texture: Some(t),
            ..m(name, [1.0; 4], AlphaMode::Mask)
        };
        Geometry {
            materials: vec![
                m("red", [1.0, 0.0, 0.0, 1.0], AlphaMode::Opaque),
                masked("leaf", 0),
                m("blue", [0.0, 0.0, 1.0, 0.5], AlphaMode::Opaque),
                m("veil", [1.0; 4], AlphaMode::Blend),
                Material {
                    alpha_cutoff: 0.25,
                    ..masked("leaf low", 0)
                },
                masked("leaf recoloured", 1),
                masked("leaf holed", 2),
                Material {
                    double_sided: false,
                    ..m("red one side", [1.0, 0.0, 0.0, 1.0], AlphaMode::Opaque)
                },
                Material {
                    transmission: 1.0,
                    ..m("glass", [1.0; 4], AlphaMode::Opaque)
                },
            ],
            textures: vec![texture(128, 10), texture(128, 200), texture(0, 10)],
            variants: vec![MaterialVariant {
                name: "v".into(),
                materials: variant,
            }],
            ..Geometry::default()
        }
    }

    fn with(slot0: u32, slot1: u32) -> Geometry {
        let mut map: Vec<u32> = (0..9).collect();
        map[0] = slot0;
        map[1] = slot1;
        geometry(map)
    }

    #[test]
    fn a_variant_changing_colour_only_applies() {
        for (slot0, slot1) in [(2, 1), (0, 5), (2, 5), (0, 1)] {
            let g = with(slot0, slot1);
            g.check_structure().unwrap();
            let table = g.variant_materials(Some("v")).unwrap();
            assert_eq!(table[0], g.materials[slot0 as usize]);
            assert_eq!(table[1], g.materials[slot1 as usize]);
            assert_eq!(table[2..], g.materials[2..]);
            assert_eq!(g.variant_materials(None).unwrap(), g.materials);
        }
    }

    #[test]
    fn a_variant_changing_what_decides_visibility_is_refused_naming_it() {
        for (slot0, slot1, field, from, to) in [
            (3, 1, "alpha mode", "red", "veil"),
            (7, 1, "double-sidedness", "red", "red one side"),
            (8, 1, "transmission", "red", "glass"),
            (0, 4, "alpha cutoff", "leaf", "leaf low"),
            (0, 6, "texture's alpha", "leaf", "leaf holed"),
        ] {
            let err = with(slot0, slot1).variant_materials(Some("v")).unwrap_err();
            let VariantError::ChangesVisibility { field: f, .. } = &err else {
                panic!("{err:?}");
            };
            assert!(f.contains(field), "{err}");
            let text = err.to_string();
            for needle in ["\"v\"", &format!("{from:?}"), &format!("{to:?}"), "exact"] {
                assert!(text.contains(needle), "{text} lacks {needle}");
            }
        }
        // An alpha factor change on a blend material is refused too.
        let mut g = with(0, 1);
        g.materials[2] = Material {
            base_color: [1.0, 1.0, 1.0, 0.5],
            ..g.materials[3].clone()
        };
        g.variants[0].materials[3] = 2;
        let err = g.variant_materials(Some("v")).unwrap_err();
        assert!(err.to_string().contains("its alpha;"), "{err}");
    }

    #[test]
    fn an_unknown_variant_lists_the_files_variants() {
        let err = with(0, 1).variant_materials(Some("w")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "no material variant \"w\": the file's variants are \"v\""
        );
        let none = Geometry::default()
            .variant_materials(Some("w"))
            .unwrap_err();
        assert!(
            none.to_string().ends_with("the file has no variants"),
            "{none}"
        );
    }

    #[test]
    fn check_structure_refuses_variants_that_do_not_map_every_slot() {
        let mut g = with(0, 1);
        g.variants[0].materials.pop();
        assert!(g
            .check_structure()
            .unwrap_err()
            .problem
            .contains("maps 8 material slots"));
        let mut g = with(0, 1);
        g.variants[0].materials[0] = 9;
        assert!(g
            .check_structure()
            .unwrap_err()
            .problem
            .contains("missing material 9"));
    }

    fn image(w: u32, h: u32) -> Vec<u8> {
        (0..w * h * 4).map(|i| (i * 37 % 251) as u8).collect()
    }

    #[test]
    fn mip_chains_halve_each_dimension_down_to_one_texel() {
        for (w, h, levels) in [
            (1, 1, 0),
            (2, 2, 1),
            (5, 3, 2),
            (7, 7, 2),
            (8, 2, 3),
            (1, 9, 3),
            (13, 1, 3),
            (1024, 3, 10),
        ] {
            let (t, dropped) = Texture::with_mips("t".into(), w, h, image(w, h), true, 1024);
            assert_eq!(dropped, 0);
            assert_eq!((t.width, t.height), (w, h));
            assert_eq!(t.mips.len(), levels, "{w}x{h}");
            for (k, mip) in t.mips.iter().enumerate() {
                let (lw, lh) = Texture::level_size(w, h, k as u32 + 1);
                assert_eq!((lw, lh), ((w >> (k + 1)).max(1), (h >> (k + 1)).max(1)));
                assert_eq!(mip.len() as u32, lw * lh * 4, "{w}x{h} level {}", k + 1);
            }
            assert_eq!(t.mips.last().map_or(4, |m| m.len()), 4, "ends at 1x1");
            let g = Geometry {
                textures: vec![t],
                ..Geometry::default()
            };
            g.check_structure().unwrap();
        }
    }

    #[test]
    fn srgb_mips_average_light_and_linear_ones_bytes() {
        // Black and white texels with alpha 0 and 255.
        let px = vec![0, 0, 0, 0, 255, 255, 255, 255];
        let (srgb, _) = Texture::with_mips(String::new(), 2, 1, px.clone(), true, 1024);
        assert_eq!(srgb.mips, vec![vec![188, 188, 188, 128]]);
        let (linear, _) = Texture::with_mips(String::new(), 2, 1, px, false, 1024);
        assert_eq!(linear.mips, vec![vec![128, 128, 128, 128]]);
        // An odd row of three averages all three: 0, 0 and 255 give a third of the light.
        let (odd, _) = Texture::with_mips(
            String::new(),
            3,
            1,
            vec![0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255, 255],
            true,
            1024,
        );
        // linear 1/3 -> sRGB 0.6134 -> 156.4
        assert_eq!(odd.mips, vec![vec![156, 156, 156, 255]]);
        // A uniform image stays uniform at every level.
        let (flat, _) = Texture::with_mips(
            String::new(),
            6,
            5,
            [90u8, 20, 200, 77].repeat(30),
            true,
            1024,
        );
        assert!(flat
            .mips
            .iter()
            .flatten()
            .collect::<Vec<_>>()
            .chunks(4)
            .all(|p| *p[0] == 90 && *p[1] == 20 && *p[2] == 200 && *p[3] == 77));
    }

    #[test]
    fn images_larger_than_the_cap_are_stored_from_the_first_level_that_fits() {
        let (t, dropped) = Texture::with_mips("big".into(), 20, 6, image(20, 6), false, 4);
        assert_eq!(dropped, 3);
        assert_eq!((t.width, t.height), (2, 1));
        assert_eq!(t.rgba8.len(), 2 * 4);
        assert_eq!(t.mips.len(), 1);
        // Level 0 as stored is what the full chain's level 3 would be.
        let (chain, _) = Texture::with_mips(String::new(), 20, 6, image(20, 6), false, 1024);
        assert_eq!(t.rgba8, chain.mips[2]);
        assert_eq!(t.mips[0], chain.mips[3]);
        let (fits, dropped) = Texture::with_mips("edge".into(), 4, 4, image(4, 4), false, 4);
        assert_eq!((dropped, fits.width), (0, 4));
        assert_eq!(fits.byte_len(), 4 * 4 * 4 + 2 * 2 * 4 + 4);
    }

    /// A valid geometry with one textured material using every slot.
    fn textured() -> Geometry {
        let (t, _) = Texture::with_mips("t".into(), 4, 2, image(4, 2), true, 1024);
        let slot = TextureSlot {
            texture: 0,
            tex_coord: 1,
            transform: TextureTransform::default(),
        };
        Geometry {
            materials: vec![Material {
                base_color_texture: Some(0),
                metallic_roughness_texture: Some(slot),
                normal_texture: Some(slot),
                occlusion_texture: Some(slot),
                emissive_texture: Some(slot),
                ..Material::default()
            }],
            textures: vec![t],
            ..Geometry::default()
        }
    }

    #[test]
    fn check_structure_refuses_bad_texture_slots_factors_and_mips() {
        textured().check_structure().unwrap();
        type Edit = fn(&mut Geometry);
        let cases: Vec<(Edit, &str)> = vec![
            (
                |g| g.materials[0].base_color_texture = Some(1),
                "base-colour texture refers to missing texture 1",
            ),
            (
                |g| g.materials[0].normal_texture.as_mut().unwrap().texture = 3,
                "normal texture refers to missing texture 3",
            ),
            (
                |g| g.materials[0].occlusion_texture.as_mut().unwrap().tex_coord = 2,
                "occlusion texture samples texture coordinate set 2",
            ),
            (
                |g| g.materials[0].base_color_tex_coord = 2,
                "base-colour texture samples texture coordinate set 2",
            ),
            (
                |g| {
                    g.materials[0]
                        .emissive_texture
                        .as_mut()
                        .unwrap()
                        .transform
                        .rotation = f32::NAN
                },
                "emissive texture transform is not finite",
            ),
            (
                |g| g.materials[0].base_color_transform.scale[1] = f32::INFINITY,
                "base-colour texture transform is not finite",
            ),
            (
                |g| {
                    g.materials[0]
                        .metallic_roughness_texture
                        .as_mut()
                        .unwrap()
                        .transform
                        .offset[0] = f32::NAN
                },
                "metallic-roughness texture transform",
            ),
            (|g| g.materials[0].metallic = f32::NAN, "non-finite factor"),
            (
                |g| g.materials[0].roughness = f32::INFINITY,
                "non-finite factor",
            ),
            (
                |g| g.materials[0].normal_scale = f32::NAN,
                "non-finite factor",
            ),
            (
                |g| g.materials[0].occlusion_strength = f32::NEG_INFINITY,
                "non-finite factor",
            ),
            (|g| g.materials[0].clearcoat = f32::NAN, "non-finite factor"),
            (
                |g| g.materials[0].clearcoat_roughness = f32::NAN,
                "non-finite factor",
            ),
            (
                |g| {
                    g.textures[0].mips.pop();
                },
                "has 1 mip levels, a full chain has 2",
            ),
            (
                |g| {
                    g.textures[0].mips[1].push(0);
                },
                "mip level 2 has 5 bytes, 1x1 RGBA8 needs 4",
            ),
            (
                |g| {
                    g.textures[0].mips[0].truncate(4);
                },
                "mip level 1 has 4 bytes, 2x1 RGBA8 needs 8",
            ),
            (
                |g| {
                    g.textures[0].rgba8.pop();
                },
                "texture 0 has the wrong number of bytes",
            ),
            (
                |g| {
                    g.textures[0].width = 0;
                },
                "texture 0 is empty",
            ),
        ];
        for (edit, expected) in cases {
            let mut g = textured();
            edit(&mut g);
            let err = g.check_structure().unwrap_err().problem;
            assert!(err.contains(expected), "{err:?} lacks {expected:?}");
        }
        // A texture without its mips is refused, naming it; a 1x1 texture has none to store.
        let mut g = textured();
        g.textures[0].mips.clear();
        let err = g.check_structure().unwrap_err().problem;
        assert!(
            err.contains("texture 0 \"t\" (4x2) has 0 mip levels, a full chain has 2"),
            "{err}"
        );
        g.textures[0] = Texture::with_mips("dot".into(), 1, 1, vec![9; 4], true, 4).0;
        assert!(g.textures[0].mips.is_empty());
        g.check_structure().unwrap();
    }

    #[test]
    fn a_variant_moving_a_varying_alpha_is_refused() {
        // Slot 1 ("leaf") is masked with texture 0, whose alpha varies.
        let mut g = with(0, 5);
        g.materials[5].base_color_tex_coord = 1;
        let err = g.variant_materials(Some("v")).unwrap_err();
        assert!(err.to_string().contains("texture coordinate set"), "{err}");
        let mut g = with(0, 5);
        g.materials[5].base_color_transform.rotation = 0.5;
        let err = g.variant_materials(Some("v")).unwrap_err();
        assert!(err.to_string().contains("texture transform"), "{err}");
        // Opaque materials may move their texture freely.
        let mut g = with(2, 1);
        g.materials[2].base_color_texture = Some(0);
        g.materials[2].base_color_transform.offset = [0.5, 0.0];
        g.variant_materials(Some("v")).unwrap();
    }
}
