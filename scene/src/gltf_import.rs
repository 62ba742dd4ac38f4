//! glTF 2.0 import: [`load`] turns a `.glb` or `.gltf` file into a [`Scene`].
//!
//! # What is imported
//!
//! - **Geometry**: every mesh instance of the default scene (scene 0 when the file names no
//!   default), instancing expanded: a mesh used by two nodes gives two sets of vertices and
//!   triangles. Positions and normals stay in the local space of the node that carries the mesh,
//!   and [`Vertex::node`](trisort_format::Vertex::node) is that node, so rigid animation moves
//!   its triangles. Triangle strips and fans become lists; points and lines are skipped with a
//!   note. Under a node whose *world* rest transform has a negative determinant, the winding of
//!   every triangle is flipped (its last two indices swapped) so that front faces stay
//!   counter-clockwise in world space. Normals come from the file (renormalised); a primitive
//!   without normals gets flat normals, as the glTF specification requires: each of its
//!   triangles gets three vertices of its own carrying its face normal.
//! - **Nodes**: *all* nodes of the file, reordered so that parents precede children: a
//!   depth-first pre-order walk (children in file order) from the scene's root nodes, then
//!   from the remaining root nodes in file order. [`Node::rest`] is the node's local matrix
//!   (its `matrix`, or translation · rotation · scale) in f64. Animations and cameras refer to
//!   the new indices.
//! - **Materials**: every material of the file at its own index, then one default material
//!   (glTF's defaults) when some primitive has none: base colour factor and texture, alpha mode
//!   and cutoff, double-sidedness, emissive × `KHR_materials_emissive_strength`, and the
//!   `KHR_materials_transmission` factor. Other extensions are ignored with one note each.
//! - **Textures**: only base-colour textures, decoded (PNG or JPEG) to RGBA8, one per image
//!   (two textures sharing an image share one [`Texture`]), in order of first use by the
//!   materials. [`Vertex::uv`](trisort_format::Vertex::uv) holds the texture coordinate set the
//!   material's base-colour texture names (`TEXCOORD_0` almost always; another set is noted) and
//!   is zero for untextured materials.
//! - **Animations**: translation, rotation and scale channels with their times and flattened
//!   values (LINEAR, STEP, CUBICSPLINE); morph-weight channels are skipped with a note.
//! - **Cameras**: perspective cameras on nodes of the scene; orthographic ones are noted and
//!   skipped.
//!
//! # Triangle ids
//!
//! A triangle's index in [`Geometry::triangles`] is its id. Ids are assigned in this order:
//! nodes in the order of [`Geometry::nodes`] (depth-first scene order, see above) restricted
//! to nodes of the scene; within a node, the primitives of its mesh in file order; within a
//! primitive, triangles in index order (for strips and fans, in the order the specification
//! derives them). The same file always gives the same ids.
//!
//! # Errors
//!
//! No file should make the importer panic, and no `catch_unwind` hides one: the GLB container
//! and every accessor are parsed and bounds-checked here. The `gltf` crate is used for JSON
//! parsing, validation and document navigation only: its accessor readers and GLB parser can
//! panic on hostile data and are not used, and where its validation leaves gaps that its
//! navigation then unwraps (POSITION indices, animation channel targets, image sources, camera
//! parameters, in gltf 1.4.1) the JSON is checked or read directly. The tests mutate every byte
//! of a GLB and every number and member of a rich document to hold this.
//!
//! Errors: a skin on a node of the scene, morph targets on a mesh of the scene, NaN or infinite
//! positions, node cycles or nodes with two parents, accessors outside their data, missing or
//! short buffers, and base-colour images that cannot be read or decoded; see [`SceneError`].
//! Meshes outside the imported scene are not read, so they cannot fail the import; all nodes,
//! materials, base-colour images and animations are.
//!
//! `stats.materials` counts the file's materials (not the appended default one);
//! `stats.primitives` counts the triangle primitives of all meshes of the file, once per mesh.

use std::borrow::Cow;
use std::collections::hash_map::Entry;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use glam::{DMat4, DQuat, DVec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use gltf::Semantic;
use trisort_format::{AlphaMode, Geometry, Material, Node, Texture, Vertex};

use crate::{
    Animation, Channel, Interpolation, Property, Scene, SceneCamera, SceneError, SceneStats,
};

/// An accessor without a buffer view holds zeros (plus sparse values); its `count` is then not
/// backed by any data, so it is capped to keep a hostile header from allocating unbounded memory.
const MAX_VIEWLESS_ELEMENTS: usize = 1 << 24;

/// Extensions whose content the importer uses.
const HANDLED_EXTENSIONS: &[&str] = &[
    "KHR_materials_transmission",
    "KHR_materials_emissive_strength",
    "KHR_mesh_quantization",
];

/// Imports a `.glb` or `.gltf` file (external buffers and images are resolved relative to its
/// folder).
///
/// The scene is named after the file stem. See the [module documentation](self) for what is
/// imported, the node and triangle orders, and the errors.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    load_slice(&bytes, path)
}

