//! Block-compressed textures as a baked file stores them (`bake`/`merge --textures`): a
//! texture's level 0 and every mip level as 4×4 blocks of one GPU format, decoded on reading
//! into the RGBA8 levels every other part of trisort reads ([`Texture::rgba8`],
//! [`Texture::mips`]), so a player whose device lacks the format, the exact reference and the
//! C API see the texels a device that samples the blocks natively sees.
//!
//! The decoders are texture2ddecoder's (pure Rust, no_std, so the wasm player decodes too).
//! ETC2, EAC and BC7 decode to 8-bit values by their specifications, so a conforming GPU reads
//! exactly these texels; ASTC's LDR decoding keeps up to 16 bits per channel in linear
//! textures and expands sRGB endpoints differently, so a device decoding ASTC natively may
//! differ from these texels by one step of 8 bits in colour — never in alpha, which a baked
//! file's ASTC keeps at 255 wherever alpha decides visibility (see the bake's
//! `trisort_bake::textures`).
//!
//! Only textures whose width and height are powers of two are stored compressed: a level
//! narrower than a block (2×2, 1×1) is encoded tiled to fill its block, and every level then
//! tiles a texture array's larger layer block by block exactly as its texels would
//! ([`crate::gpu_layout::tiled`]).

use serde::{Deserialize, Serialize};

use crate::geometry::Texture;

/// A GPU block format a baked texture may be stored in: 4×4 texels a block.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum BlockFormat {
    /// ETC2 RGB8 (8 bytes a block; alpha reads as 255). OpenGL ES 3.0 and Vulkan mobile GPUs.
    Etc2Rgb8,
    /// ETC2 RGBA8: an EAC alpha block then an ETC2 colour block (16 bytes).
    Etc2Rgba8,
    /// ASTC LDR with 4×4 blocks (16 bytes).
    Astc4x4,
    /// BC7 (16 bytes). Desktop GPUs.
    Bc7,
}

impl BlockFormat {
    /// Bytes of one 4×4 block.
    pub fn block_bytes(self) -> usize {
        match self {
            BlockFormat::Etc2Rgb8 => 8,
            _ => 16,
        }
    }

    /// The name `--textures` and `--json` use for its family (`etc2`, `astc`, `bc7`).
    pub fn family(self) -> &'static str {
        match self {
            BlockFormat::Etc2Rgb8 | BlockFormat::Etc2Rgba8 => "etc2",
            BlockFormat::Astc4x4 => "astc",
            BlockFormat::Bc7 => "bc7",
        }
    }

    /// Bytes of a `w` × `h` level: whole blocks covering it.
    pub fn level_bytes(self, w: u32, h: u32) -> usize {
        w.div_ceil(4) as usize * h.div_ceil(4) as usize * self.block_bytes()
    }

    /// Decodes a `w` × `h` level's blocks into RGBA8 rows, top to bottom (blocks past the
    /// level's edge cropped). The caller checked the byte count ([`TextureBlocks::check`]).
    pub fn decode(self, blocks: &[u8], w: u32, h: u32) -> Vec<u8> {
        let (wu, hu) = (w as usize, h as usize);
        let mut texels = vec![0u32; wu * hu];
        let result = match self {
            BlockFormat::Etc2Rgb8 => texture2ddecoder::decode_etc2_rgb(blocks, wu, hu, &mut texels),
            BlockFormat::Etc2Rgba8 => {
                texture2ddecoder::decode_etc2_rgba8(blocks, wu, hu, &mut texels)
            }
            BlockFormat::Astc4x4 => texture2ddecoder::decode_astc_4_4(blocks, wu, hu, &mut texels),
            BlockFormat::Bc7 => texture2ddecoder::decode_bc7(blocks, wu, hu, &mut texels),
        };
        result.expect("block count checked before decoding");
        // texture2ddecoder packs a texel as little-endian B, G, R, A.
        let mut out = Vec::with_capacity(wu * hu * 4);
        for t in texels {
            let [b, g, r, a] = t.to_le_bytes();
            out.extend_from_slice(&[r, g, b, a]);
        }
        out
    }
}

impl std::fmt::Display for BlockFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BlockFormat::Etc2Rgb8 => "etc2-rgb8",
            BlockFormat::Etc2Rgba8 => "etc2-rgba8",
            BlockFormat::Astc4x4 => "astc-4x4",
            BlockFormat::Bc7 => "bc7",
        })
    }
}

/// A texture's levels in a block format: level 0, then each level of its full mip chain
/// (the sizes of [`Texture::level_size`]). A level narrower or shorter than a block holds its
/// texels repeated to fill the block.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureBlocks {
    /// The format of every level.
    pub format: BlockFormat,
    /// The levels' blocks, rows of blocks top to bottom.
    pub levels: Vec<Vec<u8>>,
}

impl TextureBlocks {
    /// Bytes of every level.
    pub fn byte_len(&self) -> u64 {
        self.levels.iter().map(|l| l.len() as u64).sum()
    }

