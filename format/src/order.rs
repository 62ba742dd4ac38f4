//! The ORDER file: trisort's sorted triangle list named by glTF source triangles.
//!
//! This module holds the file format only: its types, reading, writing and checking. Building
//! an order from a baked file needs the glTF importer, so it lives with the C API
//! (`trisort_capi::order::export`), which the `export-order` command calls too.
//!
//! Layout (little endian, no compression; docs/FORMAT.md § ORDER is the specification):
//!
//! | bytes | field |
//! |---|---|
//! | 8 | magic `TRISORD\0` |
//! | 4 | version ([`ORDER_VERSION`]) |
//! | 4 | flags: bit 0 set when the bake split intersecting triangles ([`Order::split`]) |
//! | 32 | the baked file's scene hash |
//! | 4 | frame count F |
//! | 4 | range count R |
//! | 4 | triangle count T |
//! | 4 | reserved, 0 |
//! | 8·F | per frame: first range, range count |
//! | 8·R | per range, front to back: first triangle, triangle count |
//! | 16·T | per index-buffer triangle, front to back: mesh, primitive, triangle, node |
//!
//! The file is exactly that long; readers refuse anything else.

use std::path::{Path, PathBuf};

use crate::{FormatError, Hash};

/// The ORDER file's magic bytes.
pub const ORDER_MAGIC: &[u8; 8] = b"TRISORD\0";
/// The ORDER file version this build writes and reads.
pub const ORDER_VERSION: u32 = 1;
const HEADER_LEN: usize = 8 + 4 + 4 + 32 + 4 * 4;

/// One run of consecutive index-buffer triangles drawn by one call.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OrderRange {
    /// First triangle (multiply by 3 for the first index).
    pub first: u32,
    /// Number of triangles.
    pub count: u32,
}

/// Where one index-buffer triangle comes from in the glTF file (all indices of the file).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OrderSource {
    /// Mesh index.
    pub mesh: u32,
    /// Primitive index within the mesh.
    pub primitive: u32,
    /// Triangle index within the primitive (its indices `3t, 3t+1, 3t+2` for a triangle
    /// list; strips and fans as the glTF specification derives them).
    pub triangle: u32,
    /// Node index (the instance of the mesh: its world transform moves the triangle).
    pub node: u32,
}

/// An order-only export of a baked file.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Order {
    /// Whether the bake split intersecting triangles: consecutive entries of a range can then
    /// name the same source triangle (its pieces), see docs/FORMAT.md § ORDER.
    pub split: bool,
    /// The baked file's scene hash.
    pub scene_hash: Hash,
    /// Per frame, its window in `ranges`.
    pub frames: Vec<OrderRange>,
    /// Draw ranges over `triangles`, front to back within each frame.
    pub ranges: Vec<OrderRange>,
    /// Per index-buffer triangle, front to back, its source.
    pub triangles: Vec<OrderSource>,
}

/// Why an ORDER file could not be read or written. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum OrderError {
    /// Reading or writing failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not a valid ORDER file.
    #[error("{path}: not a valid trisort ORDER file: {problem}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// Writing failed other than by I/O.
    #[error(transparent)]
    Format(#[from] FormatError),
}

impl Order {
    /// The ranges of frame `f`, front to back.
    pub fn frame_ranges(&self, f: usize) -> &[OrderRange] {
        let w = self.frames[f];
        &self.ranges[w.first as usize..(w.first + w.count) as usize]
    }

    /// The file's bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(
            HEADER_LEN + 8 * (self.frames.len() + self.ranges.len()) + 16 * self.triangles.len(),
        );
        out.extend_from_slice(ORDER_MAGIC);
        let words = |out: &mut Vec<u8>, xs: &[u32]| {
            for x in xs {
                out.extend_from_slice(&x.to_le_bytes());
            }
        };
        words(&mut out, &[ORDER_VERSION, self.split as u32]);
        out.extend_from_slice(&self.scene_hash);
        words(
            &mut out,
            &[
                self.frames.len() as u32,
                self.ranges.len() as u32,
                self.triangles.len() as u32,
                0,
            ],
        );
        for r in self.frames.iter().chain(&self.ranges) {
            words(&mut out, &[r.first, r.count]);
        }
        for s in &self.triangles {
            words(&mut out, &[s.mesh, s.primitive, s.triangle, s.node]);
        }
        out
    }

    /// Parses and checks an ORDER file read from `path` (used in messages): magic, version,
    /// exact length, frames inside the range list, ranges inside the triangle list.
    pub fn decode(bytes: &[u8], path: &Path) -> Result<Order, OrderError> {
        let bad = |problem: String| OrderError::Malformed {
            path: path.to_path_buf(),
            problem,
        };
        if bytes.len() < 8 || &bytes[..8] != ORDER_MAGIC {
            return Err(bad("wrong magic bytes".into()));
        }
        if bytes.len() < HEADER_LEN {
            return Err(bad(format!(
                "{} bytes, shorter than the {HEADER_LEN}-byte header",
                bytes.len()
            )));
        }
        let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let version = word(8);
        if version != ORDER_VERSION {
            return Err(bad(format!(
                "version {version} is not supported (this trisort reads {ORDER_VERSION})"
            )));
        }
        let flags = word(12);
        if flags & !1 != 0 {
            return Err(bad(format!("unknown flags {flags:#x}")));
        }
        let scene_hash: Hash = bytes[16..48].try_into().unwrap();
        let (nf, nr, nt) = (word(48) as u64, word(52) as u64, word(56) as u64);
        let expected = HEADER_LEN as u64 + 8 * (nf + nr) + 16 * nt;
        if bytes.len() as u64 != expected {
            return Err(bad(format!(
                "{} bytes, the header's counts ({nf} frames, {nr} ranges, {nt} triangles) \
                 need {expected}",
                bytes.len()
            )));
        }
        let pairs = |at: usize, n: u64| -> Vec<OrderRange> {
            (0..n as usize)
                .map(|k| OrderRange {
                    first: word(at + 8 * k),
                    count: word(at + 8 * k + 4),
                })
                .collect()
        };
        let frames = pairs(HEADER_LEN, nf);
        let ranges = pairs(HEADER_LEN + 8 * nf as usize, nr);
        let at = HEADER_LEN + 8 * (nf + nr) as usize;
        let triangles = (0..nt as usize)
            .map(|k| OrderSource {
                mesh: word(at + 16 * k),
                primitive: word(at + 16 * k + 4),
                triangle: word(at + 16 * k + 8),
                node: word(at + 16 * k + 12),
            })
            .collect();
        for (f, w) in frames.iter().enumerate() {
            if w.first as u64 + w.count as u64 > nr {
                return Err(bad(format!(
                    "frame {f}'s ranges lie outside the range list"
                )));
            }
        }
        for (k, r) in ranges.iter().enumerate() {
            if r.first as u64 + r.count as u64 > nt {
                return Err(bad(format!("range {k} lies outside the triangle list")));
            }
        }
        Ok(Order {
            split: flags & 1 != 0,
            scene_hash,
            frames,
            ranges,
            triangles,
        })
    }

    /// Reads and checks an ORDER file.
    pub fn read(path: &Path) -> Result<Order, OrderError> {
        let bytes = std::fs::read(path).map_err(|source| OrderError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Order::decode(&bytes, path)
    }

    /// Writes the file atomically (a temporary file renamed into place).
    pub fn write(&self, path: &Path) -> Result<(), OrderError> {
        crate::container::write_bytes_atomic(path, &self.encode()).map_err(|e| match e {
            FormatError::Io { path, source } => OrderError::Io { path, source },
            other => OrderError::Format(other),
        })
    }
}
