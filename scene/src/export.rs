//! glTF 2.0 export of a scene, as one binary `.glb` file.
//!
//! The file holds the scene's rest pose (no animations or cameras):
//! - one glTF node per scene node, same order, names and parents, with the rest transform as
//!   `matrix` (omitted when it is the identity);
//! - one mesh with one triangle-list primitive per (node, material) group of triangles, in the
//!   order the groups first appear in triangle id order, triangles in ascending id order. A
//!   node with one group carries its mesh itself; a node with several gets one extra child
//!   node (no transform, named `node/material`) per group, appended after the scene's nodes;
//! - per primitive: `POSITION` (with min/max), `NORMAL` (left out for a group with a zero or
//!   non-unit normal, so readers compute their own), `TEXCOORD_0` for textured materials, and
//!   u16 indices where the group has at most 65,535 vertices, else u32;
//! - materials as metallic-roughness with base colour, metallic and roughness factors and the
//!   base-colour texture (its TEXCOORD_0, untransformed: the other texture slots, texture
//!   transforms and TEXCOORD_1 are not exported), alpha mode (and cutoff for `MASK`), double
//!   sidedness, emissive colour (through `KHR_materials_emissive_strength` when brighter
//!   than 1), `KHR_materials_transmission` for glass and `KHR_materials_clearcoat`'s factors;
//!   the extensions are listed in `extensionsUsed` when used, never required;
//! - every texture as an embedded PNG (sRGB texels stored as they are), linear filtering with
//!   mipmaps, repeat wrapping.
//!
//! Output is deterministic (the same scene gives the same bytes) and written atomically.

use std::path::{Path, PathBuf};

use serde_json::{json, Map, Value};
use trisort_format::{AlphaMode, Geometry, Material};

use crate::Scene;

/// Why a scene could not be exported.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The scene refers to something that does not exist or cannot be stored in glTF.
    #[error("{path}: cannot export the scene: {reason}")]
    InvalidScene {
        /// The file being written.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A texture could not be encoded as PNG.
    #[error("{path}: texture {texture} ({name:?}) could not be encoded as PNG: {source}")]
    Png {
        /// The file being written.
        path: PathBuf,
        /// Texture index.
        texture: usize,
        /// Texture name.
        name: String,
        /// The encoder's error.
        source: image::ImageError,
    },
    /// The binary chunk would exceed the 4 GiB that a GLB header can describe.
    #[error("{path}: the scene needs {bytes} bytes, more than a .glb file can hold (4 GiB)")]
    TooLarge {
        /// The file being written.
        path: PathBuf,
        /// Bytes needed.
        bytes: u64,
    },
    /// The JSON chunk could not be serialized.
    #[error("{path}: cannot serialize the glTF JSON: {source}")]
    Json {
        /// The file being written.
        path: PathBuf,
        /// The serializer's error.
        source: serde_json::Error,
    },
    /// Writing the file failed.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file being written.
        path: PathBuf,
        /// The I/O error (it names the file too).
        source: trisort_format::FormatError,
    },
}

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const TRIANGLES: u32 = 4;
const GLB_MAGIC: u32 = 0x4654_6C67;
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// Writes `scene` as a glTF 2.0 binary file at `path` (atomically: a temporary file renamed
/// over `path`). See the module documentation for what the file contains.
///
/// Errors name `path`: an inconsistent scene (an index out of range, a non-finite position, a
/// texture whose byte count does not match its size), a PNG encoding failure, a file over the
/// GLB limit of 4 GiB, or an I/O error.
pub fn export_glb(scene: &Scene, path: &Path) -> Result<(), ExportError> {
    let bytes = encode_glb(scene, path)?;
    trisort_format::container::write_bytes_atomic(path, &bytes).map_err(|source| {
        ExportError::Write {
            path: path.to_path_buf(),
            source,
        }
    })
}

