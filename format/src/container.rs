//! The checked container every trisort file uses, and atomic writes.
//!
//! Layout (little endian):
//!
//! | bytes | field |
//! |---|---|
//! | 8 | magic: `TRISREC\0` (Recording), `TRISBAK\0` (Baked) or `TRISPRE\0` (Presorted) |
//! | 4 | format version ([`FORMAT_VERSION`]) |
//! | 8 | length of the compressed payload |
//! | 8 | length of the decompressed payload |
//! | 32 | BLAKE3 hash of the compressed payload |
//! | n | payload: zstd(postcard(value)) |
//!
//! Reading never trusts the header for allocation: the payload length must match the file,
//! the checksum is verified before decompressing, decompression stops at the declared size
//! (which is capped), and postcard caps what it preallocates.
//!
//! Writing uses zstd's C library and exists only off wasm32; reading decompresses with zstd's C
//! decoder natively and with the pure-Rust `ruzstd` on wasm32 ([`decode_pure`] reaches that path
//! anywhere, so tests check that both decoders give the same bytes).

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
#[cfg(not(target_arch = "wasm32"))]
use serde::Serialize;

/// Current version of the container and of the types inside it. Files of another version are
/// refused ([`FormatError::Version`]), never guessed at.
///
/// History: 1, the first; 2, [`crate::MergeInfo`] stores its options as enums
/// ([`crate::options`]) instead of strings; 3, [`crate::RecordSettings`] stores how robust
/// the recording is ([`crate::Robust`]), and (before any release of 3) [`crate::Geometry`]
/// its material variants and [`crate::Recording`] and [`crate::Baked`] the path's fps. Files
/// of version 3 written before those two fields fail to decode with a "record or merge it
/// again" message (the checksum matches, the layout does not); 4, physically based
/// materials ([`crate::TextureSlot`]s, metallic-roughness, clearcoat), vertex tangents and a
/// second texture coordinate, texture colour spaces and mip chains, and the baked file's
/// [`crate::Environment`]; 5, [`crate::Robust`] ends with the bake's
/// [`crate::RasterProfile`].
pub const FORMAT_VERSION: u32 = 7;

/// Decompressed payloads larger than this are refused (16 GiB).
pub const MAX_PAYLOAD: u64 = 16 << 30;

const HEADER_LEN: usize = 8 + 4 + 8 + 8 + 32;

/// The kind of a trisort file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// A `Recording` (`trisort record`).
    Recording,
    /// A `Baked` file (`trisort merge`, `trisort bake`).
    Baked,
    /// A `Presorted` file (`trisort presort`).
    Presorted,
}

impl FileKind {
    /// The 8-byte magic.
    pub fn magic(self) -> &'static [u8; 8] {
        match self {
            FileKind::Recording => b"TRISREC\0",
            FileKind::Baked => b"TRISBAK\0",
            FileKind::Presorted => b"TRISPRE\0",
        }
    }

    /// A human name.
    pub fn name(self) -> &'static str {
        match self {
            FileKind::Recording => "recording",
            FileKind::Baked => "baked file",
            FileKind::Presorted => "presorted file",
        }
    }

    /// Which kind of file `bytes` starts like, if any.
    pub fn sniff(bytes: &[u8]) -> Option<FileKind> {
        [FileKind::Recording, FileKind::Baked, FileKind::Presorted]
            .into_iter()
            .find(|k| bytes.starts_with(k.magic()))
    }
}

