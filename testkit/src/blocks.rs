//! Random block-compressed textures with known decodings, for the tests of the texture
//! arrays' block tiling (`trisort-format`) and of the player's native block upload
//! (`trisort-player`): valid for every decoder, of every BC7 mode, uniform where a level is
//! smaller than a block (how a file stores such a level, tiled).

use trisort_format::{BlockFormat, Texture, TextureBlocks};

/// A pseudo-random generator for test blocks (xorshift), seeded.
pub struct Bits(pub u64);

impl Bits {
    /// The next byte.
    pub fn byte(&mut self) -> u8 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 24) as u8
    }
}

/// A block of `format` valid for every decoder: random BC7 of every mode (the mode's bit set
/// in the first byte), random ETC2 (RGBA8: its EAC multiplier not 0, which is not for
/// encoders to write); where `uniform`, one colour over the block (BC7 mode 6 with every
/// index 0; ETC2 individual mode with equal halves and every index 0, and one alpha).
pub fn block(bits: &mut Bits, format: BlockFormat, uniform: bool) -> Vec<u8> {
    let mut b: Vec<u8> = (0..format.block_bytes()).map(|_| bits.byte()).collect();
    let colour = b.len() - 8;
    match (format, uniform) {
        (BlockFormat::Bc7, false) => {
            let mode = b[1] % 8;
            b[0] = (b[0] & !((2u16 << mode) - 1) as u8) | (1 << mode);
        }
        (BlockFormat::Bc7, true) => {
            // Mode 6: 7 mode bits, 56 endpoint bits, 2 p-bits, then 63 index bits.
            b[0] = (b[0] & 0x80) | 0x40;
            b[8] &= 0x01;
            b[9..].fill(0);
        }
        (_, true) => {
            for c in &mut b[colour..colour + 3] {
                *c = (*c & 0xf0) | (*c >> 4);
            }
            let table = b[colour + 3] >> 5;
            b[colour + 3] = table << 5 | table << 2;
            b[colour + 4..].fill(0);
            // An EAC alpha block's indices (ETC2 RGBA8), all 0: one alpha.
            if colour == 8 {
                b[2..colour].fill(0);
            }
        }
        _ => {}
    }
    if format == BlockFormat::Etc2Rgba8 {
        b[1] |= 0x10;
    }
    b
}

/// A `w` × `h` texture (powers of two) stored as random `format` blocks (levels under 4
/// texels uniform), its RGBA8 levels decoded from them as reading a file decodes them.
pub fn texture_of_blocks(
    bits: &mut Bits,
    format: BlockFormat,
    (w, h): (u32, u32),
    srgb: bool,
) -> Texture {
    let levels: Vec<Vec<u8>> = (0..=Texture::mip_count(w, h) as u32)
        .map(|k| {
            let (lw, lh) = Texture::level_size(w, h, k);
            (0..lw.div_ceil(4) * lh.div_ceil(4))
                .flat_map(|_| block(bits, format, lw < 4 || lh < 4))
                .collect()
        })
        .collect();
    let blocks = TextureBlocks { format, levels };
    blocks.check(w, h).expect("a full chain of whole blocks");
    let mut decoded = (0..blocks.levels.len()).map(|k| blocks.decode_level(w, h, k));
    Texture {
        name: format!("{format} {w}x{h}"),
        width: w,
        height: h,
        rgba8: decoded.next().expect("level 0"),
        srgb,
        mips: decoded.collect(),
        blocks: Some(blocks),
    }
}
