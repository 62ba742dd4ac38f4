//! Mip chains for decoded textures: what the importer and the procedural car store in
//! [`Texture::mips`], so that every player uploads the same levels.
//!
//! Building the chain is the producer's job (an sRGB-aware box filter, see
//! [`texture_with_mips`]); a reader of a baked file only checks its sizes
//! (`Geometry::check_structure` in `trisort-format`) and uploads it as stored.

use trisort_format::Texture;

/// The largest width or height [`texture_with_mips`] is given by the importer and the
/// procedural car: a bigger image is stored from its first mip level that fits.
pub const MAX_SIZE: u32 = 1024;

/// A texture from a decoded `width` × `height` RGBA8 image (rows top to bottom), with its
/// full mip chain ([`Texture::mips`]). Each level is a box filter of the one above it:
/// texel `(x, y)` averages the texels of the level above that its footprint overlaps (2×2,
/// or 3 along an odd dimension, 1 along a dimension of size 1), with equal weights. For an
/// `srgb` texture the colour channels are decoded to linear light, averaged and encoded
/// again (black and white average to 188, not 128); alpha, and every channel of a linear
/// texture, is averaged as stored. Rounds to nearest.
///
/// An image wider or taller than `max_size` is stored from its first mip level that fits
/// (levels above it are computed and dropped); the second value returned is that level
/// (0 when it fits). `rgba8` must hold `width * height * 4` bytes and both sizes must be at
/// least 1, else this panics.
pub fn texture_with_mips(
    name: String,
    width: u32,
    height: u32,
    rgba8: Vec<u8>,
    srgb: bool,
    max_size: u32,
) -> (Texture, u32) {
    assert!(width > 0 && height > 0, "an empty image has no mips");
    assert_eq!(
        rgba8.len() as u64,
        width as u64 * height as u64 * 4,
        "RGBA8 byte count of a {width}x{height} image"
    );
    let max_size = max_size.max(1);
    let (mut w, mut h, mut level0) = (width, height, rgba8);
    let mut dropped = 0;
    while w > max_size || h > max_size {
        let (nw, nh) = Texture::level_size(w, h, 1);
        level0 = downsample(&level0, w, h, nw, nh, srgb);
        (w, h) = (nw, nh);
        dropped += 1;
    }
    let mut mips: Vec<Vec<u8>> = Vec::with_capacity(Texture::mip_count(w, h));
    let (mut lw, mut lh) = (w, h);
    for _ in 0..Texture::mip_count(w, h) {
        let (nw, nh) = Texture::level_size(lw, lh, 1);
        let above = mips.last().unwrap_or(&level0);
        let next = downsample(above, lw, lh, nw, nh, srgb);
        mips.push(next);
        (lw, lh) = (nw, nh);
    }
    let texture = Texture {
        name,
        width: w,
        height: h,
        rgba8: level0,
        srgb,
        mips,
        blocks: None,
    };
    (texture, dropped)
}

/// sRGB-encoded byte to linear light.
fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light in [0, 1] to the nearest sRGB-encoded byte.
fn linear_to_srgb(l: f32) -> u8 {
    let l = l.clamp(0.0, 1.0);
    let c = if l <= 0.0031308 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (c * 255.0).round() as u8
}

/// The `[start, end)` texels of a source dimension of `from` texels that dest texel `i` of
/// `to` overlaps.
fn footprint(i: u32, from: u32, to: u32) -> (usize, usize) {
    let start = (i as u64 * from as u64) / to as u64;
    let end = ((i as u64 + 1) * from as u64).div_ceil(to as u64);
    (start as usize, end as usize)
}

