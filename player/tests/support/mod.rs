//! Baked files built by hand for the player's tests: a few quads at different depths and
//! colours, three frames with different windows.

use glam::{DMat4, DVec3};
use trisort_format::{
    AlphaMode, Baked, Camera, DeviceInfo, DrawIndexedIndirectArgs, FrameState, FrameWindow,
    Geometry, Material, RecordSettings, Vertex,
};
use trisort_testkit::fixtures::{flat_quad, scene};

/// Recorded image size (square).
pub const SIZE: u32 = 32;

/// Camera distance from the origin along +Z.
pub const EYE_Z: f64 = 5.0;

/// Linear base colours of the quads: red and green half transparent, blue opaque.
pub const RED: [f32; 4] = [1.0, 0.0, 0.0, 0.5];
/// Green, half transparent, behind red.
pub const GREEN: [f32; 4] = [0.0, 1.0, 0.0, 0.5];
/// Blue, opaque, behind everything, covering the whole view.
pub const BLUE: [f32; 4] = [0.0, 0.0, 1.0, 1.0];

fn material(base_color: [f32; 4], alpha_mode: AlphaMode) -> Material {
    Material {
        base_color,
        alpha_mode,
        ..Default::default()
    }
}

/// Indirect args over `count` indices from `first`.
pub fn args(first_index: u32, index_count: u32) -> DrawIndexedIndirectArgs {
    DrawIndexedIndirectArgs {
        index_count,
        instance_count: 1,
        first_index,
        base_vertex: 0,
        first_instance: 0,
    }
}

/// The camera: at (0, 0, 5) looking at the origin; y ∈ [−1, 1] at z = 0 fills the view.
pub fn frame_state() -> FrameState {
    FrameState {
        camera: Camera {
            view: DMat4::look_at_rh(DVec3::new(0.0, 0.0, EYE_Z), DVec3::ZERO, DVec3::Y)
                .to_cols_array(),
            yfov: 2.0 * (1.0 / EYE_Z).atan(),
            znear: 0.1,
            zfar: Some(20.0),
        },
        poses: vec![],
    }
}

/// Three quads, G-local triangles:
/// - 0, 1: Q0, red (α 0.5), z = 0.5 (front), x, y ∈ [−0.8, 0.3];
/// - 2, 3: Q1, green (α 0.5), z = 0, x, y ∈ [−0.3, 0.8];
/// - 4, 5: Q2, blue (opaque), z = −0.5, covering the view.
///
/// Copies (front to back): [0 1 2 3 | 4 5 | 2 3]. Draws: A = Q0 Q1 (indices 0..12),
/// B = Q2 (12..18), D = the first copy of Q0 (0..6), C = the second copy of Q1 (18..24);
/// the draw list is [A, B, D, C]. Frames: 0 = [A] (red over green), 1 = [A, B] (red over
/// green over blue), 2 = [D, C] (red over green from two ranges).
pub fn quads() -> Baked {
    let mut g = scene(vec![
        material(RED, AlphaMode::Blend),
        material(GREEN, AlphaMode::Blend),
        material(BLUE, AlphaMode::Opaque),
    ]);
    flat_quad(&mut g, -0.8, 0.3, -0.8, 0.3, 0.5, 0);
    flat_quad(&mut g, -0.3, 0.8, -0.3, 0.8, 0.0, 1);
    flat_quad(&mut g, -3.0, 3.0, -3.0, 3.0, -0.5, 2);
    let frames = 3;
    Baked {
        tool_version: trisort_format::TOOL_VERSION.into(),
        scene_hash: [1; 32],
        path_hash: [2; 32],
        recording_hashes: vec![[3; 32]],
        settings: RecordSettings {
            width: SIZE,
            height: SIZE,
            samples: 1,
            ..Default::default()
        },
        device: DeviceInfo {
            adapter: "hand-made".into(),
            driver: "none".into(),
            backend: "Vulkan".into(),
        },
        merge: Default::default(),
        stats: Default::default(),
        scene_ids: (0..g.triangles.len() as u32).map(|t| t * 10).collect(),
        geometry: g,
        copies: vec![0, 1, 2, 3, 4, 5, 2, 3],
        draws: vec![args(0, 12), args(12, 6), args(0, 6), args(18, 6)],
        frames: vec![
            FrameWindow { first: 0, count: 1 },
            FrameWindow { first: 0, count: 2 },
            FrameWindow { first: 2, count: 2 },
        ],
        frame_states: vec![frame_state(); frames],
        removed_edges: vec![vec![]; frames],
        fps: None,
        environment: trisort_format::Environment::uniform(1.0),
        clips: vec![trisort_format::Clip::whole(frames as u32, None, [2; 32])],
    }
}

