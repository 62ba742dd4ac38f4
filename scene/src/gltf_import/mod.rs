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
//!   from the remaining root nodes in file order.
//!   [`Node::rest`](trisort_format::Node::rest) is the node's local matrix (its `matrix`, or
//!   translation · rotation · scale) in f64. Animations and cameras refer to the new indices.
//! - **Materials**: every material of the file at its own index, then one default material
//!   (glTF's defaults) when some primitive has none: base colour, metallic and roughness
//!   factors; base-colour, metallic-roughness, normal (with its scale), occlusion (with its
//!   strength) and emissive textures, each with its texture coordinate set and
//!   `KHR_texture_transform` (offset, rotation, scale and `texCoord` override, read from the
//!   reference's raw JSON; a malformed one is [`SceneError::Malformed`] naming the material; a
//!   set above 1 is noted and read as 0); alpha mode and cutoff, double-sidedness, emissive ×
//!   `KHR_materials_emissive_strength`, the `KHR_materials_transmission` factor and
//!   `KHR_materials_clearcoat`'s factor and roughness factor. What a material has that is not
//!   rendered (clearcoat textures, iridescence, sheen, the transmission texture, …) is named in
//!   one note per material; other extensions of the file get one note each.
//! - **Material variants** (`KHR_materials_variants`): per variant, the material each
//!   material slot shows ([`Geometry::variants`](trisort_format::Geometry::variants)). glTF
//!   maps variants per primitive; where primitives sharing a material map it differently, a
//!   primitive gets a copy of its material in a slot of its own (appended after the default
//!   material, in order of first use), so one table per variant says it all.
//! - **Textures**: every image a material slot uses, decoded (PNG, JPEG, WebP through
//!   `EXT_texture_webp`, KTX2 with Basis Universal ETC1S or UASTC data through
//!   `KHR_texture_basisu`, level 0 transcoded by the pure-Rust `basisu` crate, see `ktx2.rs`)
//!   to RGBA8, the texels as stored; a texture's extension image is preferred to its `source`
//!   (the fallback, which it may lack). Once per colour space it is used in (sRGB for base
//!   colour and emissive, linear for the others), in order of first use by the materials
//!   (slots in the order above), with its mip chain
//!   ([`texture_with_mips`](crate::mips::texture_with_mips); a KTX2 file's own levels are
//!   not read); an image wider or taller than 1024 is stored from its first mip level that
//!   fits, with a note giving the bytes.
//! - **Vertex attributes**: [`Vertex::uv`](trisort_format::Vertex::uv) is `TEXCOORD_0` and
//!   [`Vertex::uv1`](trisort_format::Vertex::uv1) `TEXCOORD_1`, each read where a texture slot
//!   of a material the primitive may show (its own or a variant's) samples that set, zero
//!   otherwise. [`Vertex::tangent`](trisort_format::Vertex::tangent) is read from `TANGENT`
//!   where such a material has a normal texture; a primitive without `TANGENT` gets MikkTSpace
//!   tangents (the `mikktspace` crate) from the normal texture's set, computed in the file's
//!   winding and local space before any winding flip and after flat-normal expansion; a vertex
//!   whose triangle corners get different tangents is copied, one copy per tangent.
//! - **Animations**: translation, rotation and scale channels with their times and flattened
//!   values (LINEAR, STEP, CUBICSPLINE); morph-weight channels are skipped with a note.
//! - **Cameras**: perspective cameras on nodes of the scene; orthographic ones are noted and
//!   skipped.
//! - **Compression and quantization**: quantized attributes (`KHR_mesh_quantization`: any
//!   component type, normalized or not, with gltfpack's dequantizing node transforms) and
//!   meshopt-compressed buffer views (`EXT_meshopt_compression`, `KHR_meshopt_compression`,
//!   decoded by meshoptimizer; their fallback buffers need no data), see `meshopt.rs`, and
//!   Draco-compressed primitives (`KHR_draco_mesh_compression`, decoded by the pure-Rust
//!   `draco-core` when a primitive of the scene is read), see `draco.rs`. A file whose
//!   `extensionsRequired` names any other extension than these, the two texture image ones,
//!   the transmission and the emissive-strength one is refused with [`SceneError::UnsupportedExtension`] naming it.
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
//! short buffers, images that cannot be read or decoded, malformed texture transforms and
//! clearcoat values; see [`SceneError`].
//! Meshes outside the imported scene are not read, so they cannot fail the import; all nodes,
//! materials, their images and animations are.
//!
//! `stats.materials` counts the file's materials (not the appended default one);
//! `stats.primitives` counts the triangle primitives of all meshes of the file, once per mesh.

mod accessors;
mod animations;
mod cameras;
mod container;
mod draco;
mod ktx2;
mod materials;
mod meshopt;
mod nodes;
mod primitives;
mod tangents;

use std::path::{Path, PathBuf};

use gltf::mesh::Mode;
use trisort_format::Geometry;

use crate::{Animation, Scene, SceneCamera, SceneError, SceneStats};

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
    load_slice_with_sources(bytes, file).map(|(scene, _)| scene)
}

