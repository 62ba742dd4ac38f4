//! The C API on a hand-built baked file with known answers: counts, the index buffer in both
//! orders and widths, each frame's ranges mirrored onto the reversed buffer, matrices in both
//! depth conventions, materials, textures, and the refusals.

use std::ptr::null_mut;

use glam::{DMat4, DVec3, DVec4};
use trisort_capi::ffi::*;
use trisort_format::container::encode;
use trisort_format::{Baked, FileKind, FrameWindow, TextureSlot, TextureTransform};
use trisort_testkit::fixtures::{baked, draw, material, quad, scene};

use crate::api::last_error;

/// Four quads (8 triangles) in front of each other; the index buffer holds 10 copies, front
/// to back; frame 0 draws copies 0..4 and 6..10, frame 1 copies 2..8.
pub fn sample() -> Baked {
    let mut g = scene(vec![
        material([1.0, 0.0, 0.0], 1.0),
        material([0.0, 0.0, 1.0], 0.5),
    ]);
    for k in 0..4 {
        let z = -1.0 - k as f32;
        quad(&mut g, [-1.0, 1.0], [-1.0, 1.0], [z, z], (k % 2) as u32);
    }
    g.materials[1].base_color_texture = Some(0);
    g.materials[1].base_color_tex_coord = 1;
    g.materials[1].base_color_transform.offset = [0.5, 0.25];
    g.materials[0].metallic = 0.25;
    g.materials[0].clearcoat = 0.75;
    g.materials[0].normal_texture = Some(TextureSlot {
        texture: 1,
        tex_coord: 0,
        transform: TextureTransform {
            offset: [0.0; 2],
            rotation: std::f32::consts::FRAC_PI_2,
            scale: [2.0, 3.0],
        },
    });
    g.vertices[5].tangent = [1.0, 0.0, 0.0, -1.0];
    g.vertices[5].uv1 = [0.125, 0.875];
    let (colour, _) =
        trisort_scene::mips::texture_with_mips("t".into(), 2, 1, (1..=8).collect(), true, 1024);
    g.textures.push(colour);
    let (normals, _) =
        trisort_scene::mips::texture_with_mips("n".into(), 4, 2, vec![128; 32], false, 1024);
    g.textures.push(normals);
    let copies = vec![0, 1, 2, 3, 4, 5, 6, 7, 2, 3];
    baked(
        g,
        copies,
        vec![draw(0, 4), draw(6, 4), draw(2, 6)],
        vec![
            FrameWindow { first: 0, count: 2 },
            FrameWindow { first: 2, count: 1 },
        ],
        &[DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.5, 0.0, 2.0)],
    )
}

/// Opens `baked` from its encoded bytes.
pub fn open(baked: &Baked) -> *mut TrisortBaked {
    baked.check_structure().unwrap();
    let bytes = encode(FileKind::Baked, baked);
    let mut h = null_mut();
    assert_eq!(
        unsafe { trisort_open_bytes(bytes.as_ptr(), bytes.len(), &mut h) },
        TrisortStatus::Ok
    );
    h
}

/// Copies out with the length query first, as a C host does.
pub fn get<T: Default + Clone>(
    mut f: impl FnMut(*mut T, usize, *mut usize) -> TrisortStatus,
) -> Vec<T> {
    let mut len = 0;
    assert_eq!(f(null_mut(), 0, &mut len), TrisortStatus::Ok);
    let mut out = vec![T::default(); len];
    assert_eq!(f(out.as_mut_ptr(), len, &mut len), TrisortStatus::Ok);
    out
}

#[test]
fn counts_index_buffers_and_ranges_match_the_file() {
    let b = sample();
    let h = open(&b);
    let mut info = TrisortInfo::default();
    assert_eq!(unsafe { trisort_info(h, &mut info) }, TrisortStatus::Ok);
    assert_eq!(
        (info.frame_count, info.width, info.height, info.samples),
        (2, 64, 32, 4)
    );
    assert_eq!((info.triangle_count, info.index_triangle_count), (8, 10));
    assert_eq!(
        (info.draw_count, info.material_count, info.texture_count),
        (3, 2, 2)
    );
    assert!(info.fits_u16 && !info.depth_only);
    assert_eq!(info.recommended_mode, TrisortMode::Blend);

    let front: Vec<u32> = get(|o, c, l| unsafe { trisort_indices_u32(h, false, o, c, l) });
    assert_eq!(front, b.indices());
    let front16: Vec<u16> = get(|o, c, l| unsafe { trisort_indices_u16(h, false, o, c, l) });
    assert!(front16.iter().zip(&front).all(|(&a, &b)| a as u32 == b));
    let back: Vec<u32> = get(|o, c, l| unsafe { trisort_indices_u32(h, true, o, c, l) });
    // Per frame: the triangles drawn back to front are those drawn front to back, reversed.
    for f in 0..2 {
        let drawn = |idx: &[u32], back_to_front: bool| -> Vec<[u32; 3]> {
            let ranges: Vec<TrisortRange> =
                get(|o, c, l| unsafe { trisort_frame_ranges(h, f, back_to_front, o, c, l) });
            ranges
                .iter()
                .flat_map(|r| idx[r.first as usize..(r.first + r.count) as usize].chunks(3))
                .map(|t| [t[0], t[1], t[2]])
                .collect()
        };
        let mut reversed = drawn(&back, true);
        reversed.reverse();
        assert_eq!(drawn(&front, false), reversed, "frame {f}");
        let draws: Vec<TrisortDrawIndexedIndirectArgs> =
            get(|o, c, l| unsafe { trisort_frame_draws(h, f, false, o, c, l) });
        let want: Vec<_> = b
            .frame_draws(f as usize)
            .iter()
            .map(|d| (d.first_index, d.index_count))
            .collect();
        let got: Vec<_> = draws
            .iter()
            .map(|d| (d.first_index, d.index_count))
            .collect();
        assert_eq!(got, want);
    }
    let mut n = 0;
    assert_eq!(
        unsafe { trisort_frame_ranges(h, 2, false, null_mut(), 0, &mut n) },
        TrisortStatus::OutOfRange
    );
    unsafe { trisort_close(h) };
}

