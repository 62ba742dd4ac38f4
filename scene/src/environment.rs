//! Environment light from a file: a Radiance `.hdr` equirectangular image, prefiltered into a
//! [`trisort_format::Environment`].

use std::io::Cursor;
use std::path::{Path, PathBuf};

use image::codecs::hdr::HdrDecoder;
use image::ImageDecoder;
use trisort_format::Environment;

/// The most texels [`load_hdr`] decodes (8192 × 8192; 12 bytes each while decoding).
pub const MAX_HDR_TEXELS: u64 = 1 << 26;

/// Why an environment image could not be loaded. Every message starts with the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EnvironmentError {
    /// The file could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a Radiance HDR image.
    #[error(
        "{}: not a Radiance HDR image ({problem}); an environment is an equirectangular .hdr file",
        file.display()
    )]
    NotHdr {
        /// The file.
        file: PathBuf,
        /// What was found instead.
        problem: String,
    },
    /// The HDR header or pixels are truncated or corrupt.
    #[error("{}: truncated or corrupt HDR image: {problem}", file.display())]
    Corrupt {
        /// The file.
        file: PathBuf,
        /// What the decoder said.
        problem: String,
    },
    /// The HDR image uses a feature the decoder lacks (an orientation other than `-Y h +X w`).
    #[error("{}: unsupported HDR image: {problem}", file.display())]
    Unsupported {
        /// The file.
        file: PathBuf,
        /// What the decoder said.
        problem: String,
    },
    /// The image decoded but cannot be an environment (too large, empty, a non-finite or
    /// negative texel).
    #[error("{}: unusable as an environment: {problem}", file.display())]
    Unusable {
        /// The file.
        file: PathBuf,
        /// Why.
        problem: String,
    },
}