/// Imports glTF (binary or JSON) from memory. `file` is where the bytes came from: it names the
/// scene (its stem) and the errors, and its folder resolves relative URIs. Same semantics as
/// [`load`].
pub fn load_slice(bytes: &[u8], file: &Path) -> Result<Scene, SceneError> {
    let (json, bin) = split_container(bytes, file)?;
    let json = json.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(json);
    let root = gltf::json::Root::from_slice(json).map_err(|e| SceneError::Malformed {
        file: file.to_path_buf(),
        problem: format!("invalid JSON: {e}"),
    })?;
    // gltf-json's validation indexes the POSITION accessor before checking that it exists
    // (gltf-json 1.4.1, mesh.rs); check it first so a dangling index is an error, not a panic.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &prim.attributes {
                if index.value() >= root.accessors.len() {
                    return Err(SceneError::Malformed {
                        file: file.to_path_buf(),
                        problem: format!(
                            "mesh {m} primitive {p}: attribute {semantic:?} names accessor {}, \
                             the file has {}",
                            index.value(),
                            root.accessors.len()
                        ),
                    });
                }
            }
        }
    }
    let doc = gltf::Document::from_json(root).map_err(|e| SceneError::Malformed {
        file: file.to_path_buf(),
        problem: e.to_string(),
    })?;
    let mut importer = Importer {
        file: file.to_path_buf(),
        base: file.parent().map(Path::to_path_buf),
        doc: &doc,
        buffers: Vec::new(),
        notes: Vec::new(),
    };
    importer.load_buffers(bin)?;
    importer.run()
}

/// Splits a file into its JSON text and, for GLB, its binary chunk.
fn split_container<'a>(
    bytes: &'a [u8],
    file: &Path,
) -> Result<(&'a [u8], Option<&'a [u8]>), SceneError> {
    let malformed = |problem: String| SceneError::Malformed {
        file: file.to_path_buf(),
        problem,
    };
    let is_glb_name = file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if !bytes.starts_with(b"glTF") {
        if is_glb_name {
            return Err(malformed(
                "not a binary glTF file (it does not start with the magic \"glTF\")".into(),
            ));
        }
        return Ok((bytes, None));
    }
    if bytes.len() < 12 {
        return Err(malformed(format!(
            "truncated: {} bytes, shorter than the 12-byte GLB header",
            bytes.len()
        )));
    }
    let word =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let version = word(4);
    if version != 2 {
        return Err(malformed(format!("GLB version {version}, expected 2")));
    }
    let length = word(8) as usize;
    if length > bytes.len() {
        return Err(malformed(format!(
            "truncated: the GLB header declares {length} bytes, the file has {}",
            bytes.len()
        )));
    }
    if length < 12 {
        return Err(malformed(format!(
            "the GLB header declares a length of {length} bytes, less than the header itself"
        )));
    }
    let mut json = None;
    let mut bin = None;
    let mut at = 12;
    while at < length {
        if length - at < 8 {
            return Err(malformed(format!("truncated chunk header at byte {at}")));
        }
        let chunk_len = word(at) as usize;
        let kind = &bytes[at + 4..at + 8];
        let start = at + 8;
        if chunk_len > length - start {
            return Err(malformed(format!(
                "truncated: the chunk at byte {at} declares {chunk_len} bytes, {} remain",
                length - start
            )));
        }
        let data = &bytes[start..start + chunk_len];
        match (json.is_none(), kind) {
            (true, b"JSON") => json = Some(data),
            (true, _) => return Err(malformed("the first GLB chunk is not JSON".into())),
            (false, b"BIN\0") if bin.is_none() => bin = Some(data),
            // Unknown chunks must be ignored (glTF 2.0 § 4.4.3.1).
            _ => {}
        }
        at = start + chunk_len;
    }
    match json {
        Some(json) => Ok((json, bin)),
        None => Err(malformed("the GLB file has no JSON chunk".into())),
    }
}

/// `kind index "name"`, or `kind index` for unnamed objects.
fn label(kind: &str, index: usize, name: Option<&str>) -> String {
    match name {
        Some(name) => format!("{kind} {index} {name:?}"),
        None => format!("{kind} {index}"),
    }
}

fn mesh_label(mesh: &gltf::Mesh) -> String {
    label("mesh", mesh.index(), mesh.name())
}

fn node_label(node: &gltf::Node) -> String {
    label("node", node.index(), node.name())
}

/// Standard base64 (also accepting the URL-safe alphabet), padding optional, whitespace
/// ignored. `None` on any other character.
fn base64_decode(text: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    let mut acc: u32 = 0;
    let mut bits = 0;
    for &c in text.as_bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            b' ' | b'\n' | b'\r' | b'\t' => continue,
            _ => return None,
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// Decodes `%XX` escapes of a relative URI. `None` for a bad escape or non-UTF-8 result.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes.get(i + 1..i + 3)?;
            let hex = std::str::from_utf8(hex).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Reads the bytes a URI names: a base64 `data:` URI, or a path relative to `base`.
/// The error is a sentence without the glTF file's name.
fn read_uri(uri: &str, base: Option<&Path>) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err("data: URI is not base64-encoded".into());
        };
        return base64_decode(payload).ok_or_else(|| "data: URI holds invalid base64".into());
    }
    let scheme = uri.split(['/', '\\']).next().unwrap_or("");
    if scheme.contains(':') {
        return Err(format!(
            "unsupported URI scheme in {uri:?} (only relative paths and data: URIs)"
        ));
    }
    let rel = percent_decode(uri).ok_or_else(|| format!("URI {uri:?} has a bad %-escape"))?;
    let path = match base {
        Some(base) => base.join(rel),
        None => PathBuf::from(rel),
    };
    std::fs::read(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}

/// Converts one component of an accessor to f32, applying `normalized` integer scaling.
fn float_reader(kind: DataType, normalized: bool) -> fn(&[u8]) -> f32 {
    match (kind, normalized) {
        (DataType::F32, _) => |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::U8, false) => |b| f32::from(b[0]),
        (DataType::U8, true) => |b| f32::from(b[0]) / 255.0,
        (DataType::I8, false) => |b| f32::from(b[0] as i8),
        (DataType::I8, true) => |b| (f32::from(b[0] as i8) / 127.0).max(-1.0),
        (DataType::U16, false) => |b| f32::from(u16::from_le_bytes([b[0], b[1]])),
        (DataType::U16, true) => |b| f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
        (DataType::I16, false) => |b| f32::from(i16::from_le_bytes([b[0], b[1]])),
        (DataType::I16, true) => {
            |b| (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
        }
        (DataType::U32, false) => |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
        (DataType::U32, true) => |b| {
            (f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])) / f64::from(u32::MAX)) as f32
        },
    }
}