#[test]
fn matrices_materials_and_textures() {
    let b = sample();
    let h = open(&b);
    check_vertices(h, &b);
    check_matrices(h, &b);
    check_materials(h);
    check_textures(h);
    unsafe { trisort_close(h) };
}

/// The vertices are the file's, byte for byte.
fn check_vertices(h: *mut TrisortBaked, b: &Baked) {
    let vertices: Vec<TrisortVertex> = get(|o, c, l| unsafe { trisort_vertices(h, o, c, l) });
    assert_eq!(vertices.len(), b.geometry.vertices.len());
    assert_eq!(vertices[5].position, b.geometry.vertices[5].position);
    assert_eq!(std::mem::size_of::<TrisortVertex>(), 64);
    assert_eq!(
        (vertices[5].tangent, vertices[5].uv1),
        ([1.0, 0.0, 0.0, -1.0], [0.125, 0.875])
    );
    // The C struct is the file's vertex, byte for byte.
    let bytes = |p: *const u8| unsafe { std::slice::from_raw_parts(p, 64) };
    assert_eq!(std::mem::size_of::<trisort_format::Vertex>(), 64);
    assert_eq!(
        bytes((&b.geometry.vertices[5] as *const trisort_format::Vertex).cast()),
        bytes((&vertices[5] as *const TrisortVertex).cast())
    );
}

/// The view, projection (both depth conventions) and node matrices of `b`'s frames.
fn check_matrices(h: *mut TrisortBaked, b: &Baked) {
    let mut view = [0f32; 16];
    assert_eq!(
        unsafe { trisort_frame_view(h, 1, view.as_mut_ptr()) },
        TrisortStatus::Ok
    );
    assert_eq!(
        view,
        b.frame_states[1]
            .camera
            .view_matrix()
            .as_mat4()
            .to_cols_array()
    );
    // The near plane maps to depth 0 or −1, the far plane to 1, in each convention.
    for (depth, near) in [
        (TrisortDepthRange::ZeroToOne, 0.0),
        (TrisortDepthRange::MinusOneToOne, -1.0),
    ] {
        let mut p = [0f32; 16];
        let s = unsafe { trisort_frame_projection(h, 0, 2.0, depth as u32, p.as_mut_ptr()) };
        assert_eq!(s, TrisortStatus::Ok);
        let p = DMat4::from_cols_array(&p.map(f64::from));
        let ndc = |z: f64| {
            let c = p * DVec4::new(0.0, 0.0, -z, 1.0);
            c.z / c.w
        };
        assert!((ndc(0.01) - near).abs() < 1e-3, "{depth:?}");
        assert!((ndc(100.0) - 1.0).abs() < 1e-3, "{depth:?}");
    }
    let mut p = [0f32; 16];
    let bad_aspect = unsafe {
        trisort_frame_projection(
            h,
            0,
            0.0,
            TrisortDepthRange::ZeroToOne as u32,
            p.as_mut_ptr(),
        )
    };
    assert_eq!(bad_aspect, TrisortStatus::OutOfRange);
    // A depth range outside the enum (a C caller's 2) is refused, not undefined behaviour.
    for bad in [2, u32::MAX] {
        let s = unsafe { trisort_frame_projection(h, 0, 2.0, bad, p.as_mut_ptr()) };
        assert_eq!(s, TrisortStatus::OutOfRange);
        assert!(
            last_error().contains(&format!("depth range {bad}")),
            "{}",
            last_error()
        );
    }
    let nodes: Vec<f32> =
        get(|o, c, l| unsafe { trisort_frame_node_matrices(h, 0, true, o, c, l) });
    assert_eq!(nodes.len(), 16);
    assert_eq!(&nodes[..], &view_of(b, 0)[..]);
    assert_eq!(
        unsafe { trisort_frame_view(h, 0, null_mut()) },
        TrisortStatus::NullArgument
    );
}