/// Loads an equirectangular Radiance `.hdr` image (row 0 at the zenith, column 0 looking along
/// +X, the image's middle column along −X; [`Environment`] describes the mapping) and
/// prefilters it ([`trisort_light::from_equirect`]). The environment is named after the file
/// (its name without folders), has no sun and exposure 1.
///
/// Files starting `#?RADIANCE` are read strictly, other `#?` signatures (`#?RGBE`) leniently.
/// Errors name the file: missing or unreadable, not an HDR image, a truncated or corrupt one,
/// one stored in another orientation than `-Y h +X w` (rows top down), more than
/// [`MAX_HDR_TEXELS`] texels, or texels that are not finite and non-negative.
pub fn load_hdr(path: &Path) -> Result<Environment, EnvironmentError> {
    let file = || path.to_path_buf();
    let bytes = std::fs::read(path).map_err(|source| EnvironmentError::Io {
        file: file(),
        source,
    })?;
    if !bytes.starts_with(b"#?") {
        let head = String::from_utf8_lossy(&bytes[..bytes.len().min(10)]).into_owned();
        return Err(EnvironmentError::NotHdr {
            file: file(),
            problem: if bytes.is_empty() {
                "the file is empty".into()
            } else {
                format!("it starts {head:?}, not \"#?RADIANCE\"")
            },
        });
    }
    let corrupt = |e: image::ImageError| match e {
        image::ImageError::Unsupported(_) => EnvironmentError::Unsupported {
            file: file(),
            problem: e.to_string(),
        },
        _ => EnvironmentError::Corrupt {
            file: file(),
            problem: e.to_string(),
        },
    };
    let strict = bytes.starts_with(b"#?RADIANCE");
    let decoder = HdrDecoder::with_strictness(Cursor::new(&bytes[..]), strict).map_err(corrupt)?;
    let (width, height) = decoder.dimensions();
    let texels = width as u64 * height as u64;
    if texels > MAX_HDR_TEXELS {
        return Err(EnvironmentError::Unusable {
            file: file(),
            problem: format!(
                "{width}×{height} texels is more than {MAX_HDR_TEXELS}; resize it first \
                 (trisort uses it at 128×64)"
            ),
        });
    }
    let mut raw = vec![0u8; (texels * 12) as usize];
    decoder.read_image(&mut raw).map_err(corrupt)?;
    let rgb: Vec<f32> = raw
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string());
    trisort_light::from_equirect(&name, width, height, &rgb).map_err(|problem| {
        EnvironmentError::Unusable {
            file: file(),
            problem,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::codecs::hdr::HdrEncoder;
    use image::Rgb;

    /// Writes a `w` × `h` HDR image, brighter in its top half, to `path`.
    fn write_hdr(path: &Path, w: usize, h: usize) {
        let pixels: Vec<Rgb<f32>> = (0..w * h)
            .map(|i| {
                if i / w < h / 2 {
                    Rgb([2.0, 1.5, 1.0])
                } else {
                    Rgb([0.25; 3])
                }
            })
            .collect();
        let mut out = Vec::new();
        HdrEncoder::new(&mut out).encode(&pixels, w, h).unwrap();
        std::fs::write(path, out).unwrap();
    }

    #[test]
    fn loads_an_hdr_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sky.hdr");
        write_hdr(&path, 64, 32);
        let env = load_hdr(&path).unwrap();
        env.check_structure().unwrap();
        assert_eq!(env.name, "sky.hdr");
        assert_eq!((env.sun, env.exposure), (None, 1.0));
        // The bright half is above: row 0 of level 0 holds its (RGBE-rounded) radiance.
        let top = env.texel(0, 5, 0);
        assert!(
            (top[0] - 2.0).abs() < 0.02 && (top[2] - 1.0).abs() < 0.02,
            "{top:?}"
        );
        assert!(env.irradiance([0.0, 1.0, 0.0])[0] > env.irradiance([0.0, -1.0, 0.0])[0]);
    }

    #[test]
    fn bad_files_are_refused_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.hdr");
        let e = load_hdr(&missing).unwrap_err().to_string();
        assert!(
            e.starts_with(&missing.display().to_string()) && e.contains("cannot read"),
            "{e}"
        );

        let png = dir.path().join("picture.hdr");
        std::fs::write(&png, b"\x89PNG\r\n\x1a\n....").unwrap();
        let e = load_hdr(&png).unwrap_err().to_string();
        assert!(e.starts_with(&png.display().to_string()), "{e}");
        assert!(e.contains("not a Radiance HDR image"), "{e}");

        let empty = dir.path().join("empty.hdr");
        std::fs::write(&empty, b"").unwrap();
        let e = load_hdr(&empty).unwrap_err().to_string();
        assert!(e.contains("the file is empty"), "{e}");

        let good = dir.path().join("good.hdr");
        write_hdr(&good, 64, 32);
        let bytes = std::fs::read(&good).unwrap();
        let cut = dir.path().join("cut.hdr");
        std::fs::write(&cut, &bytes[..bytes.len() - 40]).unwrap();
        let e = load_hdr(&cut).unwrap_err().to_string();
        assert!(e.starts_with(&cut.display().to_string()), "{e}");
        assert!(e.contains("truncated or corrupt"), "{e}");

        let header_only = dir.path().join("header.hdr");
        std::fs::write(&header_only, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n").unwrap();
        let e = load_hdr(&header_only).unwrap_err().to_string();
        assert!(e.contains("truncated or corrupt"), "{e}");

        let flipped = dir.path().join("flipped.hdr");
        std::fs::write(
            &flipped,
            b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+Y 8 +X 16\n",
        )
        .unwrap();
        let e = load_hdr(&flipped).unwrap_err().to_string();
        assert!(
            e.contains("unsupported HDR image") && e.contains("+Y +X"),
            "{e}"
        );

        let huge = dir.path().join("huge.hdr");
        std::fs::write(
            &huge,
            b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n",
        )
        .unwrap();
        let e = load_hdr(&huge).unwrap_err().to_string();
        assert!(e.contains("unusable") && e.contains("100000×100000"), "{e}");
    }

    #[test]
    fn rgbe_signature_is_read_leniently() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("good.hdr");
        write_hdr(&good, 16, 8);
        let mut bytes = std::fs::read(&good).unwrap();
        assert!(bytes.starts_with(b"#?RADIANCE"));
        bytes.splice(..10, b"#?RGBE".iter().copied());
        let rgbe = dir.path().join("rgbe.hdr");
        std::fs::write(&rgbe, bytes).unwrap();
        assert_eq!(
            load_hdr(&rgbe).unwrap().levels,
            load_hdr(&good).unwrap().levels
        );
    }
}
