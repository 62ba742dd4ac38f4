//! `bake`/`merge --textures`: block-compresses a baked file's textures (issue 34), so the file
//! and the GPU memory a player needs shrink to a quarter (ETC2 with alpha, ASTC 4×4, BC7) or
//! an eighth (ETC2 without alpha) of RGBA8.
//!
//! Encoders: Intel's ISPC Texture Compressor through `intel_tex_2` (BC7, ASTC; prebuilt
//! kernels, no C++ build) and etcpak through `ctt-etcpak` (ETC2 RGB and RGBA with EAC alpha,
//! which the ISPC compressor lacks). Decoding, on reading a file, is `trisort_format::blocks`'
//! (texture2ddecoder). Basis Universal output is left out: its encoder is C++ (basisu) with
//! no maintained Rust crate, and the player would need a transcoder besides.
//!
//! **Exactness.** Alpha decides visibility where a material reads it (base-colour textures of
//! MASK and BLEND materials: the recorder discards cut and transparent fragments), sampled at
//! level 0. The recording was made with the scene's RGBA8 texels, so such a texture is stored
//! compressed only if its blocks decode to the *same* level-0 alpha, texel for texel; else it
//! stays RGBA8, and the report says why. ASTC's alpha is decoded past 8 bits by some devices,
//! so with ASTC such a texture must be opaque (alpha 255 everywhere, encoded without alpha).
//! Colour changes; [`TextureOutcome::psnr_db`] measures by how much, and the stored RGBA8
//! levels become the decoded blocks, so every player, the exact reference and `verify` see
//! the texels a device sampling the blocks does.

use rayon::prelude::*;
use trisort_format::gpu_layout::tiled;
use trisort_format::{BlockFormat, Geometry, Texture, TextureBlocks};

impl From<BlockFormat> for TextureFormat {
    /// The `--textures` value that stores blocks of `format`.
    fn from(format: BlockFormat) -> TextureFormat {
        match format {
            BlockFormat::Etc2Rgb8 | BlockFormat::Etc2Rgba8 => TextureFormat::Etc2,
            BlockFormat::Astc4x4 => TextureFormat::Astc,
            BlockFormat::Bc7 => TextureFormat::Bc7,
        }
    }
}

/// Why `--textures astc` is refused by a trisort built without the `astc` feature.
pub const ASTC_MISSING: &str = "this trisort was built without ASTC encoding: install it with \
     `cargo install --path . --features astc` (ARM's astcenc, C++ compiled \
     from source); etc2 and bc7 need nothing more";

/// What `--textures` asks for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TextureFormat {
    /// RGBA8, uncompressed (the default: exact colour).
    #[default]
    Rgba8,
    /// ETC2: RGB8 for opaque textures, RGBA8 (EAC alpha) for the rest. OpenGL ES 3 and mobile
    /// Vulkan GPUs sample it natively.
    Etc2,
    /// ASTC LDR 4×4. Mobile GPUs.
    Astc,
    /// BC7. Desktop GPUs.
    Bc7,
}

impl TextureFormat {
    /// The names `--textures` takes, in order.
    pub const NAMES: [&'static str; 4] = ["rgba8", "etc2", "astc", "bc7"];

    /// Its `--textures` name.
    pub fn name(self) -> &'static str {
        match self {
            TextureFormat::Rgba8 => "rgba8",
            TextureFormat::Etc2 => "etc2",
            TextureFormat::Astc => "astc",
            TextureFormat::Bc7 => "bc7",
        }
    }
}

impl std::str::FromStr for TextureFormat {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "rgba8" => Ok(TextureFormat::Rgba8),
            "etc2" => Ok(TextureFormat::Etc2),
            "astc" if cfg!(feature = "astc") => Ok(TextureFormat::Astc),
            "astc" => Err(ASTC_MISSING.to_string()),
            "bc7" => Ok(TextureFormat::Bc7),
            _ => Err(format!(
                "unknown texture format {s:?}: one of {} (basis is not offered: no Rust \
                 encoder)",
                Self::NAMES.join(", ")
            )),
        }
    }
}

