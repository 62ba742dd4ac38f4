//! The texture arrays' block upload (`TextureArray::block_format`, `level_blocks`): tiled
//! blocks decode to exactly the texels the RGBA8 upload of the same layer and level holds,
//! and an array goes up as blocks only when every member has blocks of one family.

use trisort_format::gpu_layout::plan_texture_arrays;
use trisort_format::{BlockFormat, Geometry, Texture};
use trisort_testkit::blocks::{texture_of_blocks, Bits};

/// Every layer and level of the sRGB array of `textures` in blocks, decoded, against the
/// RGBA8 upload of the same layer and level.
fn assert_blocks_decode_to_the_rgba8_upload(textures: Vec<Texture>, want: BlockFormat) {
    let g = Geometry {
        textures,
        ..Default::default()
    };
    let a = plan_texture_arrays(&g, 8192, false).srgb;
    assert_eq!(a.block_format(&g), Some(want));
    for layer in 0..a.layers() {
        for level in 0..a.levels {
            let (w, h) = a.level_size(level);
            let blocks = a.level_blocks(&g, want, layer, level).unwrap();
            assert_eq!(blocks.len(), want.level_bytes(w, h));
            assert!(
                want.decode(&blocks, w, h) == a.level_bytes(&g, layer, level).unwrap(),
                "layer {layer} ({}) level {level} ({w}x{h})",
                g.textures[a.members[layer as usize]].name
            );
        }
        assert_eq!(a.level_blocks(&g, want, layer, a.levels), None);
    }
}

#[test]
fn tiled_blocks_decode_to_the_tiled_texels() {
    let mut bits = Bits(0x9e37_79b9_7f4a_7c15);
    // The 16×8 member sets the layer (5 levels); the others repeat over it, the 4×16 one
    // cropped at level 0 (it is taller than the layer), the 2×2 one from one tiled block,
    // the 4×4 one past its chain from its 1×1 level.
    let textures = [(16, 8), (4, 4), (8, 2), (2, 2), (4, 16), (1, 1)]
        .map(|(w, h)| texture_of_blocks(&mut bits, BlockFormat::Bc7, (w, h), true));
    assert_blocks_decode_to_the_rgba8_upload(textures.to_vec(), BlockFormat::Bc7);
    // ETC2 RGB8 members join RGBA8 ones after the opaque alpha block.
    let textures = vec![
        texture_of_blocks(&mut bits, BlockFormat::Etc2Rgb8, (8, 8), true),
        texture_of_blocks(&mut bits, BlockFormat::Etc2Rgba8, (4, 4), true),
        texture_of_blocks(&mut bits, BlockFormat::Etc2Rgb8, (2, 4), true),
    ];
    assert_blocks_decode_to_the_rgba8_upload(textures.clone(), BlockFormat::Etc2Rgba8);
    let rgb = textures
        .into_iter()
        .filter(|t| t.blocks.as_ref().unwrap().format == BlockFormat::Etc2Rgb8);
    assert_blocks_decode_to_the_rgba8_upload(rgb.collect(), BlockFormat::Etc2Rgb8);
}

#[test]
fn an_array_is_uploaded_in_blocks_only_when_every_member_has_them() {
    let mut bits = Bits(7);
    let bc7 = |bits: &mut Bits, w, h| texture_of_blocks(bits, BlockFormat::Bc7, (w, h), true);
    let format = |textures: Vec<Texture>| {
        let g = Geometry {
            textures,
            ..Default::default()
        };
        plan_texture_arrays(&g, 8192, false).srgb.block_format(&g)
    };
    let mut plain = bc7(&mut bits, 4, 4);
    plain.blocks = None;
    let etc2 = texture_of_blocks(&mut bits, BlockFormat::Etc2Rgb8, (4, 4), true);
    assert_eq!(format(vec![bc7(&mut bits, 4, 4), plain]), None);
    assert_eq!(format(vec![bc7(&mut bits, 4, 4), etc2]), None);
    // A layer smaller than a block stays RGBA8.
    assert_eq!(
        format(vec![bc7(&mut bits, 2, 2), bc7(&mut bits, 1, 2)]),
        None
    );
    assert_eq!(format(vec![]), None);
    assert_eq!(
        format(vec![bc7(&mut bits, 2, 2), bc7(&mut bits, 4, 4)]),
        Some(BlockFormat::Bc7)
    );
}