/// Reads one unsigned integer component (u8, u16 or u32).
fn index_reader(kind: DataType) -> Option<fn(&[u8]) -> u32> {
    match kind {
        DataType::U8 => Some(|b| u32::from(b[0])),
        DataType::U16 => Some(|b| u32::from(u16::from_le_bytes([b[0], b[1]]))),
        DataType::U32 => Some(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        _ => None,
    }
}

/// The triangles of one mesh primitive, read once and instanced per node.
struct PrimitiveData {
    positions: Vec<[f32; 3]>,
    /// Unit normals from the file; `None` means flat normals are generated.
    normals: Option<Vec<[f32; 3]>>,
    /// Texture coordinates of the material's base-colour set, if textured.
    uvs: Option<Vec<[f32; 2]>>,
    triangles: Vec<[u32; 3]>,
    zero_area: u64,
    material: u32,
}

struct Importer<'d> {
    file: PathBuf,
    base: Option<PathBuf>,
    doc: &'d gltf::Document,
    buffers: Vec<Vec<u8>>,
    notes: Vec<String>,
}

impl<'d> Importer<'d> {
    fn malformed(&self, problem: String) -> SceneError {
        SceneError::Malformed {
            file: self.file.clone(),
            problem,
        }
    }

    fn load_buffers(&mut self, bin: Option<&[u8]>) -> Result<(), SceneError> {
        let mut bin = bin;
        for buffer in self.doc.buffers() {
            let err = |problem: String| SceneError::Buffer {
                file: self.file.clone(),
                buffer: buffer.index(),
                problem,
            };
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => bin
                    .take()
                    .ok_or_else(|| {
                        err(
                            "has no URI and there is no (unused) GLB binary chunk to hold it"
                                .into(),
                        )
                    })?
                    .to_vec(),
                gltf::buffer::Source::Uri(uri) => {
                    read_uri(uri, self.base.as_deref()).map_err(err)?
                }
            };
            if data.len() < buffer.length() {
                return Err(err(format!(
                    "holds {} bytes, {} declared (truncated?)",
                    data.len(),
                    buffer.length()
                )));
            }
            self.buffers.push(data);
        }
        Ok(())
    }

    /// The bytes of a buffer view, checked against its buffer.
    fn view_bytes(&self, view: &gltf::buffer::View) -> Result<&[u8], String> {
        let data = &self.buffers[view.buffer().index()];
        let start = view.offset();
        start
            .checked_add(view.length())
            .and_then(|end| data.get(start..end))
            .ok_or_else(|| {
                format!(
                    "buffer view {} (bytes {start}+{}) exceeds buffer {} of {} bytes",
                    view.index(),
                    view.length(),
                    view.buffer().index(),
                    data.len()
                )
            })
    }

    /// Reads every component of an accessor (flattened, `count × components`), including
    /// sparse substitution, with bounds checks. `convert` decodes one component.
    fn read_components<T: Copy + Default>(
        &self,
        accessor: &gltf::Accessor,
        usage: &str,
        convert: impl Fn(&[u8]) -> T,
    ) -> Result<Vec<T>, SceneError> {
        let err = |problem: String| SceneError::Accessor {
            file: self.file.clone(),
            accessor: accessor.index(),
            usage: usage.to_string(),
            problem,
        };
        let comps = accessor.dimensions().multiplicity();
        let csize = accessor.data_type().size();
        let elem = comps * csize;
        let count = accessor.count();
        let mut out: Vec<T>;
        match accessor.view() {
            Some(view) => {
                let data = self.view_bytes(&view).map_err(err)?;
                let stride = view.stride().unwrap_or(elem);
                if stride < elem {
                    return Err(err(format!(
                        "byte stride {stride} is smaller than the element size {elem}"
                    )));
                }
                let start = accessor.offset();
                if count > 0 {
                    let end = (count - 1)
                        .checked_mul(stride)
                        .and_then(|x| x.checked_add(start))
                        .and_then(|x| x.checked_add(elem));
                    if end.is_none_or(|end| end > data.len()) {
                        return Err(err(format!(
                            "{count} elements from byte {start} (stride {stride}) exceed buffer \
                             view {} of {} bytes",
                            view.index(),
                            data.len()
                        )));
                    }
                }
                out = Vec::with_capacity(count * comps);
                for i in 0..count {
                    let at = start + i * stride;
                    for c in 0..comps {
                        out.push(convert(&data[at + c * csize..at + (c + 1) * csize]));
                    }
                }
            }
            None => {
                if count > MAX_VIEWLESS_ELEMENTS {
                    return Err(err(format!(
                        "{count} elements without a buffer view (more than {MAX_VIEWLESS_ELEMENTS})"
                    )));
                }
                out = vec![T::default(); count * comps];
            }
        }
        if let Some(sparse) = accessor.sparse() {
            let n = sparse.count();
            let indices = sparse.indices();
            let read_index = match indices.index_type() {
                gltf::accessor::sparse::IndexType::U8 => index_reader(DataType::U8),
                gltf::accessor::sparse::IndexType::U16 => index_reader(DataType::U16),
                gltf::accessor::sparse::IndexType::U32 => index_reader(DataType::U32),
            }
            .ok_or_else(|| err("bad sparse index type".into()))?;
            let isize = match indices.index_type() {
                gltf::accessor::sparse::IndexType::U8 => 1,
                gltf::accessor::sparse::IndexType::U16 => 2,
                gltf::accessor::sparse::IndexType::U32 => 4,
            };
            let idata = self.view_bytes(&indices.view()).map_err(err)?;
            let values = sparse.values();
            let vdata = self.view_bytes(&values.view()).map_err(err)?;
            let fits = |data: &[u8], offset: usize, size: usize| {
                n.checked_mul(size)
                    .and_then(|x| x.checked_add(offset))
                    .is_some_and(|end| end <= data.len())
            };
            if !fits(idata, indices.offset(), isize) || !fits(vdata, values.offset(), elem) {
                return Err(err(format!("{n} sparse entries exceed their buffer views")));
            }
            for k in 0..n {
                let at = indices.offset() + k * isize;
                let target = read_index(&idata[at..at + isize]) as usize;
                if target >= count {
                    return Err(err(format!(
                        "sparse index {target} is out of range (count {count})"
                    )));
                }
                let at = values.offset() + k * elem;
                for c in 0..comps {
                    out[target * comps + c] = convert(&vdata[at + c * csize..at + (c + 1) * csize]);
                }
            }
        }
        Ok(out)
    }

    /// Reads a float accessor of one of the given shapes; returns the flattened values.
    fn read_floats(
        &self,
        accessor: &gltf::Accessor,
        usage: &str,
        shapes: &[Dimensions],
    ) -> Result<Vec<f32>, SceneError> {
        if !shapes.contains(&accessor.dimensions()) {
            return Err(SceneError::Accessor {
                file: self.file.clone(),
                accessor: accessor.index(),
                usage: usage.to_string(),
                problem: format!(
                    "type {:?}, expected one of {shapes:?}",
                    accessor.dimensions()
                ),
            });
        }
        let convert = float_reader(accessor.data_type(), accessor.normalized());
        self.read_components(accessor, usage, convert)
    }

    fn read_vec3(
        &self,
        accessor: &gltf::Accessor,
        usage: &str,
    ) -> Result<Vec<[f32; 3]>, SceneError> {
        let flat = self.read_floats(accessor, usage, &[Dimensions::Vec3])?;
        Ok(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    }

    fn read_indices(&self, accessor: &gltf::Accessor, usage: &str) -> Result<Vec<u32>, SceneError> {
        let convert = index_reader(accessor.data_type())
            .filter(|_| accessor.dimensions() == Dimensions::Scalar)
            .ok_or_else(|| SceneError::Accessor {
                file: self.file.clone(),
                accessor: accessor.index(),
                usage: usage.to_string(),
                problem: format!(
                    "indices must be unsigned scalar integers, found {:?} {:?}",
                    accessor.data_type(),
                    accessor.dimensions()
                ),
            })?;
        self.read_components(accessor, usage, convert)
    }

    /// Parents of every node, rejecting nodes with two parents.
    fn parents(&self) -> Result<Vec<Option<usize>>, SceneError> {
        let mut parent = vec![None; self.doc.nodes().len()];
        for node in self.doc.nodes() {
            for child in node.children() {
                if let Some(other) = parent[child.index()] {
                    return Err(self.malformed(format!(
                        "{} is a child of both node {other} and node {} (nodes must form trees)",
                        node_label(&child),
                        node.index()
                    )));
                }
                parent[child.index()] = Some(node.index());
            }
        }
        Ok(parent)
    }

    fn run(mut self) -> Result<Scene, SceneError> {
        let doc = self.doc;
        let file_nodes: Vec<gltf::Node> = doc.nodes().collect();
        let parent = self.parents()?;
        let scene = doc.default_scene().or_else(|| doc.scenes().next());
        if doc.scenes().len() > 1 {
            if let Some(s) = &scene {
                self.notes.push(format!(
                    "the file has {} scenes; imported {}",
                    doc.scenes().len(),
                    label("scene", s.index(), s.name())
                ));
            }
        }
        let listed: Vec<usize> = scene
            .as_ref()
            .map(|s| s.nodes().map(|n| n.index()).collect())
            .unwrap_or_default();
        if scene.is_none() {
            self.notes
                .push("the file has no scene: no geometry imported".to_string());
        }

        // Depth-first pre-order from the scene's roots, then the other roots.
        let mut order: Vec<usize> = Vec::with_capacity(file_nodes.len());
        let mut new_index = vec![u32::MAX; file_nodes.len()];
        let roots = listed
            .iter()
            .copied()
            .filter(|&n| parent[n].is_none())
            .chain((0..file_nodes.len()).filter(|&n| parent[n].is_none()));
        for root in roots {
            if new_index[root] != u32::MAX {
                continue;
            }
            let mut stack = vec![root];
            while let Some(n) = stack.pop() {
                new_index[n] = order.len() as u32;
                order.push(n);
                let children: Vec<usize> = file_nodes[n].children().map(|c| c.index()).collect();
                stack.extend(children.into_iter().rev());
            }
        }
        if let Some(n) = (0..file_nodes.len()).find(|&n| new_index[n] == u32::MAX) {
            return Err(self.malformed(format!(
                "{} cannot be reached from any root: the node hierarchy has a cycle",
                node_label(&file_nodes[n])
            )));
        }
        let mut in_scene = vec![false; file_nodes.len()];
        for &n in &listed {
            in_scene[n] = true;
        }
        for &n in &order {
            if let Some(p) = parent[n] {
                in_scene[n] |= in_scene[p];
            }
        }

        let mut nodes = Vec::with_capacity(order.len());
        for &n in &order {
            let node = &file_nodes[n];
            nodes.push(Node {
                name: node.name().unwrap_or("").to_string(),
                parent: parent[n].map(|p| new_index[p]),
                rest: self.rest_matrix(node)?.to_cols_array(),
            });
        }
        let world = trisort_format::world_transforms(&nodes, &[]);

        // Materials and their base-colour textures.
        let mut materials = Vec::new();
        let mut textures = Vec::new();
        let mut texture_of_image: HashMap<usize, u32> = HashMap::new();
        let mut uv_set = Vec::new();
        for m in doc.materials() {
            let (material, set) = self.material(&m, &mut textures, &mut texture_of_image)?;
            materials.push(material);
            uv_set.push(set);
        }
        let mut default_material: Option<u32> = None;

        // Geometry.
        let mut geometry = Geometry {
            nodes,
            ..Geometry::default()
        };
        // Each primitive is read once (`None`: skipped, noted once) and instanced per node.
        let mut primitive_cache: HashMap<(usize, usize), Option<PrimitiveData>> = HashMap::new();
        let mut skipped: BTreeMap<&'static str, Vec<String>> = BTreeMap::new();
        let mut zero_area_triangles = 0u64;
        for &n in &order {
            let node = &file_nodes[n];
            if !in_scene[n] {
                continue;
            }
            if let Some(skin) = node.skin() {
                return Err(SceneError::Skinned {
                    file: self.file.clone(),
                    node: node_label(node),
                    skin: skin.index(),
                });
            }
            let Some(mesh) = node.mesh() else { continue };
            let new_node = new_index[n];
            let flip = world[new_node as usize].determinant() < 0.0;
            for prim in mesh.primitives() {
                let key = (mesh.index(), prim.index());
                if let Entry::Vacant(slot) = primitive_cache.entry(key) {
                    let kind = match prim.mode() {
                        Mode::Points => Some("points"),
                        Mode::Lines | Mode::LineLoop | Mode::LineStrip => Some("lines"),
                        _ => None,
                    };
                    if let Some(kind) = kind {
                        skipped.entry(kind).or_default().push(format!(
                            "{} primitive {}",
                            mesh_label(&mesh),
                            prim.index()
                        ));
                        slot.insert(None);
                        continue;
                    }
                    let material = match prim.material().index() {
                        Some(i) => i as u32,
                        None => *default_material.get_or_insert_with(|| {
                            materials.push(Material {
                                name: "default".to_string(),
                                ..Material::default()
                            });
                            uv_set.push(None);
                            (materials.len() - 1) as u32
                        }),
                    };
                    slot.insert(self.primitive(
                        &mesh,
                        &prim,
                        material,
                        uv_set[material as usize],
                    )?);
                }
                let Some(Some(data)) = primitive_cache.get(&key) else {
                    continue;
                };
                zero_area_triangles += data.zero_area;
                instance(&mut geometry, data, new_node, flip).map_err(|problem| {
                    SceneError::Unsupported {
                        file: self.file.clone(),
                        problem,
                    }
                })?;
            }
        }
        for (kind, list) in &skipped {
            let shown: Vec<&str> = list.iter().take(4).map(String::as_str).collect();
            let more = if list.len() > shown.len() {
                ", …"
            } else {
                ""
            };
            self.notes.push(format!(
                "skipped {} {kind} primitive(s) (only triangles are drawn): {}{more}",
                list.len(),
                shown.join(", ")
            ));
        }
        geometry.materials = materials;
        geometry.textures = textures;

        let animations = self.animations(&new_index)?;
        let cameras = self.cameras(&order, &in_scene, &file_nodes);

        for ext in doc.extensions_used() {
            if !HANDLED_EXTENSIONS.contains(&ext) {
                let what = match ext {
                    "KHR_texture_transform" => {
                        "textures are sampled with untransformed coordinates"
                    }
                    "KHR_materials_variants" => "each primitive keeps its default material",
                    "KHR_materials_volume" => "glass thickness and attenuation are not modelled",
                    _ => "not supported",
                };
                self.notes.push(format!("extension {ext} ignored: {what}"));
            }
        }

        let stats = SceneStats {
            triangles: geometry.triangles.len() as u64,
            zero_area_triangles,
            meshes: doc.meshes().len() as u64,
            primitives: doc
                .meshes()
                .flat_map(|m| m.primitives())
                .filter(|p| {
                    matches!(
                        p.mode(),
                        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
                    )
                })
                .count() as u64,
            nodes: geometry.nodes.len() as u64,
            materials: doc.materials().len() as u64,
            textures: geometry.textures.len() as u64,
            animations: animations.len() as u64,
            cameras: cameras.len() as u64,
        };
        let name = self
            .file
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Ok(Scene {
            name,
            geometry,
            animations,
            cameras,
            stats,
            notes: self.notes,
        })
    }

    /// A node's local rest transform in f64.
    fn rest_matrix(&self, node: &gltf::Node) -> Result<DMat4, SceneError> {
        let m = match node.transform() {
            gltf::scene::Transform::Matrix { matrix } => {
                DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)))
            }
            gltf::scene::Transform::Decomposed {
                translation,
                rotation,
                scale,
            } => {
                let q = DQuat::from_array(rotation.map(f64::from));
                if q.length().is_nan() || q.length() <= 0.0 {
                    return Err(self.malformed(format!(
                        "{} has an invalid rotation {rotation:?}",
                        node_label(node)
                    )));
                }
                DMat4::from_scale_rotation_translation(
                    DVec3::from_array(scale.map(f64::from)),
                    q.normalize(),
                    DVec3::from_array(translation.map(f64::from)),
                )
            }
        };
        if !m.is_finite() {
            return Err(self.malformed(format!("{} has a non-finite transform", node_label(node))));
        }
        Ok(m)
    }

    /// Converts a material; returns it with the texture coordinate set its base-colour texture
    /// samples (`None` when untextured). Decodes its texture on first use.
    fn material(
        &mut self,
        m: &gltf::Material,
        textures: &mut Vec<Texture>,
        texture_of_image: &mut HashMap<usize, u32>,
    ) -> Result<(Material, Option<u32>), SceneError> {
        let pbr = m.pbr_metallic_roughness();
        let name = m.name().unwrap_or("").to_string();
        let mut texture = None;
        let mut set = None;
        if let Some(info) = pbr.base_color_texture() {
            let image = info.texture().source();
            let slot = match texture_of_image.get(&image.index()) {
                Some(&slot) => slot,
                None => {
                    textures.push(self.decode_image(&image)?);
                    let slot = (textures.len() - 1) as u32;
                    texture_of_image.insert(image.index(), slot);
                    slot
                }
            };
            texture = Some(slot);
            set = Some(info.tex_coord());
            if info.tex_coord() != 0 {
                self.notes.push(format!(
                    "{} samples its base-colour texture with TEXCOORD_{}; imported as the \
                     vertex uv",
                    label("material", m.index().unwrap_or(0), m.name()),
                    info.tex_coord()
                ));
            }
        }
        let strength = m.emissive_strength().unwrap_or(1.0);
        let material = Material {
            name,
            base_color: pbr.base_color_factor(),
            base_color_texture: texture,
            alpha_mode: match m.alpha_mode() {
                gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                gltf::material::AlphaMode::Mask => AlphaMode::Mask,
                gltf::material::AlphaMode::Blend => AlphaMode::Blend,
            },
            alpha_cutoff: m.alpha_cutoff().unwrap_or(0.5),
            double_sided: m.double_sided(),
            emissive: m.emissive_factor().map(|c| c * strength),
            transmission: m.transmission().map_or(0.0, |t| t.transmission_factor()),
        };
        Ok((material, set))
    }

    /// Loads and decodes an image to RGBA8.
    fn decode_image(&self, image: &gltf::Image) -> Result<Texture, SceneError> {
        // Read the JSON directly: `gltf::Image::source` unwraps a missing mimeType or URI.
        let json = &self.doc.as_json().images[image.index()];
        let (bytes, uri): (Cow<[u8]>, Option<&str>) = match (&json.buffer_view, &json.uri) {
            (Some(view), _) => {
                let view = self.doc.views().nth(view.value()).ok_or_else(|| {
                    self.image_error(image, "", "dangling buffer view".to_string())
                })?;
                (
                    Cow::Borrowed(
                        self.view_bytes(&view)
                            .map_err(|p| self.image_error(image, "", p))?,
                    ),
                    None,
                )
            }
            (None, Some(uri)) => (
                Cow::Owned(
                    read_uri(uri, self.base.as_deref())
                        .map_err(|p| self.image_error(image, uri, p))?,
                ),
                Some(uri.as_str()),
            ),
            (None, None) => {
                return Err(self.image_error(
                    image,
                    "",
                    "has neither a URI nor a buffer view".to_string(),
                ))
            }
        };
        let name = image
            .name()
            .or(uri.filter(|u| !u.starts_with("data:")))
            .map_or_else(|| format!("image {}", image.index()), str::to_string);
        let decoded = ::image::load_from_memory(&bytes)
            .map_err(|e| self.image_error(image, &name, format!("cannot decode: {e}")))?
            .into_rgba8();
        Ok(Texture {
            name,
            width: decoded.width(),
            height: decoded.height(),
            rgba8: decoded.into_raw(),
        })
    }

    fn image_error(&self, image: &gltf::Image, uri: &str, problem: String) -> SceneError {
        let name = image
            .name()
            .unwrap_or(if uri.starts_with("data:") { "" } else { uri });
        SceneError::Image {
            file: self.file.clone(),
            image: image.index(),
            name: name.to_string(),
            problem,
        }
    }

    /// Reads one triangle primitive; `None` (with a note) when it has no positions.
    fn primitive(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
        material: u32,
        uv_set: Option<u32>,
    ) -> Result<Option<PrimitiveData>, SceneError> {
        let where_ = format!("{} primitive {}", mesh_label(mesh), prim.index());
        if prim.morph_targets().next().is_some() {
            return Err(SceneError::MorphTargets {
                file: self.file.clone(),
                mesh: mesh_label(mesh),
                primitive: prim.index(),
            });
        }
        let Some(pos_acc) = prim.get(&Semantic::Positions) else {
            self.notes
                .push(format!("skipped {where_}: it has no POSITION attribute"));
            return Ok(None);
        };
        let positions = self.read_vec3(&pos_acc, &format!("{where_} POSITION"))?;
        if let Some(vertex) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(SceneError::NonFinitePosition {
                file: self.file.clone(),
                mesh: mesh_label(mesh),
                primitive: prim.index(),
                accessor: pos_acc.index(),
                vertex,
            });
        }
        let n = positions.len();
        let count_mismatch = |acc: &gltf::Accessor, what: &str, got: usize| SceneError::Accessor {
            file: self.file.clone(),
            accessor: acc.index(),
            usage: format!("{where_} {what}"),
            problem: format!("{got} elements, POSITION has {n}"),
        };
        let normals = match prim.get(&Semantic::Normals) {
            Some(acc) => {
                let normals = self.read_vec3(&acc, &format!("{where_} NORMAL"))?;
                if normals.len() != n {
                    return Err(count_mismatch(&acc, "NORMAL", normals.len()));
                }
                Some(normals.into_iter().map(unit).collect())
            }
            None => None,
        };
        let uvs = match uv_set {
            None => None,
            Some(set) => match prim.get(&Semantic::TexCoords(set)) {
                Some(acc) => {
                    let what = format!("TEXCOORD_{set}");
                    let flat =
                        self.read_floats(&acc, &format!("{where_} {what}"), &[Dimensions::Vec2])?;
                    if flat.len() != 2 * n {
                        return Err(count_mismatch(&acc, &what, flat.len() / 2));
                    }
                    Some(flat.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
                }
                None => {
                    self.notes.push(format!(
                        "{where_} has a textured material but no TEXCOORD_{set}; its uv is zero"
                    ));
                    None
                }
            },
        };
        let indices: Vec<u32> = match prim.indices() {
            Some(acc) => {
                let usage = format!("{where_} indices");
                let indices = self.read_indices(&acc, &usage)?;
                if let Some(k) = indices.iter().position(|&i| i as usize >= n) {
                    return Err(SceneError::Accessor {
                        file: self.file.clone(),
                        accessor: acc.index(),
                        usage,
                        problem: format!(
                            "index {} at position {k} is out of range ({n} vertices)",
                            indices[k]
                        ),
                    });
                }
                indices
            }
            None => (0..n as u32).collect(),
        };
        let triangles = match prim.mode() {
            Mode::Triangles => {
                let rest = indices.len() % 3;
                if rest != 0 {
                    self.notes.push(format!(
                        "{where_}: {} indices is not a multiple of 3; the last {rest} ignored",
                        indices.len(),
                    ));
                }
                indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]])
                    .collect()
            }
            Mode::TriangleStrip => strip_triangles(&indices),
            Mode::TriangleFan => fan_triangles(&indices),
            _ => Vec::new(),
        };
        let zero_area = triangles
            .iter()
            .filter(|t| is_zero_area(&positions, t))
            .count() as u64;
        Ok(Some(PrimitiveData {
            positions,
            normals,
            uvs,
            triangles,
            zero_area,
            material,
        }))
    }

    /// Animations with their target nodes remapped to the new node order.
    fn animations(&mut self, new_index: &[u32]) -> Result<Vec<Animation>, SceneError> {
        let mut animations = Vec::new();
        let mut morph_channels = 0;
        for anim in self.doc.animations() {
            let mut channels = Vec::new();
            // Channel targets are not checked by gltf-json's validation (1.4.1) and
            // `gltf::animation::Target` unwraps them: check them on the JSON first.
            let json = &self.doc.as_json().animations[anim.index()];
            for (ch, json_ch) in anim.channels().zip(&json.channels) {
                let name = label("animation", anim.index(), anim.name());
                let target_node = json_ch.target.node.value();
                if target_node >= new_index.len() {
                    return Err(self.malformed(format!(
                        "{name} channel {} targets node {target_node}, which does not exist",
                        ch.index()
                    )));
                }
                let gltf::json::validation::Checked::Valid(path) = json_ch.target.path else {
                    return Err(self.malformed(format!(
                        "{name} channel {} has an unknown target path",
                        ch.index()
                    )));
                };
                let (property, shape) = match path {
                    gltf::animation::Property::Translation => {
                        (Property::Translation, Dimensions::Vec3)
                    }
                    gltf::animation::Property::Rotation => (Property::Rotation, Dimensions::Vec4),
                    gltf::animation::Property::Scale => (Property::Scale, Dimensions::Vec3),
                    gltf::animation::Property::MorphTargetWeights => {
                        morph_channels += 1;
                        continue;
                    }
                };
                let sampler = ch.sampler();
                let interpolation = match sampler.interpolation() {
                    gltf::animation::Interpolation::Linear => Interpolation::Linear,
                    gltf::animation::Interpolation::Step => Interpolation::Step,
                    gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
                };
                let usage = format!(
                    "{} channel {}",
                    label("animation", anim.index(), anim.name()),
                    ch.index()
                );
                let input = sampler.input();
                let times =
                    self.read_floats(&input, &format!("{usage} input"), &[Dimensions::Scalar])?;
                let output = sampler.output();
                let values = self.read_floats(&output, &format!("{usage} output"), &[shape])?;
                let per_key = shape.multiplicity()
                    * if interpolation == Interpolation::CubicSpline {
                        3
                    } else {
                        1
                    };
                let bad =
                    |acc: &gltf::Accessor, what: &str, problem: String| SceneError::Accessor {
                        file: self.file.clone(),
                        accessor: acc.index(),
                        usage: format!("{usage} {what}"),
                        problem,
                    };
                if times.is_empty() {
                    return Err(bad(&input, "input", "no keyframes".into()));
                }
                if !times.iter().all(|t| t.is_finite()) || times.windows(2).any(|w| w[1] < w[0]) {
                    return Err(bad(
                        &input,
                        "input",
                        "key times must be finite and ascending".into(),
                    ));
                }
                if values.len() != times.len() * per_key {
                    return Err(bad(
                        &output,
                        "output",
                        format!(
                            "{} values for {} keys, expected {per_key} per key",
                            values.len(),
                            times.len()
                        ),
                    ));
                }
                if !values.iter().all(|v| v.is_finite()) {
                    return Err(bad(&output, "output", "non-finite key value".into()));
                }
                channels.push(Channel {
                    node: new_index[target_node],
                    property,
                    interpolation,
                    times,
                    values,
                });
            }
            animations.push(Animation {
                name: anim.name().unwrap_or("").to_string(),
                channels,
            });
        }
        if morph_channels > 0 {
            self.notes.push(format!(
                "skipped {morph_channels} morph-weight animation channel(s) (no morph targets)"
            ));
        }
        Ok(animations)
    }

    /// Perspective cameras on nodes of the scene, in node order.
    fn cameras(
        &mut self,
        order: &[usize],
        in_scene: &[bool],
        file_nodes: &[gltf::Node],
    ) -> Vec<SceneCamera> {
        let mut cameras = Vec::new();
        for (new, &n) in order.iter().enumerate() {
            let node = &file_nodes[n];
            let Some(camera) = node.camera().filter(|_| in_scene[n]) else {
                continue;
            };
            // Read the JSON directly: `gltf::Camera::projection` unwraps a missing
            // perspective object when the type says perspective.
            let json = &self.doc.as_json().cameras[camera.index()];
            let perspective = matches!(
                json.type_,
                gltf::json::validation::Checked::Valid(gltf::json::camera::Type::Perspective)
            );
            match json.perspective.as_ref().filter(|_| perspective) {
                Some(p) => cameras.push(SceneCamera {
                    name: camera.name().unwrap_or("").to_string(),
                    node: new as u32,
                    yfov: f64::from(p.yfov),
                    znear: f64::from(p.znear),
                    zfar: p.zfar.map(f64::from),
                    aspect: p.aspect_ratio.map(f64::from),
                }),
                None => self.notes.push(format!(
                    "skipped {} on {}: {}",
                    label("camera", camera.index(), camera.name()),
                    node_label(node),
                    if perspective {
                        "no perspective parameters"
                    } else {
                        "orthographic cameras are not supported"
                    }
                )),
            }
        }
        cameras
    }
}