/// Where an imported triangle comes from in the glTF file: the triangle of
/// [`Geometry::triangles`] with the same index is triangle `triangle` of primitive
/// `primitive` of mesh `mesh`, instanced by node `node`. All four are indices of the file
/// (`node` is the file's node index, not the reordered [`Geometry::nodes`] index); `triangle`
/// counts the primitive's triangles in index order (for strips and fans, in the order the
/// glTF specification derives them), before any winding flip.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TriangleSource {
    /// Mesh index in the file.
    pub mesh: u32,
    /// Primitive index within the mesh.
    pub primitive: u32,
    /// Triangle index within the primitive.
    pub triangle: u32,
    /// Node index in the file (the mesh instance).
    pub node: u32,
}

/// [`load`], and the source of every triangle of the scene's geometry (same length as
/// [`Geometry::triangles`], same order).
pub fn load_with_sources(path: &Path) -> Result<(Scene, Vec<TriangleSource>), SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    load_slice_with_sources(&bytes, path)
}

/// [`load_slice`], and the source of every triangle (see [`load_with_sources`]).
pub fn load_slice_with_sources(
    bytes: &[u8],
    file: &Path,
) -> Result<(Scene, Vec<TriangleSource>), SceneError> {
    let container::Parsed {
        doc,
        bin,
        compression,
        draco,
        placeholders,
        variants,
        variant_maps,
        variant_notes,
    } = container::parse(bytes, file)?;
    let mut importer = Importer {
        file: file.to_path_buf(),
        base: file.parent().map(Path::to_path_buf),
        doc: &doc,
        buffers: Vec::new(),
        compression,
        decoded: Vec::new(),
        draco,
        draco_floats: Default::default(),
        draco_indices: Default::default(),
        draco_placeholders: placeholders,
        variants,
        variant_maps,
        notes: variant_notes,
        sources: Vec::new(),
    };
    importer.load_buffers(bin)?;
    importer.run()
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

/// One import in progress: the file, its document and buffers, and the notes so far.
struct Importer<'d> {
    /// The file, for errors.
    file: PathBuf,
    /// Folder that relative URIs are resolved against.
    base: Option<PathBuf>,
    doc: &'d gltf::Document,
    /// Every buffer's bytes, by buffer index.
    buffers: Vec<Vec<u8>>,
    /// Meshopt-compressed buffer views and fallback buffers, as the JSON declares them.
    compression: meshopt::Compression,
    /// By buffer view index, the decoded bytes of a meshopt-compressed view (which stand for
    /// the view's bytes).
    decoded: Vec<Option<Vec<u8>>>,
    /// `KHR_draco_mesh_compression` primitives by `(mesh, primitive)`.
    draco: std::collections::BTreeMap<(usize, usize), draco::DracoPrimitive>,
    /// By accessor index, the decoded components of a Draco primitive's attribute (which
    /// stand for the accessor's data), filled as its primitive is read.
    draco_floats: std::collections::HashMap<usize, Vec<f32>>,
    /// By accessor index, the decoded indices of a Draco primitive.
    draco_indices: std::collections::HashMap<usize, Vec<u32>>,
    /// Accessors of Draco primitives without data of their own (see `container::Parsed`).
    draco_placeholders: std::collections::BTreeSet<usize>,
    /// Names of the file's material variants.
    variants: Vec<String>,
    /// Per primitive, the material each variant gives it.
    variant_maps: container::VariantMaps,
    /// Warnings and notes for [`Scene::notes`].
    notes: Vec<String>,
    /// Per imported triangle, where it comes from.
    sources: Vec<TriangleSource>,
}

impl<'d> Importer<'d> {
    fn malformed(&self, problem: String) -> SceneError {
        SceneError::Malformed {
            file: self.file.clone(),
            problem,
        }
    }

    /// Imports the document in this order, which is also the order of its errors and notes:
    /// nodes, materials (with their images), the geometry of the scene, animations, cameras,
    /// ignored extensions.
    fn run(mut self) -> Result<(Scene, Vec<TriangleSource>), SceneError> {
        let file_nodes: Vec<gltf::Node> = self.doc.nodes().collect();
        let (tree, nodes) = self.node_tree(&file_nodes)?;
        let materials = self.materials()?;
        let (geometry, zero_area_triangles) =
            self.geometry(&file_nodes, &tree, nodes, materials)?;
        let animations = self.animations(&tree.new_index)?;
        let cameras = self.cameras(&tree.order, &tree.in_scene, &file_nodes);
        self.note_ignored_extensions();

        let stats = stats(
            self.doc,
            &geometry,
            zero_area_triangles,
            &animations,
            &cameras,
        );
        let name = self
            .file
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        debug_assert_eq!(self.sources.len(), geometry.triangles.len());
        let scene = Scene {
            name,
            geometry,
            animations,
            cameras,
            stats,
            notes: self.notes,
            variants: self.variants,
            hash_cache: Default::default(),
        };
        Ok((scene, self.sources))
    }
}

/// The counts `inspect` reports (see the module documentation for what they count).
fn stats(
    doc: &gltf::Document,
    geometry: &Geometry,
    zero_area_triangles: u64,
    animations: &[Animation],
    cameras: &[SceneCamera],
) -> SceneStats {
    SceneStats {
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
    }
}
