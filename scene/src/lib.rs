//! Scenes for trisort: glTF 2.0 import, the procedural demo car and glTF export.
//!
//! This crate exists apart from `recorder` so that each stage pulls in only what it uses:
//! `paths` needs scenes (node names, animations, bounds) but no GPU, and the merger and player
//! must not depend on `gltf`.
#![deny(missing_docs)]

use std::sync::OnceLock;

use serde::{Deserialize, Serialize};
use trisort_format::Geometry;

/// A scene ready for recording: the full geometry plus what paths need (animations, cameras)
/// and what `inspect` reports.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Display name (file stem, or "demo car").
    pub name: String,
    /// All triangles of the scene; a triangle's index is its scene id.
    pub geometry: Geometry,
    /// Animations of node transforms.
    pub animations: Vec<Animation>,
    /// Cameras placed in the scene.
    pub cameras: Vec<SceneCamera>,
    /// Counts for `inspect`.
    pub stats: SceneStats,
    /// Warnings and notes from import (skipped primitives, ignored extensions, …).
    pub notes: Vec<String>,
    /// Names of the file's material variants (`KHR_materials_variants`), in file order; an
    /// unnamed variant is `""`. Empty without the extension. Their material tables are
    /// [`Geometry::variants`](trisort_format::Geometry::variants), which players apply.
    pub variants: Vec<String>,
    /// [`Scene::hash`], computed on its first call. Leave it empty (`Default::default()`,
    /// which `..Scene::default()` gives) when building a scene by hand or from another
    /// scene's parts, and change `geometry` after a `hash()` only through
    /// [`Scene::geometry_mut`], which empties it.
    pub hash_cache: HashCache,
}

/// The cached value of [`Scene::hash`]: empty until the first call. Public only so that
/// scenes can still be built with struct literals; it has nothing to set.
#[derive(Clone, Debug, Default)]
pub struct HashCache(OnceLock<trisort_format::Hash>);

/// Which node property an animation channel drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Property {
    /// Translation (3 values per key).
    Translation,
    /// Rotation as a unit quaternion x, y, z, w (4 values per key).
    Rotation,
    /// Scale (3 values per key).
    Scale,
}

/// Keyframe interpolation of an animation channel (glTF sampler interpolation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Interpolation {
    /// Linear (slerp for rotations).
    Linear,
    /// Step: hold the previous key.
    Step,
    /// Cubic Hermite spline; values hold (in-tangent, value, out-tangent) per key.
    CubicSpline,
}

/// One animated property of one node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Channel {
    /// Target node index.
    pub node: u32,
    /// Animated property.
    pub property: Property,
    /// Interpolation.
    pub interpolation: Interpolation,
    /// Key times in seconds, ascending.
    pub times: Vec<f32>,
    /// Key values, flattened: per key 3 or 4 components, ×3 for cubic splines.
    pub values: Vec<f32>,
}

/// A named set of channels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Animation {
    /// Name (may be empty).
    pub name: String,
    /// Channels.
    pub channels: Vec<Channel>,
}

/// A perspective camera attached to a node (its view is the inverse of the node's world
/// transform; it looks down the node's −Z).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneCamera {
    /// Camera name (may be empty).
    pub name: String,
    /// Node carrying the camera.
    pub node: u32,
    /// Vertical field of view in radians.
    pub yfov: f64,
    /// Near plane.
    pub znear: f64,
    /// Far plane, `None` for infinite.
    pub zfar: Option<f64>,
    /// Aspect ratio if the file fixes one.
    pub aspect: Option<f64>,
}

/// Counts reported by `trisort inspect` for a scene.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SceneStats {
    /// Triangles after expanding instances, strips and fans.
    pub triangles: u64,
    /// Triangles with zero area (kept, counted).
    pub zero_area_triangles: u64,
    /// Meshes in the file.
    pub meshes: u64,
    /// Primitives in the file (triangle primitives counted once per mesh, not per instance).
    pub primitives: u64,
    /// Nodes in the file.
    pub nodes: u64,
    /// Materials in the file.
    pub materials: u64,
    /// Textures decoded.
    pub textures: u64,
    /// Animations.
    pub animations: u64,
    /// Cameras.
    pub cameras: u64,
}

impl Scene {
    /// A stable hash of the geometry (vertices, triangles, materials, textures, nodes): the
    /// scene identity stored in recordings and baked files.
    ///
    /// Computed once, on the first call, and kept in [`Scene::hash_cache`]; later calls return
    /// the kept value. Builds with debug assertions (the test suite) recompute it on every
    /// later call and panic if `geometry` changed behind the cache's back.
    pub fn hash(&self) -> trisort_format::Hash {
        if let Some(&hash) = self.hash_cache.0.get() {
            debug_assert!(
                hash == geometry_hash(&self.geometry),
                "scene {:?}: geometry changed after Scene::hash without Scene::geometry_mut",
                self.name
            );
            return hash;
        }
        *self
            .hash_cache
            .0
            .get_or_init(|| geometry_hash(&self.geometry))
    }