/// [`quads`] with unused vertices appended so that the indices no longer fit 16 bits.
pub fn quads_u32() -> Baked {
    let mut b = quads();
    let v = b.geometry.vertices[0];
    b.geometry.vertices.resize(70_000, v);
    assert!(!b.fits_u16());
    b
}

/// The triangles a list of draws covers, as G-local ids in draw order, for a front-to-back
/// copy list.
pub fn drawn_copies(baked: &Baked, draws: &[DrawIndexedIndirectArgs]) -> Vec<u32> {
    draws
        .iter()
        .flat_map(|d| d.first_index / 3..(d.first_index + d.index_count) / 3)
        .map(|k| baked.copies[k as usize])
        .collect()
}

/// The lit colour of a flat quad facing the camera under `--shading basic` (the shared
/// `shade_basic` with a view-space normal of +Z and no emission), straight alpha.
pub fn lit(base: [f32; 4]) -> [f64; 4] {
    let l = trisort_gpu::scene_gpu::LIGHT;
    let len = ((l[0] * l[0] + l[1] * l[1] + l[2] * l[2]) as f64).sqrt();
    let diffuse = (l[2] as f64 / len).max(0.0);
    let k = l[3] as f64 + (1.0 - l[3] as f64) * diffuse;
    [
        base[0] as f64 * k,
        base[1] as f64 * k,
        base[2] as f64 * k,
        base[3] as f64,
    ]
}

/// `src` over `dst` (straight alpha source, opaque destination).
pub fn over(src: [f64; 4], dst: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|c| src[3] * src[c] + (1.0 - src[3]) * dst[c])
}

/// 8-bit sRGB of a linear colour.
pub fn srgb8(c: [f64; 3]) -> [u8; 3] {
    c.map(|v| {
        let v = v.clamp(0.0, 1.0);
        let s = if v <= 0.0031308 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    })
}

/// The pixel at (x, y) of an RGBA8 image `SIZE` wide.
pub fn pixel(rgba8: &[u8], x: u32, y: u32) -> [u8; 3] {
    let i = ((y * SIZE + x) * 4) as usize;
    [rgba8[i], rgba8[i + 1], rgba8[i + 2]]
}

/// Largest per-channel difference of two images.
pub fn max_diff(a: &[u8], b: &[u8]) -> u8 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap_or(0)
}

/// Asserts that two colours differ by at most `tol` per channel.
pub fn assert_close(got: [u8; 3], want: [u8; 3], tol: u8, what: &str) {
    let d = got
        .iter()
        .zip(want)
        .map(|(a, b)| a.abs_diff(b))
        .max()
        .unwrap();
    assert!(d <= tol, "{what}: got {got:?}, expected {want:?} (±{tol})");
}

/// Asserts that the pixel at `xy` of an RGBA8 image `SIZE` wide is the linear colour `want`
/// in 8-bit sRGB ([`srgb8`]), within `tol` per channel.
pub fn assert_pixel(rgba8: &[u8], (x, y): (u32, u32), want: [f64; 3], tol: u8, what: &str) {
    assert_close(pixel(rgba8, x, y), srgb8(want), tol, what);
}