/// The normal scaled to unit length; zero when it is zero or not finite.
fn unit(n: [f32; 3]) -> [f32; 3] {
    let v = glam::Vec3::from(n);
    let len = v.length();
    if len > 0.0 && len.is_finite() {
        (v / len).into()
    } else {
        [0.0; 3]
    }
}

/// Triangles of a strip: triangle i is (v_i, v_{i+1+i%2}, v_{i+2-i%2}) (glTF 2.0 § 3.7.2.1).
fn strip_triangles(v: &[u32]) -> Vec<[u32; 3]> {
    (0..v.len().saturating_sub(2))
        .map(|i| [v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]])
        .collect()
}

/// Triangles of a fan: triangle i is (v_{i+1}, v_{i+2}, v_0) (glTF 2.0 § 3.7.2.1).
fn fan_triangles(v: &[u32]) -> Vec<[u32; 3]> {
    (0..v.len().saturating_sub(2))
        .map(|i| [v[i + 1], v[i + 2], v[0]])
        .collect()
}

/// Unnormalised face normal in f64: exact zero iff the triangle has zero area (the products of
/// f32 differences are exact in f64).
fn face_cross(positions: &[[f32; 3]], t: &[u32; 3]) -> DVec3 {
    let p = |i: u32| glam::Vec3::from(positions[i as usize]).as_dvec3();
    let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
    (b - a).cross(c - a)
}