/// What became of one texture.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureOutcome {
    /// Its index in the geometry.
    pub texture: u32,
    /// Its name.
    pub name: String,
    /// Width × height.
    pub size: (u32, u32),
    /// The block format it is stored in; `None`: RGBA8.
    pub stored: Option<BlockFormat>,
    /// Why it stays RGBA8 when compression was asked for.
    pub kept_because: Option<String>,
    /// Whether its alpha decides visibility (a MASK or BLEND material's base colour).
    pub alpha_decides_visibility: bool,
    /// Peak signal-to-noise ratio of level 0's colour (RGB) after compression against before,
    /// in dB (`None`: unchanged; infinite PSNR).
    pub psnr_db: Option<f64>,
    /// The largest difference of any level-0 channel, alpha included, in 8-bit steps.
    pub max_difference: u8,
    /// Bytes of every level as RGBA8.
    pub rgba8_bytes: u64,
    /// Bytes of every level as stored (blocks, or RGBA8).
    pub stored_bytes: u64,
}

/// What [`compress`] did to every texture.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureReport {
    /// What was asked for.
    pub format: TextureFormat,
    /// Per texture, in geometry order.
    pub textures: Vec<TextureOutcome>,
    /// Seconds encoding and decoding took.
    pub seconds: f64,
}

impl TextureReport {
    /// Textures stored as blocks.
    pub fn compressed(&self) -> usize {
        self.textures.iter().filter(|t| t.stored.is_some()).count()
    }

    /// Bytes of every texture level as RGBA8, and as stored.
    pub fn bytes(&self) -> (u64, u64) {
        (
            self.textures.iter().map(|t| t.rgba8_bytes).sum(),
            self.textures.iter().map(|t| t.stored_bytes).sum(),
        )
    }

    /// The lowest PSNR of a compressed texture's colour (`None`: none changed).
    pub fn worst_psnr_db(&self) -> Option<f64> {
        self.textures
            .iter()
            .filter_map(|t| t.psnr_db)
            .min_by(f64::total_cmp)
    }

    /// `bake`/`merge --json`'s `textures` object.
    pub fn to_json(&self) -> serde_json::Value {
        let (rgba8, stored) = self.bytes();
        let kept: Vec<serde_json::Value> = (self.textures.iter())
            .filter_map(|t| {
                let why = t.kept_because.as_ref()?;
                Some(serde_json::json!({"texture": t.texture, "name": t.name, "reason": why}))
            })
            .collect();
        let per_texture: Vec<serde_json::Value> = (self.textures.iter())
            .map(|t| {
                serde_json::json!({
                    "texture": t.texture,
                    "name": t.name,
                    "width": t.size.0,
                    "height": t.size.1,
                    "stored": t.stored.map_or("rgba8".to_string(), |f| f.to_string()),
                    "alpha_decides_visibility": t.alpha_decides_visibility,
                    "psnr_db": t.psnr_db,
                    "max_difference": t.max_difference,
                    "bytes": t.stored_bytes,
                })
            })
            .collect();
        serde_json::json!({
            "format": self.format.name(),
            "count": self.textures.len(),
            "compressed": self.compressed(),
            "kept_rgba8": kept,
            "rgba8_bytes": rgba8,
            "stored_bytes": stored,
            "worst_psnr_db": self.worst_psnr_db(),
            "seconds": self.seconds,
            "per_texture": per_texture,
        })
    }

    /// One line for the human summary.
    pub fn summary(&self) -> String {
        let (rgba8, stored) = self.bytes();
        let kept = self.textures.len() - self.compressed();
        let psnr = self
            .worst_psnr_db()
            .map_or("colour unchanged".to_string(), |p| {
                format!("worst colour PSNR {p:.1} dB")
            });
        format!(
            "textures {}: {} of {} compressed ({kept} kept RGBA8), {:.1} MB → {:.1} MB \
             ({:.2}×), {psnr}; {:.1} s",
            self.format.name(),
            self.compressed(),
            self.textures.len(),
            rgba8 as f64 / 1e6,
            stored as f64 / 1e6,
            stored as f64 / rgba8.max(1) as f64,
            self.seconds
        )
    }
}