/// A quad in the plane z whose front face looks away from the camera (clockwise as seen from
/// +Z, normal −Z), uv running 0 → 1 from x0 to x1.
fn back_quad(g: &mut Geometry, x0: f32, y0: f32, x1: f32, y1: f32, z: f32, material: u32) {
    let base = g.vertices.len() as u32;
    for (x, y) in [(x0, y0), (x0, y1), (x1, y1), (x1, y0)] {
        g.vertices.push(Vertex {
            position: [x, y, z],
            normal: [0.0, 0.0, -1.0],
            uv: [(x - x0) / (x1 - x0), (y - y0) / (y1 - y0)],
            material,
            node: 0,
            tangent: [0.0; 4],
            uv1: [0.0; 2],
        });
    }
    g.triangles.push([base, base + 1, base + 2]);
    g.triangles.push([base, base + 2, base + 3]);
}

/// Yellow base colour of the masked quad (its texture is white, alpha 1 on the left texel and
/// 0 on the right one).
pub const YELLOW: [f32; 4] = [1.0, 1.0, 0.0, 1.0];

/// Culling and alpha cut-outs, and an empty frame. Three quads at z = 0, none overlapping:
/// - A (triangles 0, 1): single-sided red, seen from the back → culled; x ∈ [−0.9, −0.4],
///   y ∈ [0.2, 0.8];
/// - B (2, 3): double-sided green, seen from the back → drawn; x ∈ [−0.3, 0.2], same y;
/// - C (4, 5): MASK yellow × a 2×1 texture whose right texel is transparent → only the left
///   half stays; x ∈ [−0.9, 0.9], y ∈ [−0.8, −0.2].
///
/// Frame 0 draws nothing (an empty window); frame 1 draws all three.
pub fn faces() -> Baked {
    let mut b = quads();
    let mut g = Geometry {
        materials: vec![
            material([1.0, 0.0, 0.0, 1.0], AlphaMode::Opaque),
            Material {
                double_sided: true,
                ..material([0.0, 1.0, 0.0, 1.0], AlphaMode::Opaque)
            },
            Material {
                base_color_texture: Some(0),
                alpha_cutoff: 0.5,
                ..material(YELLOW, AlphaMode::Mask)
            },
        ],
        textures: vec![
            trisort_scene::mips::texture_with_mips(
                "half".into(),
                2,
                1,
                vec![255, 255, 255, 255, 255, 255, 255, 0],
                true,
                1024,
            )
            .0,
        ],
        nodes: b.geometry.nodes.clone(),
        ..Default::default()
    };
    back_quad(&mut g, -0.9, 0.2, -0.4, 0.8, 0.0, 0);
    back_quad(&mut g, -0.3, 0.2, 0.2, 0.8, 0.0, 1);
    // C faces the camera.
    let base = g.vertices.len() as u32;
    let (x0, y0, x1, y1) = (-0.9f32, -0.8f32, 0.9f32, -0.2f32);
    for (x, y) in [(x0, y0), (x1, y0), (x1, y1), (x0, y1)] {
        g.vertices.push(Vertex {
            position: [x, y, 0.0],
            normal: [0.0, 0.0, 1.0],
            uv: [(x - x0) / (x1 - x0), (y - y0) / (y1 - y0)],
            material: 2,
            node: 0,
            tangent: [0.0; 4],
            uv1: [0.0; 2],
        });
    }
    g.triangles.push([base, base + 1, base + 2]);
    g.triangles.push([base, base + 2, base + 3]);
    b.scene_ids = (0..6).collect();
    b.geometry = g;
    b.copies = (0..6).collect();
    b.draws = vec![args(0, 18)];
    b.frames = vec![
        FrameWindow { first: 0, count: 0 },
        FrameWindow { first: 0, count: 1 },
    ];
    b.frame_states = vec![frame_state(); 2];
    b.removed_edges = vec![vec![]; 2];
    b.clips[0].count = 2;
    b
}
