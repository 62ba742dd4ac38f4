//! The `trisort_gpu_*` functions on a hand-built baked file: the bytes are those
//! `trisort_format::gpu_layout` packs for the player (the C host's PBR test in the root crate
//! checks that drawing with them matches the player's frames), in the copy conventions, and
//! every argument out of range is refused.

use std::ptr::null_mut;

use glam::DVec3;
use trisort_capi::ffi::*;

use crate::baked::{get, open};
use trisort_format::gpu_layout::{self, View};
use trisort_format::{Baked, FrameWindow, TextureSlot};
use trisort_testkit::fixtures::{baked, draw, material, quad, scene};

/// Two quads, one with an sRGB base-colour texture (2×1) and one with a linear normal
/// texture (4×2); two frames.
fn sample() -> Baked {
    let mut g = scene(vec![
        material([1.0, 0.0, 0.0], 1.0),
        material([0.0, 0.0, 1.0], 0.5),
    ]);
    quad(&mut g, [-1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], 0);
    quad(&mut g, [-1.0, 1.0], [-1.0, 1.0], [-2.0, -2.0], 1);
    g.materials[0].base_color_texture = Some(0);
    g.materials[1].normal_texture = Some(TextureSlot {
        texture: 1,
        tex_coord: 0,
        transform: Default::default(),
    });
    let (colour, _) =
        trisort_scene::mips::texture_with_mips("t".into(), 2, 1, (1..=8).collect(), true, 1024);
    g.textures.push(colour);
    let (normals, _) =
        trisort_scene::mips::texture_with_mips("n".into(), 4, 2, vec![128; 32], false, 1024);
    g.textures.push(normals);
    baked(
        g,
        vec![0, 1, 2, 3],
        vec![draw(0, 4)],
        vec![
            FrameWindow { first: 0, count: 1 },
            FrameWindow { first: 0, count: 1 },
        ],
        &[DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.5, 0.0, 2.0)],
    )
}

#[test]
fn uniforms_and_data_textures_are_the_players_bytes() {
    let b = sample();
    let h = open(&b);
    let view = View {
        width: 64,
        height: 32,
        samples: 4,
        glass_opacity: b.settings.glass_opacity,
    };
    for f in 0..2u32 {
        let bytes: Vec<u8> =
            get(|o, c, l| unsafe { trisort_gpu_frame_uniform(h, f, 0, 0, o, c, l) });
        let want = gpu_layout::frame_uniform(&b.frame_states[f as usize], view);
        assert_eq!(bytes, want.bytes());
        assert_eq!(bytes.len(), TRISORT_GPU_FRAME_UNIFORM_SIZE as usize);
    }
    let other: Vec<u8> =
        get(|o, c, l| unsafe { trisort_gpu_frame_uniform(h, 0, 128, 32, o, c, l) });
    assert_ne!(
        other,
        get(|o, c, l| unsafe { trisort_gpu_frame_uniform(h, 0, 0, 0, o, c, l) })
    );

    let lighting: Vec<u8> = get(|o, c, l| unsafe {
        trisort_gpu_lighting_uniform(h, TRISORT_SHADING_PBR, TRISORT_TONE_MAP_ACES, 0, o, c, l)
    });
    assert_eq!(lighting.len(), TRISORT_GPU_LIGHTING_UNIFORM_SIZE as usize);
    let params = floats(&lighting[176..192]);
    assert_eq!(&params[1..3], &[1.0, 1.0], "pbr, ACES");

    let materials: Vec<f32> = get(|o, c, l| unsafe { trisort_gpu_material_texels(h, 0, o, c, l) });
    assert_eq!(materials.len(), TRISORT_GPU_DATA_WIDTH as usize * 4);
    assert_eq!(&materials[..4], &b.geometry.materials[0].base_color);
    let second = (TRISORT_GPU_MATERIAL_TEXELS * 4) as usize;
    assert_eq!(
        &materials[second..second + 4],
        &b.geometry.materials[1].base_color
    );

    let nodes: Vec<f32> = get(|o, c, l| unsafe { trisort_gpu_node_texels(h, o, c, l) });
    let per_frame = b.geometry.nodes.len().max(1) * 16;
    for f in 0..2u32 {
        let m: Vec<f32> =
            get(|o, c, l| unsafe { trisort_frame_node_matrices(h, f, true, o, c, l) });
        let at = f as usize * per_frame;
        assert_eq!(&nodes[at..at + m.len()], m.as_slice(), "frame {f}");
    }
    unsafe { trisort_close(h) };
}

