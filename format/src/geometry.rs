//! Scene geometry as the GPU sees it: vertices, triangles, materials, textures and nodes.

use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};

mod variants;

pub use variants::{MaterialVariant, VariantError};

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

/// A decoded texture: tightly packed RGBA8, rows top to bottom, with its mip chain; and,
/// in a baked file made with `--textures`, the same levels as GPU blocks ([`Texture::blocks`]),
/// which the file stores in place of the RGBA8 levels.
#[derive(Clone, Debug, PartialEq, Deserialize)]
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
    /// `max(1, height >> k)`, RGBA8), generated at import (`trisort_scene::mips`). Always the
    /// full chain ([`Texture::mip_count`] levels; empty only for a 1×1 texture):
    /// [`Geometry::check_structure`] requires it, and the GPU upload uses these levels as
    /// stored, so the file is the one source of every texture's mips.
    pub mips: Vec<Vec<u8>>,
    /// The levels block-compressed (`bake`/`merge --textures`): then [`Texture::rgba8`] and
    /// [`Texture::mips`] hold these blocks decoded, and a file stores the blocks alone
    /// (reading decodes them: [`Geometry::decode_blocks`]). `None`: RGBA8 only.
    pub blocks: Option<crate::blocks::TextureBlocks>,
}

/// A file stores a block-compressed texture's blocks and leaves its RGBA8 levels empty:
/// reading decodes them again ([`Geometry::decode_blocks`]).
impl Serialize for Texture {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let compressed = self.blocks.is_some();
        let none: &[u8] = &[];
        let no_mips: &[Vec<u8>] = &[];
        let mut st = s.serialize_struct("Texture", 7)?;
        st.serialize_field("name", &self.name)?;
        st.serialize_field("width", &self.width)?;
        st.serialize_field("height", &self.height)?;
        st.serialize_field("rgba8", if compressed { none } else { &self.rgba8 })?;
        st.serialize_field("srgb", &self.srgb)?;
        st.serialize_field("mips", if compressed { no_mips } else { &self.mips })?;
        st.serialize_field("blocks", &self.blocks)?;
        st.end()
    }
}

impl Texture {
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

impl Geometry {
    /// The material of triangle `t` (the material of its first vertex).
    pub fn triangle_material(&self, t: u32) -> u32 {
        self.vertices[self.triangles[t as usize][0] as usize].material
    }

    /// Whether triangle `t` needs a depth order: its material is `BLEND` or transmissive (the
    /// default pipeline's transparent pass, the triangles `presort` sorts). The others are
    /// drawn correctly in any order with the depth test.
    pub fn needs_order(&self, t: u32) -> bool {
        let m = &self.materials[self.triangle_material(t) as usize];
        m.alpha_mode == AlphaMode::Blend || m.transmission > 0.0
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
        self.check_materials()?;
        self.check_textures()?;
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

    /// [`Geometry::check_structure`] of the materials: finite factors; every texture slot
    /// naming an existing texture, texture coordinate set 0 or 1 and a finite transform.
    fn check_materials(&self) -> Result<(), crate::StructureError> {
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
        Ok(())
    }

    /// [`Geometry::check_structure`] of the textures: non-empty, with the right byte count for
    /// level 0 and for each level of the full mip chain down to 1×1.
    fn check_textures(&self) -> Result<(), crate::StructureError> {
        for (t, tex) in self.textures.iter().enumerate() {
            if tex.width == 0 || tex.height == 0 {
                return Err(crate::Part::Geometry.error(format!(
                    "texture {t} is empty ({}x{})",
                    tex.width, tex.height
                )));
            }
            if let Some(blocks) = &tex.blocks {
                blocks.check(tex.width, tex.height).map_err(|e| {
                    crate::Part::Geometry.error(format!("texture {t} {:?}: {e}", tex.name))
                })?;
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
        Ok(())
    }

    /// Per texture: whether its level-0 alpha decides visibility, as the recorder reads it
    /// (the base colour of a MASK or BLEND material, any of them, so any variant's too: cut
    /// and transparent fragments are discarded). What `--textures` must keep exact and what
    /// `verify` checks of a block-compressed texture.
    pub fn alpha_decides_visibility(&self) -> Vec<bool> {
        let mut reads = vec![false; self.textures.len()];
        for m in &self.materials {
            if m.alpha_mode == AlphaMode::Opaque {
                continue;
            }
            if let Some(r) = m.base_color_texture.and_then(|t| reads.get_mut(t as usize)) {
                *r = true;
            }
        }
        reads
    }

    /// Decodes every block-compressed texture whose RGBA8 levels are empty (as a file stores
    /// it) into [`Texture::rgba8`] and [`Texture::mips`], after checking its blocks
    /// ([`crate::blocks::TextureBlocks::check`]). What reading a file does before
    /// [`Geometry::check_structure`].
    pub fn decode_blocks(&mut self) -> Result<(), crate::StructureError> {
        for (t, tex) in self.textures.iter_mut().enumerate() {
            let Some(blocks) = &tex.blocks else { continue };
            if !tex.rgba8.is_empty() || !tex.mips.is_empty() {
                continue;
            }
            blocks.check(tex.width, tex.height).map_err(|e| {
                crate::Part::Geometry.error(format!("texture {t} {:?}: {e}", tex.name))
            })?;
            let mut levels =
                (0..blocks.levels.len()).map(|k| blocks.decode_level(tex.width, tex.height, k));
            tex.rgba8 = levels.next().unwrap_or_default();
            tex.mips = levels.collect();
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
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32) -> Vec<u8> {
        (0..w * h * 4).map(|i| (i * 37 % 251) as u8).collect()
    }

    /// A texture of `rgba8` with a full chain of mip levels of the right sizes, each texel a
    /// copy of level 0's first: `Geometry::check_structure` looks at the sizes only (the
    /// importer's chains come from `trisort_scene::mips`).
    pub(super) fn texture_of(name: &str, width: u32, height: u32, rgba8: Vec<u8>) -> Texture {
        let mips = (1..=Texture::mip_count(width, height) as u32)
            .map(|k| {
                let (w, h) = Texture::level_size(width, height, k);
                rgba8[..4].repeat((w * h) as usize)
            })
            .collect();
        Texture {
            name: name.into(),
            width,
            height,
            rgba8,
            srgb: true,
            mips,
            blocks: None,
        }
    }

    /// A valid geometry with one textured material using every slot.
    fn textured() -> Geometry {
        let t = texture_of("t", 4, 2, image(4, 2));
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
        g.textures[0] = texture_of("dot", 1, 1, vec![9; 4]);
        assert!(g.textures[0].mips.is_empty());
        g.check_structure().unwrap();
    }
}