/// Compresses `geometry`'s textures to `format` where that keeps visibility exact (module
/// docs), replacing each compressed texture's RGBA8 levels with its blocks decoded. `Rgba8`
/// leaves everything as it is. Textures are encoded in parallel.
pub fn compress(geometry: &mut Geometry, format: TextureFormat) -> TextureReport {
    let t0 = std::time::Instant::now();
    let alpha = geometry.alpha_decides_visibility();
    let textures: Vec<TextureOutcome> = (geometry.textures.par_iter_mut())
        .enumerate()
        .map(|(i, t)| compress_one(i as u32, t, format, alpha[i]))
        .collect();
    TextureReport {
        format,
        textures,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

/// For `verify --scene`: gives `scene` (the textures as imported) the stored texels of every
/// texture `baked` stores block-compressed, after checking them against the scene's own
/// rather than taking the file's word: same size and colour space, and, where the scene's
/// materials let alpha decide visibility ([`Geometry::alpha_decides_visibility`] of the
/// scene), the same level-0
/// alpha texel for texel. The colour error is measured, not excused: the report's PSNR and
/// largest difference per texture. `None` when the file stores no blocks.
pub fn adopt_stored(
    scene: &mut Geometry,
    baked: &Geometry,
) -> Result<Option<TextureReport>, String> {
    let Some(first) = baked.textures.iter().find_map(|t| t.blocks.as_ref()) else {
        return Ok(None);
    };
    if scene.textures.len() != baked.textures.len() {
        return Err(format!(
            "the scene has {} textures, the baked file {}",
            scene.textures.len(),
            baked.textures.len()
        ));
    }
    let format = TextureFormat::from(first.format);
    let alpha = scene.alpha_decides_visibility();
    let mut textures = Vec::new();
    for (i, (s, b)) in scene.textures.iter_mut().zip(&baked.textures).enumerate() {
        let Some(blocks) = &b.blocks else { continue };
        if (s.width, s.height, s.srgb) != (b.width, b.height, b.srgb) {
            return Err(format!(
                "texture {i} {:?}: the scene's is {}×{} ({}), the baked file's {}×{} ({})",
                s.name,
                s.width,
                s.height,
                if s.srgb { "sRGB" } else { "linear" },
                b.width,
                b.height,
                if b.srgb { "sRGB" } else { "linear" }
            ));
        }
        if alpha[i] {
            let changed = (s.rgba8.chunks_exact(4).zip(b.rgba8.chunks_exact(4)))
                .filter(|(x, y)| x[3] != y[3])
                .count();
            if changed > 0 {
                return Err(format!(
                    "texture {i} {:?}: its alpha decides visibility, and the baked file's {} \
                     blocks change it in {changed} level-0 texels",
                    s.name, blocks.format
                ));
            }
        }
        let (psnr, max) = difference(&s.rgba8, &b.rgba8);
        textures.push(TextureOutcome {
            texture: i as u32,
            name: s.name.clone(),
            size: (s.width, s.height),
            stored: Some(blocks.format),
            kept_because: None,
            alpha_decides_visibility: alpha[i],
            psnr_db: psnr,
            max_difference: max,
            rgba8_bytes: s.byte_len(),
            stored_bytes: blocks.byte_len(),
        });
        *s = b.clone();
    }
    Ok(Some(TextureReport {
        format,
        textures,
        seconds: 0.0,
    }))
}

/// [`compress`] of one texture.
fn compress_one(
    index: u32,
    t: &mut Texture,
    format: TextureFormat,
    alpha_decides: bool,
) -> TextureOutcome {
    let mut outcome = TextureOutcome {
        texture: index,
        name: t.name.clone(),
        size: (t.width, t.height),
        stored: t.blocks.as_ref().map(|b| b.format),
        kept_because: None,
        alpha_decides_visibility: alpha_decides,
        psnr_db: None,
        max_difference: 0,
        rgba8_bytes: t.byte_len(),
        stored_bytes: t.blocks.as_ref().map_or(t.byte_len(), |b| b.byte_len()),
    };
    if format == TextureFormat::Rgba8 || t.blocks.is_some() {
        return outcome;
    }
    if !(t.width.is_power_of_two() && t.height.is_power_of_two()) {
        outcome.kept_because = Some(format!(
            "{}×{} is not a power of two (a texture array tiles blocks only then)",
            t.width, t.height
        ));
        return outcome;
    }
    let opaque = std::iter::once(&t.rgba8)
        .chain(&t.mips)
        .all(|l| l.chunks_exact(4).all(|p| p[3] == 255));
    let block = match format {
        TextureFormat::Rgba8 => unreachable!("returned above"),
        TextureFormat::Etc2 if opaque => BlockFormat::Etc2Rgb8,
        TextureFormat::Etc2 => BlockFormat::Etc2Rgba8,
        TextureFormat::Astc if alpha_decides && !opaque => {
            outcome.kept_because = Some(
                "its alpha decides visibility and is not 255 everywhere; ASTC alpha may \
                 decode past 8 bits on a device"
                    .into(),
            );
            return outcome;
        }
        TextureFormat::Astc => BlockFormat::Astc4x4,
        TextureFormat::Bc7 => BlockFormat::Bc7,
    };
    // Level 0 first: its alpha decides whether the texture is compressed at all, and the
    // mips are encoded only when it is.
    let mut blocks = TextureBlocks {
        format: block,
        levels: vec![encode_level(
            block,
            &t.rgba8,
            (t.width, t.height),
            opaque,
            t.srgb,
        )],
    };
    let level0 = blocks.decode_level(t.width, t.height, 0);
    if alpha_decides {
        let changed = (t.rgba8.chunks_exact(4).zip(level0.chunks_exact(4)))
            .filter(|(a, b)| a[3] != b[3])
            .count();
        if changed > 0 {
            outcome.kept_because = Some(format!(
                "its alpha decides visibility and {changed} level-0 texels' alpha \
                 would change in {block}"
            ));
            return outcome;
        }
    }
    for (k, level) in t.mips.iter().enumerate() {
        let (w, h) = Texture::level_size(t.width, t.height, k as u32 + 1);
        (blocks.levels).push(encode_level(block, level, (w, h), opaque, t.srgb));
    }
    let decoded: Vec<Vec<u8>> = std::iter::once(level0)
        .chain((1..blocks.levels.len()).map(|k| blocks.decode_level(t.width, t.height, k)))
        .collect();
    let (psnr, max) = difference(&t.rgba8, &decoded[0]);
    outcome.psnr_db = psnr;
    outcome.max_difference = max;
    outcome.stored = Some(block);
    outcome.stored_bytes = blocks.byte_len();
    let mut decoded = decoded.into_iter();
    t.rgba8 = decoded.next().expect("level 0");
    t.mips = decoded.collect();
    t.blocks = Some(blocks);
    outcome
}

/// Encodes a `w` × `h` RGBA8 level into `format`'s blocks; a level narrower or shorter than
/// a block is repeated to fill it first (what [`TextureBlocks`] stores). `opaque`: alpha is
/// 255 everywhere (encoded without an alpha channel where the encoder has that mode); `srgb`:
/// the colour is sRGB-encoded (ASTC weighs its error so).
pub fn encode_level(
    format: BlockFormat,
    level: &[u8],
    (w, h): (u32, u32),
    opaque: bool,
    srgb: bool,
) -> Vec<u8> {
    let (pw, ph) = (w.max(4), h.max(4));
    let padded;
    let data = if (pw, ph) == (w, h) {
        level
    } else {
        padded = tiled(level, (w, h), (pw, ph));
        &padded
    };
    let rgba = intel_tex_2::RgbaSurface {
        data,
        width: pw,
        height: ph,
        stride: pw * 4,
    };
    match format {
        BlockFormat::Bc7 => {
            let settings = if opaque {
                intel_tex_2::bc7::opaque_basic_settings()
            } else {
                intel_tex_2::bc7::alpha_basic_settings()
            };
            intel_tex_2::bc7::compress_blocks(&settings, &rgba)
        }
        BlockFormat::Astc4x4 => encode_astc(data, pw, ph, srgb),
        BlockFormat::Etc2Rgb8 | BlockFormat::Etc2Rgba8 => {
            // etcpak reads B, G, R, A.
            let bgra: Vec<u8> = (data.chunks_exact(4))
                .flat_map(|p| [p[2], p[1], p[0], p[3]])
                .collect();
            let surface = ctt_etcpak::Surface::new(&bgra, pw, ph);
            if format == BlockFormat::Etc2Rgb8 {
                ctt_etcpak::etc2_rgb::compress_blocks(&surface, true)
            } else {
                ctt_etcpak::etc2_rgba::compress_blocks(&surface, true)
            }
        }
    }
}

/// ASTC 4×4 blocks of a `w` × `h` RGBA8 image (multiples of 4), by ARM's astcenc at its
/// `fast` preset, in the LDR profile of the texture's colour space.
#[cfg(feature = "astc")]
fn encode_astc(data: &[u8], w: u32, h: u32, srgb: bool) -> Vec<u8> {
    use ctt_astcenc as astc;
    let profile = if srgb {
        astc::Profile::LdrSrgb
    } else {
        astc::Profile::Ldr
    };
    let config = astc::config_init(profile, 4, 4, 1, astc::Preset::Fast, astc::Flags::empty())
        .expect("astcenc accepts 4×4 LDR blocks at the fast preset");
    let mut context = astc::Context::new(&config).expect("astcenc allocates a context");
    let mut texels = data.to_vec();
    let mut planes = [texels.as_mut_ptr().cast::<std::ffi::c_void>()];
    let mut image = astc::bindings::astcenc_image {
        dim_x: w,
        dim_y: h,
        dim_z: 1,
        data_type: astc::bindings::astcenc_type_ASTCENC_TYPE_U8,
        data: planes.as_mut_ptr(),
    };
    let mut out = vec![0u8; BlockFormat::Astc4x4.level_bytes(w, h)];
    context
        .compress(&mut image, astc::Swizzle::IDENTITY, &mut out)
        .expect("astcenc compresses a whole-block LDR image");
    out
}

/// Without the `astc` feature `--textures astc` is refused when parsed
/// ([`TextureFormat::from_str`]), so no ASTC level is ever encoded.
#[cfg(not(feature = "astc"))]
fn encode_astc(_data: &[u8], _w: u32, _h: u32, _srgb: bool) -> Vec<u8> {
    unreachable!("--textures astc is refused without the astc feature")
}

/// The PSNR of `after`'s colour (RGB) against `before`'s in dB (`None` where equal), and the
/// largest difference of any channel.
pub fn difference(before: &[u8], after: &[u8]) -> (Option<f64>, u8) {
    let mut sum = 0u64;
    let mut max = 0u8;
    let mut n = 0u64;
    for (a, b) in before.chunks_exact(4).zip(after.chunks_exact(4)) {
        for c in 0..4 {
            let d = a[c].abs_diff(b[c]);
            max = max.max(d);
            if c < 3 {
                sum += d as u64 * d as u64;
                n += 1;
            }
        }
    }
    if sum == 0 {
        return (None, max);
    }
    let mse = sum as f64 / n as f64;
    (Some(10.0 * (255.0f64 * 255.0 / mse).log10()), max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use trisort_format::AlphaMode;

    /// A `size`² texture: a smooth colour ramp, and alpha `alpha(x, y)`.
    fn ramp(size: u32, alpha: impl Fn(u32, u32) -> u8) -> Texture {
        let mut level0 = Vec::new();
        for y in 0..size {
            for x in 0..size {
                let (u, v) = (x * 255 / size.max(2), y * 255 / size.max(2));
                level0.extend([u as u8, v as u8, ((u + v) / 2) as u8, alpha(x, y)]);
            }
        }
        trisort_scene::mips::texture_with_mips(
            "ramp".into(),
            size,
            size,
            level0,
            true,
            trisort_scene::mips::MAX_SIZE,
        )
        .0
    }

    fn one_texture(t: Texture, mode: AlphaMode) -> Geometry {
        let mut g = Geometry {
            textures: vec![t],
            ..Default::default()
        };
        let m = trisort_format::Material {
            alpha_mode: mode,
            base_color_texture: Some(0),
            ..Default::default()
        };
        g.materials.push(m);
        g
    }

    #[test]
    fn every_format_compresses_and_decodes_close_to_the_original() {
        let mut formats = vec![
            (TextureFormat::Etc2, BlockFormat::Etc2Rgb8, 8),
            (TextureFormat::Bc7, BlockFormat::Bc7, 4),
        ];
        if cfg!(feature = "astc") {
            formats.push((TextureFormat::Astc, BlockFormat::Astc4x4, 4));
        } else {
            let e = "astc".parse::<TextureFormat>().unwrap_err();
            assert!(e.contains("--features astc"), "{e}");
        }
        for (format, block, ratio) in formats {
            let mut g = one_texture(ramp(64, |_, _| 255), AlphaMode::Opaque);
            let before = g.textures[0].clone();
            let report = compress(&mut g, format);
            let t = &report.textures[0];
            assert_eq!(t.stored, Some(block), "{format:?}");
            let psnr = t.psnr_db.unwrap();
            // A smooth ramp: every codec keeps it well above 30 dB (a wrong channel order
            // or block layout falls far below).
            assert!(psnr > 30.0, "{format:?}: {psnr} dB");
            // Level 0 and the 4×4 levels are exactly 1/ratio of RGBA8; 2×2 and 1×1 a block.
            assert_eq!(
                t.stored_bytes,
                (64 * 64 * 4 + 32 * 32 * 4 + 16 * 16 * 4 + 8 * 8 * 4 + 4 * 4 * 4) / ratio
                    + 2 * block.block_bytes() as u64,
                "{format:?}"
            );
            // The texture holds its blocks decoded, and a file's reader decodes the same.
            let stored = &g.textures[0];
            assert_ne!(stored.rgba8, before.rgba8);
            let mut read = g.clone();
            read.textures[0].rgba8.clear();
            read.textures[0].mips.clear();
            read.decode_blocks().unwrap();
            assert_eq!(read.textures[0], *stored);
            read.check_structure().unwrap();
        }
    }

    #[test]
    fn alpha_that_decides_visibility_stays_exact_or_stays_rgba8() {
        // A hard cut-out: alpha 0 or 255 in 4×4 squares, which block codecs keep exactly.
        let cut = |x: u32, y: u32| {
            if (x / 4 + y / 4).is_multiple_of(2) {
                255
            } else {
                0
            }
        };
        // A smooth alpha ramp: lossy in every codec.
        let smooth = |x: u32, y: u32| ((x * 7 + y * 3) % 256) as u8;
        for format in [TextureFormat::Etc2, TextureFormat::Bc7] {
            let mut g = one_texture(ramp(32, cut), AlphaMode::Mask);
            let before = g.textures[0].rgba8.clone();
            let report = compress(&mut g, format);
            assert!(report.textures[0].alpha_decides_visibility);
            assert!(
                report.textures[0].stored.is_some(),
                "{format:?}: {report:?}"
            );
            let after = &g.textures[0].rgba8;
            assert!(before
                .chunks(4)
                .zip(after.chunks(4))
                .all(|(a, b)| a[3] == b[3]));

            let mut g = one_texture(ramp(32, smooth), AlphaMode::Blend);
            let before = g.textures[0].clone();
            let report = compress(&mut g, format);
            let why = report.textures[0].kept_because.as_deref().unwrap();
            assert!(why.contains("alpha decides visibility"), "{why}");
            assert_eq!(g.textures[0], before, "{format:?}: unchanged");
            // The same smooth alpha in an opaque material does not decide anything.
            let mut g = one_texture(ramp(32, smooth), AlphaMode::Opaque);
            assert!(compress(&mut g, format).textures[0].stored.is_some());
        }
        // ASTC keeps a cut-out RGBA8 too: alpha decoded past 8 bits on a device. (Refused
        // before any encoding, so this needs no astcenc.)
        let mut g = one_texture(ramp(32, cut), AlphaMode::Mask);
        let report = compress(&mut g, TextureFormat::Astc);
        assert!(report.textures[0].kept_because.is_some());
        assert_eq!(report.compressed(), 0);
    }

    #[test]
    fn odd_sizes_and_tiny_textures() {
        // Not a power of two: kept.
        let mut g = one_texture(ramp(12, |_, _| 255), AlphaMode::Opaque);
        let r = compress(&mut g, TextureFormat::Bc7);
        assert!(r.textures[0]
            .kept_because
            .as_deref()
            .unwrap()
            .contains("power of two"));
        // 1×1 and 2×2: one block each level, decoding to the texture's own texels' codes.
        for size in [1, 2] {
            let mut g = one_texture(ramp(size, |_, _| 255), AlphaMode::Opaque);
            let r = compress(&mut g, TextureFormat::Etc2);
            assert_eq!(r.textures[0].stored, Some(BlockFormat::Etc2Rgb8));
            g.check_structure().unwrap();
        }
    }

    #[test]
    fn verify_adopts_stored_texels_only_with_the_scene_s_alpha() {
        let cut = |x: u32, y: u32| {
            if (x / 4 + y / 4).is_multiple_of(2) {
                255
            } else {
                0
            }
        };
        let scene = one_texture(ramp(32, cut), AlphaMode::Mask);
        let mut baked = scene.clone();
        compress(&mut baked, TextureFormat::Bc7);
        let mut adopted = scene.clone();
        let report = adopt_stored(&mut adopted, &baked).unwrap().unwrap();
        assert_eq!(adopted.textures, baked.textures);
        assert_eq!(report.compressed(), 1);
        assert!(report.textures[0].alpha_decides_visibility);
        // A file whose blocks changed the cut-out's alpha is refused, naming the texture.
        let mut forged = baked.clone();
        forged.textures[0].rgba8[3] ^= 0xff;
        let e = adopt_stored(&mut scene.clone(), &forged).unwrap_err();
        assert!(
            e.contains("texture 0") && e.contains("1 level-0 texels"),
            "{e}"
        );
        // So is one of another size, and a file without blocks leaves the scene alone.
        let mut other = one_texture(ramp(16, cut), AlphaMode::Mask);
        compress(&mut other, TextureFormat::Bc7);
        assert!(adopt_stored(&mut scene.clone(), &other).is_err());
        assert_eq!(adopt_stored(&mut scene.clone(), &scene).unwrap(), None);
    }
}