/// The binary chunk under construction and the JSON objects describing it.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    /// Appends `data` as a buffer view (4-byte aligned) and returns its index.
    fn view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        pad4(&mut self.bin, 0);
        let mut view = json!({
            "buffer": 0,
            "byteOffset": self.bin.len(),
            "byteLength": data.len(),
        });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bin.extend_from_slice(data);
        self.views.push(view);
        self.views.len() - 1
    }

    /// Appends a float vector attribute of `N` components and returns its accessor index.
    fn attribute<const N: usize>(&mut self, values: &[[f32; N]], bounds: bool) -> usize {
        let bytes: Vec<u8> = values
            .iter()
            .flat_map(|v| v.iter().flat_map(|c| c.to_le_bytes()))
            .collect();
        let view = self.view(&bytes, Some(ARRAY_BUFFER));
        let kind = ["SCALAR", "VEC2", "VEC3", "VEC4"][N - 1];
        let mut accessor = json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": values.len(),
            "type": kind,
        });
        if bounds {
            let mut lo = [f32::INFINITY; N];
            let mut hi = [f32::NEG_INFINITY; N];
            for v in values {
                for k in 0..N {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
            accessor["min"] = json!(lo.as_slice());
            accessor["max"] = json!(hi.as_slice());
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Appends triangle indices (u16 when they fit) and returns their accessor index.
    fn indices(&mut self, indices: &[u32], vertex_count: usize) -> usize {
        let (bytes, component): (Vec<u8>, u32) = if vertex_count <= usize::from(u16::MAX) {
            (
                indices
                    .iter()
                    .flat_map(|&i| (i as u16).to_le_bytes())
                    .collect(),
                UNSIGNED_SHORT,
            )
        } else {
            (
                indices.iter().flat_map(|&i| i.to_le_bytes()).collect(),
                UNSIGNED_INT,
            )
        };
        let view = self.view(&bytes, Some(ELEMENT_ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": component,
            "count": indices.len(),
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }
}

/// Checks every index of the scene, so that encoding cannot go out of bounds.
fn validate(scene: &Scene, path: &Path) -> Result<(), ExportError> {
    let g = &scene.geometry;
    let invalid = |reason: String| ExportError::InvalidScene {
        path: path.to_path_buf(),
        reason,
    };
    for (t, tri) in g.triangles.iter().enumerate() {
        for &v in tri {
            if v as usize >= g.vertices.len() {
                return Err(invalid(format!(
                    "triangle {t} uses vertex {v}, but there are {} vertices",
                    g.vertices.len()
                )));
            }
        }
    }
    for (k, v) in g.vertices.iter().enumerate() {
        if v.material as usize >= g.materials.len() {
            return Err(invalid(format!(
                "vertex {k} uses material {}, but there are {}",
                v.material,
                g.materials.len()
            )));
        }
        if v.node as usize >= g.nodes.len() {
            return Err(invalid(format!(
                "vertex {k} belongs to node {}, but there are {}",
                v.node,
                g.nodes.len()
            )));
        }
        if !v
            .position
            .iter()
            .chain(&v.normal)
            .chain(&v.uv)
            .all(|c| c.is_finite())
        {
            return Err(invalid(format!("vertex {k} has a non-finite attribute")));
        }
    }
    for (k, m) in g.materials.iter().enumerate() {
        if let Some(t) = m.base_color_texture {
            if t as usize >= g.textures.len() {
                return Err(invalid(format!(
                    "material {k} ({:?}) uses texture {t}, but there are {}",
                    m.name,
                    g.textures.len()
                )));
            }
        }
    }
    for (k, n) in g.nodes.iter().enumerate() {
        if n.parent.is_some_and(|p| p as usize >= k) {
            return Err(invalid(format!(
                "node {k} ({:?}) has parent {:?}, which does not precede it",
                n.name, n.parent
            )));
        }
        if !n.rest.iter().all(|c| c.is_finite()) {
            return Err(invalid(format!(
                "node {k} ({:?}) has a non-finite transform",
                n.name
            )));
        }
    }
    Ok(())
}

/// The glTF JSON of one material; records the extensions it uses.
fn material_json(m: &Material, extensions: &mut Vec<&'static str>) -> Value {
    let mut pbr = json!({
        "baseColorFactor": m.base_color.map(|c| c.clamp(0.0, 1.0)),
        "metallicFactor": m.metallic.clamp(0.0, 1.0),
        "roughnessFactor": m.roughness.clamp(0.0, 1.0),
    });
    if let Some(t) = m.base_color_texture {
        pbr["baseColorTexture"] = json!({ "index": t });
    }
    let mut out = json!({ "pbrMetallicRoughness": pbr });
    if !m.name.is_empty() {
        out["name"] = json!(m.name);
    }
    match m.alpha_mode {
        AlphaMode::Opaque => {}
        AlphaMode::Mask => {
            out["alphaMode"] = json!("MASK");
            out["alphaCutoff"] = json!(m.alpha_cutoff.max(0.0));
        }
        AlphaMode::Blend => out["alphaMode"] = json!("BLEND"),
    }
    if m.double_sided {
        out["doubleSided"] = json!(true);
    }
    let mut ext = Map::new();
    let brightest = m.emissive.iter().fold(0.0f32, |a, &c| a.max(c));
    if brightest > 1.0 {
        out["emissiveFactor"] = json!(m.emissive.map(|c| (c / brightest).max(0.0)));
        ext.insert(
            "KHR_materials_emissive_strength".into(),
            json!({ "emissiveStrength": brightest }),
        );
    } else if brightest > 0.0 {
        out["emissiveFactor"] = json!(m.emissive.map(|c| c.max(0.0)));
    }
    if m.transmission > 0.0 {
        ext.insert(
            "KHR_materials_transmission".into(),
            json!({ "transmissionFactor": m.transmission.min(1.0) }),
        );
    }
    if m.clearcoat > 0.0 {
        ext.insert(
            "KHR_materials_clearcoat".into(),
            json!({
                "clearcoatFactor": m.clearcoat.min(1.0),
                "clearcoatRoughnessFactor": m.clearcoat_roughness.clamp(0.0, 1.0),
            }),
        );
    }
    for name in [
        "KHR_materials_emissive_strength",
        "KHR_materials_transmission",
        "KHR_materials_clearcoat",
    ] {
        if ext.contains_key(name) && !extensions.contains(&name) {
            extensions.push(name);
        }
    }
    if !ext.is_empty() {
        out["extensions"] = Value::Object(ext);
    }
    out
}

/// Triangles of one node and one material, in ascending id order: ((node, material), ids).
type Group = ((u32, u32), Vec<u32>);

/// Encodes the whole `.glb` file in memory. `path` only names the file in errors.
fn encode_glb(scene: &Scene, path: &Path) -> Result<Vec<u8>, ExportError> {
    validate(scene, path)?;
    let g = &scene.geometry;
    let mut b = Builder::default();
    let groups = groups(g);
    let meshes = meshes(&mut b, g, &groups);
    let (nodes, roots) = nodes(g, &groups);

    let mut extensions = Vec::new();
    let materials: Vec<Value> = g
        .materials
        .iter()
        .map(|m| material_json(m, &mut extensions))
        .collect();
    let (images, textures) = images(&mut b, g, path)?;

    let mut root = Map::new();
    root.insert(
        "asset".into(),
        json!({
            "version": "2.0",
            "generator": format!("trisort {}", trisort_format::TOOL_VERSION),
        }),
    );
    let put = |root: &mut Map<String, Value>, key: &str, list: Vec<Value>| {
        if !list.is_empty() {
            root.insert(key.into(), Value::Array(list));
        }
    };
    put(&mut root, "accessors", std::mem::take(&mut b.accessors));
    put(&mut root, "bufferViews", std::mem::take(&mut b.views));
    put(&mut root, "meshes", meshes);
    put(&mut root, "materials", materials);
    put(&mut root, "images", images);
    put(&mut root, "textures", textures.clone());
    if !textures.is_empty() {
        put(
            &mut root,
            "samplers",
            vec![json!({ "magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497 })],
        );
    }
    put(&mut root, "nodes", nodes);
    if !roots.is_empty() {
        put(&mut root, "scenes", vec![json!({ "nodes": roots })]);
        root.insert("scene".into(), json!(0));
    }
    put(
        &mut root,
        "extensionsUsed",
        extensions.iter().map(|e| json!(e)).collect(),
    );
    pad4(&mut b.bin, 0);
    if !b.bin.is_empty() {
        root.insert("buffers".into(), json!([{ "byteLength": b.bin.len() }]));
    }
    glb(Value::Object(root), &b.bin, path)
}

/// Triangles grouped by (node, material), groups in order of first appearance.
fn groups(g: &Geometry) -> Vec<Group> {
    let mut group_of: std::collections::HashMap<(u32, u32), usize> = Default::default();
    let mut groups: Vec<Group> = Vec::new();
    for (t, tri) in g.triangles.iter().enumerate() {
        let v = &g.vertices[tri[0] as usize];
        let key = (v.node, v.material);
        let k = *group_of.entry(key).or_insert_with(|| {
            groups.push((key, Vec::new()));
            groups.len() - 1
        });
        groups[k].1.push(t as u32);
    }
    groups
}

/// One mesh per group, its vertices and indices appended to the binary chunk.
fn meshes(b: &mut Builder, g: &Geometry, groups: &[Group]) -> Vec<Value> {
    let mut meshes = Vec::new();
    let mut remap = vec![u32::MAX; g.vertices.len()];
    for ((node, material), tris) in groups {
        let mut used: Vec<u32> = Vec::new();
        let mut indices = Vec::with_capacity(tris.len() * 3);
        for &t in tris {
            for v in g.triangles[t as usize] {
                if remap[v as usize] == u32::MAX {
                    remap[v as usize] = used.len() as u32;
                    used.push(v);
                }
                indices.push(remap[v as usize]);
            }
        }
        for &v in &used {
            remap[v as usize] = u32::MAX;
        }
        let verts = || used.iter().map(|&v| &g.vertices[v as usize]);
        let positions: Vec<[f32; 3]> = verts().map(|v| v.position).collect();
        let mut attributes = Map::new();
        attributes.insert("POSITION".into(), json!(b.attribute(&positions, true)));
        let unit = |n: &[f32; 3]| {
            let len2: f32 = n.iter().map(|c| c * c).sum();
            (len2 - 1.0).abs() < 1e-3
        };
        if verts().all(|v| unit(&v.normal)) {
            let normals: Vec<[f32; 3]> = verts().map(|v| v.normal).collect();
            attributes.insert("NORMAL".into(), json!(b.attribute(&normals, false)));
        }
        if g.materials[*material as usize].base_color_texture.is_some() {
            let uvs: Vec<[f32; 2]> = verts().map(|v| v.uv).collect();
            attributes.insert("TEXCOORD_0".into(), json!(b.attribute(&uvs, false)));
        }
        let indices = b.indices(&indices, used.len());
        meshes.push(json!({
            "name": format!("{}/{}", g.nodes[*node as usize].name,
                            g.materials[*material as usize].name),
            "primitives": [{
                "attributes": attributes,
                "indices": indices,
                "material": material,
                "mode": TRIANGLES,
            }],
        }));
    }
    meshes
}

/// The glTF nodes (the scene's, then one child per group for nodes with several groups) and
/// the root node indices.
fn nodes(g: &Geometry, groups: &[Group]) -> (Vec<Value>, Vec<usize>) {
    let mut nodes: Vec<Value> = g
        .nodes
        .iter()
        .map(|n| {
            let mut node = json!({ "name": n.name });
            if n.rest != glam::DMat4::IDENTITY.to_cols_array() {
                node["matrix"] = json!(n.rest);
            }
            node
        })
        .collect();
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); g.nodes.len()];
    for (k, n) in g.nodes.iter().enumerate() {
        if let Some(p) = n.parent {
            children[p as usize].push(k);
        }
    }
    let mut groups_per_node = vec![0usize; g.nodes.len()];
    for ((node, _), _) in groups {
        groups_per_node[*node as usize] += 1;
    }
    for (mesh, ((node, material), _)) in groups.iter().enumerate() {
        let node = *node as usize;
        if groups_per_node[node] == 1 {
            nodes[node]["mesh"] = json!(mesh);
        } else {
            children[node].push(nodes.len());
            nodes.push(json!({
                "name": format!("{}/{}", g.nodes[node].name, g.materials[*material as usize].name),
                "mesh": mesh,
            }));
        }
    }
    for (k, c) in children.iter().enumerate() {
        if !c.is_empty() {
            nodes[k]["children"] = json!(c);
        }
    }
    let roots: Vec<usize> = (0..g.nodes.len())
        .filter(|&k| g.nodes[k].parent.is_none())
        .collect();
    (nodes, roots)
}

/// Every texture as an embedded PNG image, and the glTF textures naming them.
fn images(
    b: &mut Builder,
    g: &Geometry,
    path: &Path,
) -> Result<(Vec<Value>, Vec<Value>), ExportError> {
    let mut images = Vec::new();
    let mut textures = Vec::new();
    for (k, t) in g.textures.iter().enumerate() {
        let png = encode_png(t).map_err(|source| ExportError::Png {
            path: path.to_path_buf(),
            texture: k,
            name: t.name.clone(),
            source,
        })?;
        let view = b.view(&png, None);
        let mut image = json!({ "bufferView": view, "mimeType": "image/png" });
        if !t.name.is_empty() {
            image["name"] = json!(t.name);
        }
        images.push(image);
        textures.push(json!({ "sampler": 0, "source": k }));
    }
    Ok((images, textures))
}

/// The GLB container: header, JSON chunk (space-padded) and binary chunk (when not empty).
fn glb(root: Value, bin: &[u8], path: &Path) -> Result<Vec<u8>, ExportError> {
    let mut json_bytes = serde_json::to_vec(&root).map_err(|source| ExportError::Json {
        path: path.to_path_buf(),
        source,
    })?;
    pad4(&mut json_bytes, b' ');
    let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin.len() };
    let total = 12 + 8 + json_bytes.len() as u64 + bin_chunk as u64;
    if total > u64::from(u32::MAX) {
        return Err(ExportError::TooLarge {
            path: path.to_path_buf(),
            bytes: total,
        });
    }
    let mut out = Vec::with_capacity(total as usize);
    for word in [
        GLB_MAGIC,
        2,
        total as u32,
        json_bytes.len() as u32,
        CHUNK_JSON,
    ] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&json_bytes);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
        out.extend_from_slice(bin);
    }
    debug_assert_eq!(out.len() as u64, total);
    Ok(out)
}

/// Pads `bytes` with `fill` to a multiple of 4 bytes (GLB chunk and buffer view alignment).
fn pad4(bytes: &mut Vec<u8>, fill: u8) {
    bytes.resize(bytes.len().next_multiple_of(4), fill);
}

/// Encodes a texture as PNG.
fn encode_png(t: &trisort_format::Texture) -> Result<Vec<u8>, image::ImageError> {
    use image::ImageEncoder;
    let expected = t.width as u64 * t.height as u64 * 4;
    if t.rgba8.len() as u64 != expected || t.width == 0 || t.height == 0 {
        return Err(image::ImageError::Parameter(
            image::error::ParameterError::from_kind(image::error::ParameterErrorKind::Generic(
                format!(
                    "{} bytes for {}×{} RGBA8 (needs {expected}, and a non-empty size)",
                    t.rgba8.len(),
                    t.width,
                    t.height
                ),
            )),
        ));
    }
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png).write_image(
        &t.rgba8,
        t.width,
        t.height,
        image::ExtendedColorType::Rgba8,
    )?;
    Ok(png)
}