/// The materials of [`sample`], with their texture slots.
fn check_materials(h: *mut TrisortBaked) {
    let materials: Vec<TrisortMaterial> = get(|o, c, l| unsafe { trisort_materials(h, o, c, l) });
    assert_eq!(materials[1].alpha_mode, TrisortAlphaMode::Blend);
    assert_eq!(
        (
            materials[0].base_color_texture,
            materials[1].base_color_texture
        ),
        (-1, 0)
    );
    // Texture slots: index, set and the 2x3 matrix of the transform.
    let base = materials[1].base_color_slot;
    assert_eq!((base.texture, base.tex_coord), (0, 1));
    assert_eq!(base.transform, [1.0, 0.0, 0.5, 0.0, 1.0, 0.25]);
    let m0 = &materials[0];
    assert_eq!((m0.metallic, m0.roughness, m0.clearcoat), (0.25, 1.0, 0.75));
    assert_eq!((m0.normal.texture, m0.normal_scale), (1, 1.0));
    let r = m0.normal.transform;
    assert!((r[0]).abs() < 1e-6 && (r[1] - 3.0).abs() < 1e-6 && (r[3] + 2.0).abs() < 1e-6);
    assert_eq!(
        (m0.occlusion.texture, m0.emissive_texture.texture),
        (-1, -1)
    );
    assert_eq!(
        m0.metallic_roughness.transform,
        [1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    );
    assert_eq!(
        (
            materials[0].base_color_slot.texture,
            materials[0].base_color_texture
        ),
        (-1, -1)
    );
}

/// The textures of [`sample`] with every mip level, and the refusals of a level, a texture or
/// an output that is not there.
fn check_textures(h: *mut TrisortBaked) {
    let (mut w, mut ht) = (0, 0);
    let texels: Vec<u8> = get(|o, c, l| unsafe { trisort_texture(h, 0, &mut w, &mut ht, o, c, l) });
    assert_eq!((w, ht, texels), (2, 1, vec![1, 2, 3, 4, 5, 6, 7, 8]));
    let mut info = TrisortTextureInfo::default();
    assert_eq!(
        unsafe { trisort_texture_info(h, 0, &mut info) },
        TrisortStatus::Ok
    );
    assert_eq!((info.srgb, info.level_count), (true, 2));
    assert_eq!(
        unsafe { trisort_texture_info(h, 1, &mut info) },
        TrisortStatus::Ok
    );
    assert_eq!(
        (info.width, info.height, info.srgb, info.level_count),
        (4, 2, false, 3)
    );
    for (level, size) in [(0, (4, 2)), (1, (2, 1)), (2, (1, 1))] {
        let texels: Vec<u8> =
            get(|o, c, l| unsafe { trisort_texture_level(h, 1, level, &mut w, &mut ht, o, c, l) });
        assert_eq!((w, ht), size);
        assert_eq!(texels, vec![128; (size.0 * size.1 * 4) as usize]);
    }
    let mut len = 0;
    assert_eq!(
        unsafe { trisort_texture_level(h, 1, 3, null_mut(), null_mut(), null_mut(), 0, &mut len) },
        TrisortStatus::OutOfRange
    );
    assert!(
        last_error().contains("mip level 3 of texture 1"),
        "{}",
        last_error()
    );
    assert_eq!(
        unsafe { trisort_texture(h, 2, null_mut(), null_mut(), null_mut(), 0, &mut len) },
        TrisortStatus::OutOfRange
    );
    assert_eq!(
        unsafe { trisort_texture_info(h, 2, &mut info) },
        TrisortStatus::OutOfRange
    );
    assert_eq!(
        unsafe { trisort_texture_info(h, 0, null_mut()) },
        TrisortStatus::NullArgument
    );
}

/// The camera-relative node matrix of the sample's one node (identity world) at frame `f`.
fn view_of(b: &Baked, f: usize) -> [f32; 16] {
    b.frame_states[f]
        .camera
        .view_matrix()
        .as_mat4()
        .to_cols_array()
}

#[test]
fn more_than_65536_vertices_refuse_u16_indices() {
    let mut b = sample();
    let extra = b.geometry.vertices[0];
    b.geometry.vertices.resize(70_000, extra);
    let h = open(&b);
    let mut len = 0;
    let s = unsafe { trisort_indices_u16(h, false, null_mut(), 0, &mut len) };
    assert_eq!(s, TrisortStatus::Unsupported);
    assert!(last_error().contains("70000 vertices"), "{}", last_error());
    let idx: Vec<u32> = get(|o, c, l| unsafe { trisort_indices_u32(h, false, o, c, l) });
    assert_eq!(idx.len(), 30);
    unsafe { trisort_close(h) };
}

#[test]
fn a_structurally_broken_file_is_refused_with_its_problem() {
    let mut b = sample();
    b.draws[0].index_count = 999;
    let bytes = encode(FileKind::Baked, &b);
    let mut h = null_mut();
    let s = unsafe { trisort_open_bytes(bytes.as_ptr(), bytes.len(), &mut h) };
    assert_eq!(s, TrisortStatus::Format);
    assert!(h.is_null());
    assert!(last_error().contains("draw 0"), "{}", last_error());
}