/// Errors reading or writing a trisort file. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    /// An I/O error.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file does not start with the expected magic.
    #[error("{path}: not a trisort {expected} (wrong magic bytes)")]
    BadMagic {
        /// The file.
        path: PathBuf,
        /// What was expected.
        expected: &'static str,
    },
    /// The file is of another version.
    #[error(
        "{path}: format version {found} is not supported (this trisort reads {}); record or \
         merge it again with this trisort", versions_text(*.oldest, *.supported)
    )]
    Version {
        /// The file.
        path: PathBuf,
        /// The version in the file.
        found: u32,
        /// The version this build writes, the newest it reads.
        supported: u32,
        /// The oldest version this build reads for this kind of file (baked files of
        /// earlier versions are migrated in memory; recordings are read only at `supported`).
        oldest: u32,
    },
    /// The file is shorter or longer than its header says.
    #[error("{path}: truncated or padded: header says {expected} payload bytes, file has {found}")]
    Length {
        /// The file.
        path: PathBuf,
        /// Bytes the header declares.
        expected: u64,
        /// Bytes present.
        found: u64,
    },
    /// The checksum does not match.
    #[error("{path}: checksum mismatch: the file is corrupted")]
    Checksum {
        /// The file.
        path: PathBuf,
    },
    /// The payload cannot be decoded.
    #[error("{path}: corrupted payload: {reason}")]
    Payload {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
}

/// `version 6` or `versions 4 to 6`.
fn versions_text(oldest: u32, newest: u32) -> String {
    if oldest == newest {
        format!("version {newest}")
    } else {
        format!("versions {oldest} to {newest}")
    }
}

/// A type stored in the container: decoded at [`FORMAT_VERSION`], and at older versions where
/// it migrates them ([`Baked`](crate::Baked) does, from
/// [`legacy::OLDEST_READABLE`](crate::legacy::OLDEST_READABLE); a recording does not).
pub trait Stored: DeserializeOwned {
    /// The oldest format version read.
    const OLDEST: u32 = FORMAT_VERSION;

    /// Decodes the postcard payload of an older format `version` (`OLDEST ≤ version <
    /// FORMAT_VERSION`) and migrates it, or says why it cannot.
    fn decode_older(version: u32, raw: &[u8]) -> Result<Self, String> {
        let _ = raw;
        Err(format!("format version {version} is not migrated"))
    }

    /// Completes a decoded value: decodes what the file stores compressed (block-compressed
    /// textures, [`Geometry::decode_blocks`](crate::Geometry::decode_blocks)).
    fn after_decode(&mut self) -> Result<(), crate::StructureError> {
        Ok(())
    }
}

impl Stored for crate::Recording {
    fn after_decode(&mut self) -> Result<(), crate::StructureError> {
        self.geometry.decode_blocks()
    }
}

impl Stored for crate::Presorted {
    fn after_decode(&mut self) -> Result<(), crate::StructureError> {
        self.geometry.decode_blocks()
    }
}

impl Stored for crate::Baked {
    const OLDEST: u32 = crate::legacy::OLDEST_READABLE;

    fn after_decode(&mut self) -> Result<(), crate::StructureError> {
        self.geometry.decode_blocks()
    }

    fn decode_older(version: u32, raw: &[u8]) -> Result<Self, String> {
        crate::legacy::decode_baked(version, raw)
            .unwrap_or_else(|| Err(format!("format version {version} is not migrated")))
    }
}

/// The format version of container bytes that start with `kind`'s magic, without checking
/// more (`None`: too short or another kind).
pub fn version_of(kind: FileKind, bytes: &[u8]) -> Option<u32> {
    (bytes.len() >= 12 && &bytes[..8] == kind.magic())
        .then(|| u32::from_le_bytes(bytes[8..12].try_into().unwrap()))
}

/// Encodes `value` into the container bytes (not on wasm32: it needs zstd's C library).
#[cfg(not(target_arch = "wasm32"))]
pub fn encode<T: Serialize>(kind: FileKind, value: &T) -> Vec<u8> {
    let raw =
        postcard::to_stdvec(value).expect("postcard serialization of trisort types cannot fail");
    encode_payload(kind, &raw)
}