/// A triangle with a repeated index or exactly zero area in local space.
fn is_zero_area(positions: &[[f32; 3]], t: &[u32; 3]) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || face_cross(positions, t) == DVec3::ZERO
}

/// Appends one instance of a primitive for `node`, flipping the winding when `flip`.
fn instance(
    geometry: &mut Geometry,
    data: &PrimitiveData,
    node: u32,
    flip: bool,
) -> Result<(), String> {
    let base = geometry.vertices.len();
    let added = match data.normals {
        Some(_) => data.positions.len(),
        None => 3 * data.triangles.len(),
    };
    if base + added > u32::MAX as usize {
        return Err("more than 2^32 vertices after expanding instances".to_string());
    }
    let vertex = |i: u32, normal: [f32; 3]| Vertex {
        position: data.positions[i as usize],
        normal,
        uv: data.uvs.as_ref().map_or([0.0; 2], |uv| uv[i as usize]),
        material: data.material,
        node,
    };
    let order = |t: [u32; 3]| if flip { [t[0], t[2], t[1]] } else { t };
    match &data.normals {
        Some(normals) => {
            geometry
                .vertices
                .extend((0..data.positions.len() as u32).map(|i| vertex(i, normals[i as usize])));
            let base = base as u32;
            geometry.triangles.extend(
                data.triangles
                    .iter()
                    .map(|t| order([t[0] + base, t[1] + base, t[2] + base])),
            );
        }
        None => {
            for t in &data.triangles {
                let n = face_cross(&data.positions, t)
                    .normalize_or_zero()
                    .as_vec3()
                    .into();
                let first = geometry.vertices.len() as u32;
                geometry.vertices.extend(t.iter().map(|&i| vertex(i, n)));
                geometry
                    .triangles
                    .push(order([first, first + 1, first + 2]));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_known_text() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64_decode("aGVsbG8h").unwrap(), b"hello!");
        assert_eq!(base64_decode("aGk").unwrap(), b"hi");
        assert!(base64_decode("a*b").is_none());
    }

    #[test]
    fn percent_escapes_decode() {
        assert_eq!(percent_decode("a%20b.bin").unwrap(), "a b.bin");
        assert!(percent_decode("bad%2").is_none());
        assert!(percent_decode("%FF").is_none());
    }

    #[test]
    fn strips_alternate_winding_and_fans_pivot() {
        assert_eq!(
            strip_triangles(&[0, 1, 2, 3, 4]),
            vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]
        );
        assert_eq!(fan_triangles(&[0, 1, 2, 3]), vec![[1, 2, 0], [2, 3, 0]]);
        assert!(strip_triangles(&[0, 1]).is_empty());
    }

    #[test]
    fn glb_header_lies_are_errors() {
        let file = Path::new("x.glb");
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(4u32.to_le_bytes());
        assert!(split_container(&glb, file).is_err());
        glb[8..12].copy_from_slice(&1000u32.to_le_bytes());
        assert!(split_container(&glb, file).is_err());
        glb[8..12].copy_from_slice(&12u32.to_le_bytes());
        assert!(split_container(&glb, file).is_err(), "no JSON chunk");
    }
}
