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

/// A material: the subset of glTF's metallic-roughness model that trisort renders.
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

/// A decoded texture: tightly packed RGBA8, rows top to bottom, colour in sRGB encoding.
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
    /// children, finite rest transforms. Returns the first problem found.
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
        }
    }
}