/// Wraps a postcard payload `raw` (whatever it holds) in a correct container: compressed,
/// with the right lengths and checksum. What [`encode`] writes; the fuzz targets and the
/// mutation fuzz (`scripts/mutation-fuzz.sh`) use it to reach the payload's decoding and the
/// structure checks past the checksum.
#[cfg(not(target_arch = "wasm32"))]
pub fn encode_payload(kind: FileKind, raw: &[u8]) -> Vec<u8> {
    let packed = zstd::encode_all(raw, 3).expect("zstd compression into memory cannot fail");
    let mut out = Vec::with_capacity(HEADER_LEN + packed.len());
    out.extend_from_slice(kind.magic());
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(packed.len() as u64).to_le_bytes());
    out.extend_from_slice(&(raw.len() as u64).to_le_bytes());
    out.extend_from_slice(blake3::hash(&packed).as_bytes());
    out.extend_from_slice(&packed);
    out
}

/// Decodes container bytes read from `path` (used only in messages), migrating a baked file
/// of an older version ([`Stored`]).
pub fn decode<T: Stored>(kind: FileKind, bytes: &[u8], path: &Path) -> Result<T, FormatError> {
    decode_with(kind, bytes, path, cfg!(target_arch = "wasm32"))
}

/// [`decode`] with the pure-Rust `ruzstd` decompressor on every target (the path wasm32 builds
/// always take); same checks, same result.
pub fn decode_pure<T: Stored>(kind: FileKind, bytes: &[u8], path: &Path) -> Result<T, FormatError> {
    decode_with(kind, bytes, path, true)
}