    /// The geometry, to change it: empties the cache of [`Scene::hash`] so that the next call
    /// hashes the changed geometry.
    pub fn geometry_mut(&mut self) -> &mut Geometry {
        self.hash_cache = HashCache::default();
        &mut self.geometry
    }

    /// World-space axis-aligned bounding box of all triangles at the rest pose, as
    /// (min, max). Returns `None` for a scene without triangles.
    pub fn bounds(&self) -> Option<(glam::DVec3, glam::DVec3)> {
        let g = &self.geometry;
        if g.triangles.is_empty() {
            return None;
        }
        let world = trisort_format::world_transforms(&g.nodes, &[]);
        let mut lo = glam::DVec3::splat(f64::INFINITY);
        let mut hi = glam::DVec3::splat(f64::NEG_INFINITY);
        let mut used = vec![false; g.vertices.len()];
        for t in &g.triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        for (v, _) in g.vertices.iter().zip(&used).filter(|(_, u)| **u) {
            let p =
                world[v.node as usize].transform_point3(glam::Vec3::from(v.position).as_dvec3());
            lo = lo.min(p);
            hi = hi.max(p);
        }
        Some((lo, hi))
    }

    /// Index of the first node with this name.
    pub fn node_by_name(&self, name: &str) -> Option<u32> {
        self.geometry
            .nodes
            .iter()
            .position(|n| n.name == name)
            .map(|i| i as u32)
    }
}

/// The hash behind [`Scene::hash`]: BLAKE3 of the geometry's postcard encoding.
///
/// The bytes are the geometry's postcard encoding as format 6 laid it out, textures without
/// their `blocks` (format 7's block-compressed levels, which a scene never has: they are a
/// baked file's way of storing its texels), so the hash of a scene is the one files baked
/// before format 7 hold.
fn geometry_hash(geometry: &Geometry) -> trisort_format::Hash {
    /// A texture's fields before format 7.
    #[derive(serde::Serialize)]
    struct TextureBytes<'a> {
        name: &'a str,
        width: u32,
        height: u32,
        rgba8: &'a [u8],
        srgb: bool,
        mips: &'a [Vec<u8>],
    }
    let g = geometry;
    let textures: Vec<TextureBytes> = (g.textures.iter())
        .map(|t| TextureBytes {
            name: &t.name,
            width: t.width,
            height: t.height,
            rgba8: &t.rgba8,
            srgb: t.srgb,
            mips: &t.mips,
        })
        .collect();
    let fields = (
        &g.vertices,
        &g.triangles,
        &g.materials,
        &textures,
        &g.nodes,
        &g.variants,
    );
    let bytes = postcard::to_stdvec(&fields).expect("geometry serializes");
    trisort_format::hash_bytes(&bytes)
}

pub mod demo_car;
pub mod environment;
mod error;
pub mod export;
pub mod gltf_import;
pub mod mips;

pub use demo_car::{demo_car, DEFAULT_TRIANGLES, DOOR_NODE, DOOR_WINDOW_NODE};
pub use environment::{load_hdr, EnvironmentError};
pub use error::SceneError;
pub use export::{export_glb, ExportError};
pub use gltf_import::{load, load_slice, load_with_sources, TriangleSource};

#[cfg(test)]
mod tests {
    use super::*;

    fn one_node_scene() -> Scene {
        let mut scene = Scene::default();
        scene.geometry.nodes.push(trisort_format::Node {
            name: "n".into(),
            parent: None,
            rest: glam::DMat4::IDENTITY.to_cols_array(),
        });
        scene
    }

    #[test]
    fn hash_is_cached_and_geometry_mut_empties_the_cache() {
        let mut scene = one_node_scene();
        let first = scene.hash();
        assert_eq!(first, geometry_hash(&scene.geometry));
        assert_eq!(scene.hash_cache.0.get(), Some(&first));
        assert_eq!(scene.hash(), first);
        assert_eq!(scene.clone().hash(), first);
        scene.geometry_mut().nodes[0].name = "m".into();
        assert!(scene.hash_cache.0.get().is_none());
        let second = scene.hash();
        assert_ne!(second, first);
        assert_eq!(second, geometry_hash(&scene.geometry));
    }

    #[cfg(debug_assertions)]
    #[test]
    #[should_panic(expected = "geometry changed after Scene::hash")]
    fn a_stale_hash_panics_in_debug_builds() {
        let mut scene = one_node_scene();
        scene.hash();
        scene.geometry.nodes[0].name = "m".into();
        scene.hash();
    }
}
