//! Small hand-built scenes with known answers, for tests, examples and documentation.
//!
//! The convention: one root node at the identity, the camera at (or near) the origin looking
//! down −Z with y ∈ [−1, 1] filling the view at distance 1 ([`frame_at`]), and axis-aligned
//! quads facing +Z ([`quad`]) at negative z, so that which triangle covers which pixel, and in
//! which order, can be worked out by hand. Materials are flat colours, double-sided, blended
//! when their alpha is below 1 ([`material`]).
//!
//! Tests compare images byte for byte against answers computed from these scenes, so the
//! values written here (vertex order, normals, uv, material fields, camera) are part of what
//! those tests check: change them only together with the tests.
//!
//! ```
//! use glam::DVec3;
//! use trisort_testkit::fixtures::{frame_at, material, quad, scene};
//!
//! // A red half-transparent quad in front of an opaque grey one.
//! let mut g = scene(vec![material([0.9, 0.1, 0.1], 0.5), material([0.5; 3], 1.0)]);
//! quad(&mut g, [-0.5, 0.5], [-0.5, 0.5], [-2.0, -2.0], 0);
//! quad(&mut g, [-1.0, 1.0], [-1.0, 1.0], [-3.0, -3.0], 1);
//! assert_eq!(g.triangles.len(), 4);
//! let frame = frame_at(DVec3::ZERO);
//! assert!(frame.camera.eye().length() < 1e-12);
//! ```

use glam::{DMat4, DVec3};

use trisort_format::{
    AlphaMode, Baked, Camera, DeviceInfo, DrawIndexedIndirectArgs, FrameState, FrameWindow,
    Geometry, Material, MergeInfo, MergeStats, Node, RecordSettings, Vertex,
};

/// Adds a quad spanning `x = [x0, x1]` and `y = [y0, y1]`, at depth z0 along x = x0 and z1
/// along x = x1 (`z = [z0, z1]`): corners (x0, y0, z0), (x1, y0, z1), (x1, y1, z1), (x0, y1,
/// z0), facing +Z, as four shared vertices (normal +Z, uv 0, node 0) and two triangles,
/// (0, 1, 2) and (0, 2, 3), counter-clockwise seen from +Z. With `z0 ≠ z1` the quad is tilted
/// about the y axis.
///
/// The triangles get the next two scene ids (2k and 2k + 1 for the k-th quad of a scene built
/// from quads alone).
pub fn quad(g: &mut Geometry, x: [f32; 2], y: [f32; 2], z: [f32; 2], material: u32) {
    let ([x0, x1], [y0, y1], [z0, z1]) = (x, y, z);
    let base = g.vertices.len() as u32;
    for (x, y, z) in [(x0, y0, z0), (x1, y0, z1), (x1, y1, z1), (x0, y1, z0)] {
        g.vertices.push(Vertex {
            position: [x, y, z],
            normal: [0.0, 0.0, 1.0],
            uv: [0.0; 2],
            material,
            node: 0,
            tangent: [0.0; 4],
            uv1: [0.0; 2],
        });
    }
    g.triangles.push([base, base + 1, base + 2]);
    g.triangles.push([base, base + 2, base + 3]);
}

/// [`quad`] in the plane z: spans [x0, x1] × [y0, y1] at depth `z`, facing +Z.
pub fn flat_quad(g: &mut Geometry, x0: f32, x1: f32, y0: f32, y1: f32, z: f32, material: u32) {
    quad(g, [x0, x1], [y0, y1], [z, z], material);
}

/// The corners of [`quad`]'s two triangles, in the same order and winding:
/// `[(x0, y0, z0), (x1, y0, z1), (x1, y1, z1)]` and `[(x0, y0, z0), (x1, y1, z1), (x0, y1, z0)]`.
pub fn quad_triangles(x0: f32, x1: f32, y0: f32, y1: f32, z0: f32, z1: f32) -> [[[f32; 3]; 3]; 2] {
    [
        [[x0, y0, z0], [x1, y0, z1], [x1, y1, z1]],
        [[x0, y0, z0], [x1, y1, z1], [x0, y1, z0]],
    ]
}

/// Adds a triangle with three vertices of its own (normal +Z, uv 0, node 0), in the given
/// order (counter-clockwise seen from the camera to face it).
pub fn tri(g: &mut Geometry, corners: [[f32; 3]; 3], material: u32) {
    let base = g.vertices.len() as u32;
    for position in corners {
        g.vertices.push(Vertex {
            position,
            normal: [0.0, 0.0, 1.0],
            uv: [0.0; 2],
            material,
            node: 0,
            tangent: [0.0; 4],
            uv1: [0.0; 2],
        });
    }
    g.triangles.push([base, base + 1, base + 2]);
}

/// [`quad`]'s two triangles added with [`tri`]: the same corners, winding and ids, but six
/// vertices, none shared.
pub fn split_quad(g: &mut Geometry, x: [f32; 2], y: [f32; 2], z: [f32; 2], material: u32) {
    let ([x0, x1], [y0, y1], [z0, z1]) = (x, y, z);
    for corners in quad_triangles(x0, x1, y0, y1, z0, z1) {
        tri(g, corners, material);
    }
}

/// A flat colour: linear `rgb` with `alpha`, [`AlphaMode::Blend`] when `alpha < 1` and
/// [`AlphaMode::Opaque`] otherwise, double-sided, every other field at its default.
pub fn material(rgb: [f32; 3], alpha: f32) -> Material {
    Material {
        base_color: [rgb[0], rgb[1], rgb[2], alpha],
        alpha_mode: if alpha < 1.0 {
            AlphaMode::Blend
        } else {
            AlphaMode::Opaque
        },
        double_sided: true,
        ..Default::default()
    }
}