/// One box-filtered level (see [`texture_with_mips`]).
fn downsample(src: &[u8], w: u32, h: u32, nw: u32, nh: u32, srgb: bool) -> Vec<u8> {
    let decode: Vec<f32> = (0..=255u8)
        .map(|c| {
            if srgb {
                srgb_to_linear(c)
            } else {
                c as f32 / 255.0
            }
        })
        .collect();
    let mut out = Vec::with_capacity(nw as usize * nh as usize * 4);
    for y in 0..nh {
        let (y0, y1) = footprint(y, h, nh);
        for x in 0..nw {
            let (x0, x1) = footprint(x, w, nw);
            let mut sum = [0f32; 4];
            for sy in y0..y1 {
                let row = &src[sy * w as usize * 4..];
                for sx in x0..x1 {
                    let p = &row[sx * 4..sx * 4 + 4];
                    for c in 0..3 {
                        sum[c] += decode[p[c] as usize];
                    }
                    sum[3] += p[3] as f32;
                }
            }
            let n = ((y1 - y0) * (x1 - x0)) as f32;
            for c in sum.iter().take(3) {
                let v = c / n;
                out.push(if srgb {
                    linear_to_srgb(v)
                } else {
                    (v * 255.0).round().clamp(0.0, 255.0) as u8
                });
            }
            out.push((sum[3] / n).round().clamp(0.0, 255.0) as u8);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use trisort_format::Geometry;

    fn image(w: u32, h: u32) -> Vec<u8> {
        (0..w * h * 4).map(|i| (i * 37 % 251) as u8).collect()
    }

    #[test]
    fn mip_chains_halve_each_dimension_down_to_one_texel() {
        for (w, h, levels) in [
            (1, 1, 0),
            (2, 2, 1),
            (5, 3, 2),
            (7, 7, 2),
            (8, 2, 3),
            (1, 9, 3),
            (13, 1, 3),
            (1024, 3, 10),
        ] {
            let (t, dropped) = texture_with_mips("t".into(), w, h, image(w, h), true, 1024);
            assert_eq!(dropped, 0);
            assert_eq!((t.width, t.height), (w, h));
            assert_eq!(t.mips.len(), levels, "{w}x{h}");
            for (k, mip) in t.mips.iter().enumerate() {
                let (lw, lh) = Texture::level_size(w, h, k as u32 + 1);
                assert_eq!((lw, lh), ((w >> (k + 1)).max(1), (h >> (k + 1)).max(1)));
                assert_eq!(mip.len() as u32, lw * lh * 4, "{w}x{h} level {}", k + 1);
            }
            assert_eq!(t.mips.last().map_or(4, |m| m.len()), 4, "ends at 1x1");
            let g = Geometry {
                textures: vec![t],
                ..Geometry::default()
            };
            g.check_structure().unwrap();
        }
    }

    #[test]
    fn srgb_mips_average_light_and_linear_ones_bytes() {
        // Black and white texels with alpha 0 and 255.
        let px = vec![0, 0, 0, 0, 255, 255, 255, 255];
        let (srgb, _) = texture_with_mips(String::new(), 2, 1, px.clone(), true, 1024);
        assert_eq!(srgb.mips, vec![vec![188, 188, 188, 128]]);
        let (linear, _) = texture_with_mips(String::new(), 2, 1, px, false, 1024);
        assert_eq!(linear.mips, vec![vec![128, 128, 128, 128]]);
        // An odd row of three averages all three: 0, 0 and 255 give a third of the light.
        let (odd, _) = texture_with_mips(
            String::new(),
            3,
            1,
            vec![0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255, 255],
            true,
            1024,
        );
        // linear 1/3 -> sRGB 0.6134 -> 156.4
        assert_eq!(odd.mips, vec![vec![156, 156, 156, 255]]);
        // A uniform image stays uniform at every level.
        let (flat, _) = texture_with_mips(
            String::new(),
            6,
            5,
            [90u8, 20, 200, 77].repeat(30),
            true,
            1024,
        );
        assert!(flat
            .mips
            .iter()
            .flatten()
            .collect::<Vec<_>>()
            .chunks(4)
            .all(|p| *p[0] == 90 && *p[1] == 20 && *p[2] == 200 && *p[3] == 77));
    }

    #[test]
    fn images_larger_than_the_cap_are_stored_from_the_first_level_that_fits() {
        let (t, dropped) = texture_with_mips("big".into(), 20, 6, image(20, 6), false, 4);
        assert_eq!(dropped, 3);
        assert_eq!((t.width, t.height), (2, 1));
        assert_eq!(t.rgba8.len(), 2 * 4);
        assert_eq!(t.mips.len(), 1);
        // Level 0 as stored is what the full chain's level 3 would be.
        let (chain, _) = texture_with_mips(String::new(), 20, 6, image(20, 6), false, 1024);
        assert_eq!(t.rgba8, chain.mips[2]);
        assert_eq!(t.mips[0], chain.mips[3]);
        let (fits, dropped) = texture_with_mips("edge".into(), 4, 4, image(4, 4), false, 4);
        assert_eq!((dropped, fits.width), (0, 4));
        assert_eq!(fits.byte_len(), 4 * 4 * 4 + 2 * 2 * 4 + 4);
    }
}
