//! Scene geometry as the GPU sees it: vertices, triangles, materials, textures and nodes.

use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};

/// One vertex, laid out as the vertex buffer of every pipeline (recorder, player, reference).
///
/// `position` and `normal` are in the local space of `node`: the node whose (possibly animated)
/// world transform moves this vertex. All three vertices of a triangle share `material` and
/// `node`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable, Serialize, Deserialize)]
pub struct Vertex {
    /// Position in the node's local space.
    pub position: [f32; 3],
    /// Unit normal in the node's local space (zero when the source had none and it could not
    /// be derived).
    pub normal: [f32; 3],
    /// Texture coordinate (TEXCOORD_0); zero for untextured materials.
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
    /// where the source has none.
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
    /// `max(1, height >> k)`, RGBA8), generated at import; empty for a texture without mips.
    pub mips: Vec<Vec<u8>>,
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
    /// finite material factors, textures present with the right byte count, parents before
    /// children, finite rest transforms, variants mapping every material slot to an existing
    /// material. Returns the first problem found.
    pub fn check_structure(&self) -> Result<(), String> {
        let nv = self.vertices.len() as u64;
        for (k, t) in self.triangles.iter().enumerate() {
            if t.iter().any(|&v| v as u64 >= nv) {
                return Err(format!("triangle {k} refers to a vertex beyond {nv}"));
            }
        }
        for (k, v) in self.vertices.iter().enumerate() {
            if v.material as usize >= self.materials.len() || v.node as usize >= self.nodes.len() {
                return Err(format!("vertex {k} refers to a missing material or node"));
            }
            if !v.position.iter().all(|x| x.is_finite()) {
                return Err(format!("vertex {k} has a non-finite position"));
            }
        }
        for (k, m) in self.materials.iter().enumerate() {
            let factors = m
                .base_color
                .iter()
                .chain(&m.emissive)
                .chain([&m.alpha_cutoff, &m.transmission]);
            if !factors.into_iter().all(|x| x.is_finite()) {
                return Err(format!("material {k} has a non-finite factor"));
            }
            if let Some(t) = m.base_color_texture {
                let Some(tex) = self.textures.get(t as usize) else {
                    return Err(format!("material {k} refers to missing texture {t}"));
                };
                if tex.rgba8.len() as u64 != tex.width as u64 * tex.height as u64 * 4 {
                    return Err(format!("texture {t} has the wrong number of bytes"));
                }
            }
        }
        for (k, v) in self.variants.iter().enumerate() {
            if v.materials.len() != self.materials.len() {
                return Err(format!(
                    "material variant {k} maps {} material slots, the geometry has {}",
                    v.materials.len(),
                    self.materials.len()
                ));
            }
            if let Some(m) = v
                .materials
                .iter()
                .find(|&&m| m as usize >= self.materials.len())
            {
                return Err(format!(
                    "material variant {k} refers to missing material {m}"
                ));
            }
        }
        for (k, n) in self.nodes.iter().enumerate() {
            if n.parent.is_some_and(|p| p as usize >= k) {
                return Err(format!("node {k} has a parent that does not precede it"));
            }
            if !n.rest.iter().all(|x| x.is_finite()) {
                return Err(format!("node {k}'s rest transform is not finite"));
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
    /// and for non-glass `Mask` and `Blend` materials the alpha factor and the base-colour
    /// texture's alpha channel. Colour, emissive and opaque textures may change freely.
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
        None
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
        let texture = |alpha: u8, rgb: u8| Texture {
            name: String::new(),
            width: 2,
            height: 1,
            rgba8: vec![rgb, rgb, rgb, alpha, 0, 0, 0, 255],
            srgb: true,
            mips: Vec::new(),
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
            .contains("maps 8 material slots"));
        let mut g = with(0, 1);
        g.variants[0].materials[0] = 9;
        assert!(g
            .check_structure()
            .unwrap_err()
            .contains("missing material 9"));
    }
}