/// The floats of `bytes` (native endian, 4 bytes a float).
fn floats(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks(4)
        .map(|c| f32::from_ne_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

#[test]
fn texture_arrays_and_environment_as_uploaded() {
    let b = sample();
    let h = open(&b);
    let mut t = TrisortGpuTexture::default();
    assert_eq!(
        unsafe { trisort_gpu_texture_array(h, TRISORT_TEXTURE_ARRAY_SRGB, 0, &mut t) },
        TrisortStatus::Ok
    );
    assert_eq!((t.width, t.height, t.layers, t.levels), (2, 1, 1, 2));
    let level0: Vec<u8> = get(|o, c, l| unsafe {
        trisort_gpu_texture_array_level(h, TRISORT_TEXTURE_ARRAY_SRGB, 0, 0, 0, o, c, l)
    });
    assert_eq!(level0, (1..=8).collect::<Vec<u8>>());
    assert_eq!(
        unsafe { trisort_gpu_texture_array(h, TRISORT_TEXTURE_ARRAY_LINEAR, 0, &mut t) },
        TrisortStatus::Ok
    );
    assert_eq!((t.width, t.height, t.layers, t.levels), (4, 2, 1, 3));
    // A device whose largest texture is 2 texels crops the layer and shortens the chain.
    assert_eq!(
        unsafe { trisort_gpu_texture_array(h, TRISORT_TEXTURE_ARRAY_LINEAR, 2, &mut t) },
        TrisortStatus::Ok
    );
    assert_eq!((t.width, t.height, t.levels), (2, 2, 2));

    let mut e = TrisortGpuTexture::default();
    assert_eq!(
        unsafe { trisort_gpu_environment(h, 0, &mut e) },
        TrisortStatus::Ok
    );
    assert!(e.levels >= 1 && e.layers == 1);
    let env: Vec<u16> = get(|o, c, l| unsafe { trisort_gpu_environment_level(h, 0, 0, o, c, l) });
    assert_eq!(env.len(), (e.width * e.height * 4) as usize);
    unsafe { trisort_close(h) };
}

#[test]
fn out_of_range_arguments_are_refused() {
    let h = open(&sample());
    let mut len = 0;
    let mut t = TrisortGpuTexture::default();
    let oor = TrisortStatus::OutOfRange;
    unsafe {
        assert_eq!(
            trisort_gpu_frame_uniform(h, 2, 0, 0, null_mut(), 0, &mut len),
            oor
        );
        assert_eq!(
            trisort_gpu_lighting_uniform(h, 2, 0, 0, null_mut(), 0, &mut len),
            oor
        );
        assert_eq!(
            trisort_gpu_lighting_uniform(h, 0, 2, 0, null_mut(), 0, &mut len),
            oor
        );
        assert_eq!(trisort_gpu_texture_array(h, 2, 0, &mut t), oor);
        assert_eq!(
            trisort_gpu_texture_array_level(h, 0, 1, 0, 0, null_mut(), 0, &mut len),
            oor
        );
        assert_eq!(
            trisort_gpu_texture_array_level(h, 0, 0, 9, 0, null_mut(), 0, &mut len),
            oor
        );
        assert_eq!(
            trisort_gpu_environment_level(h, 99, 0, null_mut(), 0, &mut len),
            oor
        );
        let mut small = [0u8; 16];
        assert_eq!(
            trisort_gpu_frame_uniform(h, 0, 0, 0, small.as_mut_ptr(), small.len(), &mut len),
            TrisortStatus::BufferTooSmall
        );
        assert_eq!(len, 144);
        assert_eq!(
            trisort_gpu_node_texels(std::ptr::null(), null_mut(), 0, &mut len),
            TrisortStatus::NullArgument
        );
        trisort_close(h);
    }
}