    /// Checks the levels against a `width` × `height` texture: powers of two, a full chain,
    /// each level's byte count.
    pub fn check(&self, width: u32, height: u32) -> Result<(), String> {
        if !(width.is_power_of_two() && height.is_power_of_two()) {
            return Err(format!(
                "{width}×{height} {} blocks: only power-of-two sizes are stored compressed",
                self.format
            ));
        }
        let levels = Texture::mip_count(width, height) + 1;
        if self.levels.len() != levels {
            return Err(format!(
                "{} {} levels, a {width}×{height} chain has {levels}",
                self.levels.len(),
                self.format
            ));
        }
        for (k, level) in self.levels.iter().enumerate() {
            let (w, h) = Texture::level_size(width, height, k as u32);
            let want = self.format.level_bytes(w, h);
            if level.len() != want {
                return Err(format!(
                    "{} level {k} ({w}×{h}) has {} bytes, not {want}",
                    self.format,
                    level.len()
                ));
            }
        }
        Ok(())
    }

    /// Level `k` decoded to RGBA8 for a `width` × `height` texture.
    pub fn decode_level(&self, width: u32, height: u32, k: usize) -> Vec<u8> {
        let (w, h) = Texture::level_size(width, height, k as u32);
        self.format.decode(&self.levels[k], w, h)
    }
}

/// The constant EAC alpha block that turns an ETC2 RGB8 block into an ETC2 RGBA8 one with
/// alpha 255: base 255, multiplier 1, table 0, every index 4 (modifier +2, clamped to 255 by
/// any decoder).
pub const OPAQUE_EAC_BLOCK: [u8; 8] = [255, 0x10, 0x92, 0x49, 0x24, 0x92, 0x49, 0x24];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_opaque_eac_block_decodes_to_alpha_255() {
        // An ETC2 RGBA8 block: the constant alpha block, then an ETC2 colour block of zeros.
        let mut block = OPAQUE_EAC_BLOCK.to_vec();
        block.extend([0u8; 8]);
        let texels = BlockFormat::Etc2Rgba8.decode(&block, 4, 4);
        assert!(texels.chunks(4).all(|t| t[3] == 255), "{texels:?}");
        let rgb = BlockFormat::Etc2Rgb8.decode(&[0u8; 8], 4, 4);
        assert_eq!(
            texels.chunks(4).map(|t| &t[..3]).collect::<Vec<_>>(),
            rgb.chunks(4).map(|t| &t[..3]).collect::<Vec<_>>()
        );
    }

    #[test]
    fn levels_are_checked_against_the_texture() {
        let blocks = |levels: Vec<usize>| TextureBlocks {
            format: BlockFormat::Bc7,
            levels: levels.into_iter().map(|n| vec![0u8; n]).collect(),
        };
        // 8×8: levels 8×8 (4 blocks), 4×4, 2×2, 1×1 (a block each).
        assert_eq!(blocks(vec![64, 16, 16, 16]).check(8, 8), Ok(()));
        assert!(blocks(vec![64, 16, 16]).check(8, 8).is_err());
        assert!(blocks(vec![64, 16, 16, 15]).check(8, 8).is_err());
        assert!(blocks(vec![64, 16, 16, 16])
            .check(12, 8)
            .unwrap_err()
            .contains("power-of-two"));
    }

    #[test]
    fn a_file_stores_the_blocks_and_reading_decodes_them() {
        // A 4×4 sRGB texture of one ETC2 block (all zeros: a dark colour, alpha 255).
        let blocks = TextureBlocks {
            format: BlockFormat::Etc2Rgb8,
            levels: vec![vec![0u8; 8]; 3],
        };
        let decoded: Vec<Vec<u8>> = (0..3).map(|k| blocks.decode_level(4, 4, k)).collect();
        let texture = Texture {
            name: "t".into(),
            width: 4,
            height: 4,
            rgba8: decoded[0].clone(),
            srgb: true,
            mips: decoded[1..].to_vec(),
            blocks: Some(blocks),
        };
        let bytes = postcard::to_stdvec(&texture).unwrap();
        // The RGBA8 levels are not stored: 8 bytes a level of blocks, plus names and lengths.
        assert!(bytes.len() < 3 * 8 + 24, "{} bytes", bytes.len());
        let read: Texture = postcard::from_bytes(&bytes).unwrap();
        assert!(read.rgba8.is_empty() && read.mips.is_empty());
        let mut g = crate::Geometry {
            textures: vec![read],
            ..Default::default()
        };
        g.decode_blocks().unwrap();
        assert_eq!(g.textures[0], texture);
        // Blocks that do not fit the texture are an error naming it, not a panic.
        g.textures[0].rgba8.clear();
        g.textures[0].mips.clear();
        g.textures[0].blocks.as_mut().unwrap().levels[1].pop();
        let e = g.decode_blocks().unwrap_err().to_string();
        assert!(
            e.contains("texture 0 \"t\"") && e.contains("level 1"),
            "{e}"
        );
    }
}