/// An empty scene with `materials` and one node, `root`, at the identity (no parent); add
/// triangles with [`quad`] and its siblings.
pub fn scene(materials: Vec<Material>) -> Geometry {
    Geometry {
        materials,
        nodes: vec![Node {
            name: "root".into(),
            parent: None,
            rest: DMat4::IDENTITY.to_cols_array(),
        }],
        ..Default::default()
    }
}

/// A frame looking from `eye` towards `eye − Z` (up +Y), with a vertical field of view of
/// 2·atan(1) = 90° so that y ∈ [−1, 1] fills the view at distance 1; clip planes 0.01 and 100,
/// no node poses.
pub fn frame_at(eye: DVec3) -> FrameState {
    let view = DMat4::look_at_rh(eye, eye - DVec3::Z, DVec3::Y);
    FrameState {
        camera: Camera {
            view: view.to_cols_array(),
            yfov: 2.0 * 1f64.atan(),
            znear: 0.01,
            zfar: Some(100.0),
        },
        poses: vec![],
    }
}

/// Recording settings for a square image of `size` × `size` pixels at `samples` per pixel,
/// recorded at that pattern only ([`trisort_format::Robust::OFF`]: the known answers of the
/// tests are the recorded pattern's), every other setting at its default.
pub fn settings(size: u32, samples: u32) -> RecordSettings {
    RecordSettings {
        width: size,
        height: size,
        samples,
        robust: trisort_format::Robust::OFF,
        ..Default::default()
    }
}

/// The indirect draw of `count` index-buffer triangles from triangle `first` on.
pub fn draw(first: u32, count: u32) -> DrawIndexedIndirectArgs {
    DrawIndexedIndirectArgs {
        index_count: 3 * count,
        instance_count: 1,
        first_index: 3 * first,
        base_vertex: 0,
        first_instance: 0,
    }
}

/// A baked file written by hand, for the readers' tests (the C API's, the C++ wrapper's):
/// geometry `g` (its scene ids are its triangle ids), the index buffer's triangles `copies`,
/// the `draws`, each frame's window over them and each frame's eye ([`frame_at`]); recorded at
/// 64×32 with 4 samples, lit by a uniform white environment, no frame rate, nothing removed.
/// It is not a bake of anything: only its structure holds (`Baked::check_structure`).
pub fn baked(
    g: Geometry,
    copies: Vec<u32>,
    draws: Vec<DrawIndexedIndirectArgs>,
    frames: Vec<FrameWindow>,
    eyes: &[DVec3],
) -> Baked {
    Baked {
        tool_version: "test".into(),
        scene_hash: [1; 32],
        path_hash: [2; 32],
        recording_hashes: vec![],
        settings: RecordSettings::new((64, 32), 4),
        device: DeviceInfo::default(),
        merge: MergeInfo::default(),
        stats: MergeStats::default(),
        scene_ids: (0..g.triangles.len() as u32).collect(),
        geometry: g,
        copies,
        draws,
        frames,
        frame_states: eyes.iter().map(|&e| frame_at(e)).collect(),
        removed_edges: vec![vec![]; eyes.len()],
        fps: None,
        environment: trisort_format::Environment::uniform(1.0),
        clips: vec![trisort_format::Clip::whole(
            eyes.len() as u32,
            None,
            [2; 32],
        )],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_quad_has_the_corners_and_winding_of_quad() {
        let mut shared = scene(vec![material([1.0; 3], 0.5)]);
        let mut split = shared.clone();
        quad(&mut shared, [-1.0, 2.0], [-3.0, 4.0], [-5.0, -6.0], 0);
        split_quad(&mut split, [-1.0, 2.0], [-3.0, 4.0], [-5.0, -6.0], 0);
        assert_eq!(shared.vertices.len(), 4);
        assert_eq!(split.vertices.len(), 6);
        let corners = |g: &Geometry| -> Vec<[f32; 3]> {
            g.triangles
                .iter()
                .flatten()
                .map(|&v| g.vertices[v as usize].position)
                .collect()
        };
        assert_eq!(corners(&shared), corners(&split));
    }

    #[test]
    fn flat_quad_is_quad_at_one_depth() {
        let mut a = scene(vec![]);
        let mut b = scene(vec![]);
        flat_quad(&mut a, -0.5, 0.5, -0.25, 0.75, -2.0, 3);
        quad(&mut b, [-0.5, 0.5], [-0.25, 0.75], [-2.0, -2.0], 3);
        assert_eq!(a, b);
    }

    #[test]
    fn frame_at_fills_the_view_with_unit_height_at_distance_one() {
        let f = frame_at(DVec3::new(0.5, 0.0, 1.0));
        let clip = f.camera.projection(1.0) * f.camera.view_matrix();
        let top = clip.project_point3(DVec3::new(0.5, 1.0, 0.0));
        assert!((top.y - 1.0).abs() < 1e-12, "{top}");
        assert!(top.x.abs() < 1e-12, "{top}");
    }

    #[test]
    fn material_blends_below_alpha_one() {
        assert_eq!(material([0.2; 3], 0.99).alpha_mode, AlphaMode::Blend);
        assert_eq!(material([0.2; 3], 1.0).alpha_mode, AlphaMode::Opaque);
        assert!(material([0.2; 3], 1.0).double_sided);
    }
}