fn decode_with<T: Stored>(
    kind: FileKind,
    bytes: &[u8],
    path: &Path,
    pure: bool,
) -> Result<T, FormatError> {
    let p = || path.to_path_buf();
    if bytes.len() < 8 || &bytes[..8] != kind.magic() {
        return Err(FormatError::BadMagic {
            path: p(),
            expected: kind.name(),
        });
    }
    if bytes.len() < HEADER_LEN {
        return Err(FormatError::Length {
            path: p(),
            expected: HEADER_LEN as u64,
            found: bytes.len() as u64,
        });
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    if !(T::OLDEST..=FORMAT_VERSION).contains(&version) {
        return Err(FormatError::Version {
            path: p(),
            found: version,
            supported: FORMAT_VERSION,
            oldest: T::OLDEST,
        });
    }
    let packed_len = u64::from_le_bytes(bytes[12..20].try_into().unwrap());
    let raw_len = u64::from_le_bytes(bytes[20..28].try_into().unwrap());
    let payload = &bytes[HEADER_LEN..];
    if packed_len != payload.len() as u64 {
        return Err(FormatError::Length {
            path: p(),
            expected: packed_len,
            found: payload.len() as u64,
        });
    }
    if blake3::hash(payload).as_bytes() != &bytes[28..60] {
        return Err(FormatError::Checksum { path: p() });
    }
    if raw_len > MAX_PAYLOAD {
        return Err(FormatError::Payload {
            path: p(),
            reason: format!("declared size {raw_len} bytes exceeds the limit of {MAX_PAYLOAD}"),
        });
    }
    let raw = decompress(payload, raw_len, pure)
        .map_err(|reason| FormatError::Payload { path: p(), reason })?;
    if raw.len() as u64 != raw_len {
        return Err(FormatError::Payload {
            path: p(),
            reason: format!("decompressed to {} bytes, header says {raw_len}", raw.len()),
        });
    }
    // The checksum matched, so a payload that does not decode was most likely written by
    // another build whose types differ at the same version (postcard is not self-describing:
    // a field added before a release shifts everything after it).
    let rewrite = format!(
        "the checksum matches, so another trisort build of format version {version} with a \
         different layout probably wrote it: record or merge it again with this trisort"
    );
    let mut value = if version != FORMAT_VERSION {
        T::decode_older(version, &raw).map_err(|e| FormatError::Payload {
            path: p(),
            reason: format!("decoding version {version} failed: {e}; {rewrite}"),
        })?
    } else {
        let (value, rest) =
            postcard::take_from_bytes::<T>(&raw).map_err(|e| FormatError::Payload {
                path: p(),
                reason: format!("decoding failed: {e}; {rewrite}"),
            })?;
        if !rest.is_empty() {
            return Err(FormatError::Payload {
                path: p(),
                reason: format!("{} trailing bytes; {rewrite}", rest.len()),
            });
        }
        value
    };
    value.after_decode().map_err(|e| FormatError::Payload {
        path: p(),
        reason: e.to_string(),
    })?;
    Ok(value)
}

/// Decompresses `payload`, stopping one byte past `raw_len`. The buffer grows as data arrives:
/// never preallocate what the header claims. `pure`: with ruzstd (always so on wasm32).
fn decompress(payload: &[u8], raw_len: u64, pure: bool) -> Result<Vec<u8>, String> {
    let mut raw = Vec::new();
    let failed = |e: std::io::Error| format!("decompression failed: {e}");
    #[cfg(not(target_arch = "wasm32"))]
    if !pure {
        let decoder = zstd::Decoder::new(payload).map_err(|e| e.to_string())?;
        decoder
            .take(raw_len + 1)
            .read_to_end(&mut raw)
            .map_err(failed)?;
        return Ok(raw);
    }
    let _ = pure;
    let decoder = ruzstd::decoding::StreamingDecoder::new(payload).map_err(|e| e.to_string())?;
    decoder
        .take(raw_len + 1)
        .read_to_end(&mut raw)
        .map_err(failed)?;
    Ok(raw)
}

/// Reads and decodes a file of the given kind.
pub fn read_file<T: Stored>(kind: FileKind, path: &Path) -> Result<T, FormatError> {
    let bytes = std::fs::read(path).map_err(|source| FormatError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    decode(kind, &bytes, path)
}

/// Writes `bytes` to `path` atomically: into a temporary file in the same directory, synced,
/// then renamed over `path`, and the directory synced so the rename itself survives a power
/// loss (where the platform lets a directory be opened). A crash leaves either the old file or
/// the new one, never half.
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<(), FormatError> {
    let io = |source| FormatError::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| io(std::io::Error::other("not a file path")))?;
    let tmp = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)?;
        if let Ok(d) = std::fs::File::open(&dir) {
            // Best effort: not every platform syncs a directory handle.
            let _ = d.sync_all();
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(io)
}

/// Encodes `value` and writes it atomically to `path` (not on wasm32).
#[cfg(not(target_arch = "wasm32"))]
pub fn write_file_atomic<T: Serialize>(
    kind: FileKind,
    path: &Path,
    value: &T,
) -> Result<(), FormatError> {
    write_bytes_atomic(path, &encode(kind, value))
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Stored for Vec<(u32, String)> {}

    fn sample() -> Vec<(u32, String)> {
        (0..1000).map(|i| (i, format!("item {i}"))).collect()
    }

    #[test]
    fn round_trip_and_atomic_write() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.rec");
        write_file_atomic(FileKind::Recording, &path, &sample()).unwrap();
        let back: Vec<(u32, String)> = read_file(FileKind::Recording, &path).unwrap();
        assert_eq!(back, sample());
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "temporary file left behind: {names:?}");
    }

    #[test]
    fn every_truncation_and_bit_flip_is_an_error() {
        let bytes = encode(FileKind::Baked, &sample());
        let path = Path::new("t.baked");
        for len in 0..bytes.len() {
            assert!(
                decode::<Vec<(u32, String)>>(FileKind::Baked, &bytes[..len], path).is_err(),
                "len {len}"
            );
        }
        for i in (0..bytes.len()).step_by(7) {
            let mut b = bytes.clone();
            b[i] ^= 0x10;
            assert!(
                decode::<Vec<(u32, String)>>(FileKind::Baked, &b, path).is_err(),
                "flip at {i}"
            );
        }
        assert!(matches!(
            decode::<Vec<(u32, String)>>(FileKind::Recording, &bytes, path),
            Err(FormatError::BadMagic { .. })
        ));
    }

    #[test]
    fn huge_declared_size_is_refused_without_allocating() {
        let mut bytes = encode(FileKind::Baked, &sample());
        bytes[20..28].copy_from_slice(&(u64::MAX / 2).to_le_bytes());
        let err = decode::<Vec<(u32, String)>>(FileKind::Baked, &bytes, Path::new("h.baked"))
            .unwrap_err();
        assert!(err.to_string().contains("h.baked"), "{err}");
    }

    #[test]
    fn a_file_of_a_version_not_read_is_refused_with_what_to_do() {
        let mut bytes = encode(FileKind::Baked, &sample());
        bytes[8..12].copy_from_slice(&(FORMAT_VERSION - 1).to_le_bytes());
        let err = decode::<Vec<(u32, String)>>(FileKind::Baked, &bytes, Path::new("old.baked"))
            .unwrap_err();
        assert!(matches!(
            err,
            FormatError::Version {
                found: 6,
                supported: 7,
                oldest: 7,
                ..
            }
        ));
        assert_eq!(
            err.to_string(),
            "old.baked: format version 6 is not supported (this trisort reads version 7); \
             record or merge it again with this trisort"
        );
        // A baked file reads back to version 4 (migrated), not version 3.
        bytes[8..12].copy_from_slice(&3u32.to_le_bytes());
        let err =
            decode::<crate::Baked>(FileKind::Baked, &bytes, Path::new("old.baked")).unwrap_err();
        assert!(
            err.to_string()
                .contains("format version 3 is not supported (this trisort reads versions 4 to 7)"),
            "{err}"
        );
    }

    #[test]
    fn ruzstd_decodes_what_zstd_encodes() {
        let bytes = encode(FileKind::Baked, &sample());
        let path = Path::new("p.baked");
        let native: Vec<(u32, String)> = decode(FileKind::Baked, &bytes, path).unwrap();
        let pure: Vec<(u32, String)> = decode_pure(FileKind::Baked, &bytes, path).unwrap();
        assert_eq!(native, pure);
        assert_eq!(pure, sample());
        // The raw payloads, byte for byte, including a multi-block one (> 128 KiB).
        let big: Vec<u8> = (0..600_000u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        let packed = zstd::encode_all(&big[..], 3).unwrap();
        let n = big.len() as u64;
        assert_eq!(decompress(&packed, n, true).unwrap(), big);
        assert_eq!(decompress(&packed, n, false).unwrap(), big);
    }

    /// A file of this version written by a build whose types had fewer fields (here: a
    /// struct that later gained a trailing field) is refused, saying what to do.
    #[test]
    fn an_older_layout_of_the_same_version_is_refused_with_what_to_do() {
        #[derive(serde::Serialize)]
        struct Before {
            a: u32,
            b: Vec<u8>,
        }
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct After {
            a: u32,
            b: Vec<u8>,
            fps: Option<f64>,
        }
        impl Stored for After {}
        let bytes = encode(
            FileKind::Baked,
            &Before {
                a: 7,
                b: vec![1, 2, 3],
            },
        );
        let err = decode::<After>(FileKind::Baked, &bytes, Path::new("early.baked")).unwrap_err();
        let text = err.to_string();
        assert!(
            text.starts_with("early.baked: corrupted payload: decoding failed"),
            "{text}"
        );
        assert!(
            text.ends_with("record or merge it again with this trisort"),
            "{text}"
        );
    }

    #[test]
    fn wrong_version_is_named() {
        let mut bytes = encode(FileKind::Baked, &sample());
        bytes[8..12].copy_from_slice(&99u32.to_le_bytes());
        let err = decode::<Vec<(u32, String)>>(FileKind::Baked, &bytes, Path::new("v.baked"))
            .unwrap_err();
        assert!(err.to_string().contains("version 99"), "{err}");
    }
}
