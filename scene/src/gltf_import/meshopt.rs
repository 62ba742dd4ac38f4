//! `EXT_meshopt_compression` and `KHR_meshopt_compression`: buffer views whose bytes are
//! stored compressed by meshoptimizer's codecs in another buffer (gltfpack `-c`/`-cc`).
//!
//! The extension object on a buffer view names where the compressed bytes are (`buffer`,
//! `byteOffset`, `byteLength`), how many elements of which size they decode to (`count`,
//! `byteStride`), the codec (`mode`: `ATTRIBUTES`, `TRIANGLES` or `INDICES`) and a filter
//! applied after decoding (`NONE`, `OCTAHEDRAL`, `QUATERNION`, `EXPONENTIAL`, and for the KHR
//! version `COLOR`). The view's own buffer is then a *fallback* buffer, usually without data;
//! the decoded bytes stand for the view's bytes, so accessors read them unchanged.
//!
//! The `gltf` crate drops unknown extension objects, so they are read from the JSON here.
//! Every parameter is checked before meshoptimizer's decoders see it (they assert on sizes,
//! and the decoded size is capped relative to the compressed one), so a hostile file gets an
//! error, not an abort or an unbounded allocation.

use std::path::Path;

use serde_json::Value;

use crate::SceneError;

/// The two names of the extension (same JSON schema; the KHR one adds the `COLOR` filter and
/// a newer vertex codec, which the decoder reads too).
pub(super) const EXTENSIONS: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// The most bytes one compressed byte may decode to. meshoptimizer's codecs do not come near
/// it (constant data is about 1:64), so only a hostile header reaches it.
const MAX_EXPANSION: usize = 4096;

/// meshoptimizer's codec of a compressed view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Attributes,
    Triangles,
    Indices,
}

/// The filter applied to decoded attributes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Filter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
    Color,
}

/// One compressed buffer view, as its extension object describes it.
#[derive(Clone, Debug)]
pub(super) struct CompressedView {
    /// Which of [`EXTENSIONS`] it uses (for messages).
    ext: &'static str,
    /// Buffer holding the compressed bytes.
    pub buffer: usize,
    /// Their offset in that buffer.
    pub offset: usize,
    /// Their length.
    pub length: usize,
    stride: usize,
    count: usize,
    mode: Mode,
    filter: Filter,
}

/// The compression information of a document: per buffer view, its compressed source (if
/// any); per buffer, whether it is a fallback buffer (whose data need not exist).
#[derive(Debug, Default)]
pub(super) struct Compression {
    /// By buffer view index.
    pub views: Vec<Option<CompressedView>>,
    /// By buffer index.
    pub fallback: Vec<bool>,
}

/// Reads the extension objects of the document's buffer views and buffers from its JSON.
pub(super) fn read(root: &Value, file: &Path) -> Result<Compression, SceneError> {
    let malformed = |problem: String| SceneError::Malformed {
        file: file.to_path_buf(),
        problem,
    };
    fn ext_of(item: &Value) -> Option<(&'static str, &Value)> {
        EXTENSIONS
            .iter()
            .find_map(|name| Some((*name, item.get("extensions")?.get(*name)?)))
    }
    let list = |key: &str| {
        root.get(key)
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default()
    };
    let mut out = Compression::default();
    for buffer in list("buffers") {
        let fallback = ext_of(&buffer)
            .and_then(|(_, e)| e.get("fallback"))
            .and_then(Value::as_bool)
            .unwrap_or(false);
        out.fallback.push(fallback);
    }
    for (i, view) in list("bufferViews").iter().enumerate() {
        let Some((ext, e)) = ext_of(view) else {
            out.views.push(None);
            continue;
        };
        let bad = |what: String| malformed(format!("buffer view {i}: {ext}: {what}"));
        let size = |key: &str, required: bool| -> Result<usize, SceneError> {
            match e.get(key) {
                None if !required => Ok(0),
                None => Err(bad(format!("{key} is missing"))),
                Some(v) => v
                    .as_u64()
                    .and_then(|v| usize::try_from(v).ok())
                    .ok_or_else(|| bad(format!("{key} is not a non-negative integer: {v}"))),
            }
        };
        let word = |key: &str, default: Option<&'static str>| -> Result<String, SceneError> {
            match (e.get(key), default) {
                (None, Some(d)) => Ok(d.to_string()),
                (None, None) => Err(bad(format!("{key} is missing"))),
                (Some(v), _) => v
                    .as_str()
                    .map(str::to_string)
                    .ok_or_else(|| bad(format!("{key} is not a string: {v}"))),
            }
        };
        let mode = match word("mode", None)?.as_str() {
            "ATTRIBUTES" => Mode::Attributes,
            "TRIANGLES" => Mode::Triangles,
            "INDICES" => Mode::Indices,
            other => return Err(bad(format!("unknown mode {other:?}"))),
        };
        let filter = match word("filter", Some("NONE"))?.as_str() {
            "NONE" => Filter::None,
            "OCTAHEDRAL" => Filter::Octahedral,
            "QUATERNION" => Filter::Quaternion,
            "EXPONENTIAL" => Filter::Exponential,
            "COLOR" if ext == "KHR_meshopt_compression" => Filter::Color,
            other => return Err(bad(format!("unknown filter {other:?}"))),
        };
        let v = CompressedView {
            ext,
            buffer: size("buffer", true)?,
            offset: size("byteOffset", false)?,
            length: size("byteLength", true)?,
            stride: size("byteStride", true)?,
            count: size("count", true)?,
            mode,
            filter,
        };
        v.check().map_err(bad)?;
        out.views.push(Some(v));
    }
    Ok(out)
}

impl CompressedView {
    /// The sizes meshoptimizer's decoders and filters accept (they assert on them).
    fn check(&self) -> Result<(), String> {
        let (s, n) = (self.stride, self.count);
        match self.mode {
            Mode::Attributes if s == 0 || s % 4 != 0 || s > 256 => {
                return Err(format!(
                    "ATTRIBUTES byteStride {s} is not a multiple of 4 in 4..=256"
                ))
            }
            Mode::Triangles | Mode::Indices if s != 2 && s != 4 => {
                return Err(format!("{:?} byteStride {s} is not 2 or 4", self.mode))
            }
            Mode::Triangles if n % 3 != 0 => {
                return Err(format!("TRIANGLES count {n} is not a multiple of 3"))
            }
            _ => {}
        }
        let filter_ok = match self.filter {
            Filter::None => true,
            _ if self.mode != Mode::Attributes => false,
            Filter::Octahedral | Filter::Color => s == 4 || s == 8,
            Filter::Quaternion => s == 8,
            Filter::Exponential => true,
        };
        if !filter_ok {
            return Err(format!(
                "filter {:?} does not apply to mode {:?} with byteStride {s}",
                self.filter, self.mode
            ));
        }
        let decoded = n
            .checked_mul(s)
            .ok_or_else(|| format!("count {n} × byteStride {s} overflows"))?;
        if decoded > self.length.saturating_mul(MAX_EXPANSION).max(1 << 16) {
            return Err(format!(
                "{decoded} bytes cannot come from {} compressed bytes",
                self.length
            ));
        }
        Ok(())
    }

    /// The decoded size in bytes (`count × byteStride`).
    pub fn decoded_len(&self) -> usize {
        self.count * self.stride
    }

    /// Decodes `compressed` (this view's `length` bytes) into `count × byteStride` bytes.
    pub fn decode(&self, compressed: &[u8]) -> Result<Vec<u8>, String> {
        debug_assert!(self.check().is_ok());
        let size = self.decoded_len();
        // u32 words: the filters read 16- and 32-bit components in place, so the destination
        // is 4-byte aligned.
        let mut words = vec![0u32; size.div_ceil(4)];
        let dst = words.as_mut_ptr().cast::<std::ffi::c_void>();
        let (src, len) = (compressed.as_ptr(), compressed.len());
        let (n, s) = (self.count, self.stride);
        // SAFETY: `dst` holds at least `n × s` bytes, 4-byte aligned, and `src..src+len` is
        // `compressed`; `check` keeps the sizes to what the decoders and filters accept.
        let rc = unsafe {
            match self.mode {
                Mode::Attributes => meshopt::ffi::meshopt_decodeVertexBuffer(dst, n, s, src, len),
                Mode::Triangles => meshopt::ffi::meshopt_decodeIndexBuffer(dst, n, s, src, len),
                Mode::Indices => meshopt::ffi::meshopt_decodeIndexSequence(dst, n, s, src, len),
            }
        };
        if rc != 0 {
            return Err(format!(
                "{}: the {:?} data does not decode (meshoptimizer error {rc})",
                self.ext, self.mode
            ));
        }
        // SAFETY: as above; every filter was checked against the stride.
        unsafe {
            match self.filter {
                Filter::None => {}
                Filter::Octahedral => meshopt::ffi::meshopt_decodeFilterOct(dst, n, s),
                Filter::Quaternion => meshopt::ffi::meshopt_decodeFilterQuat(dst, n, s),
                Filter::Exponential => meshopt::ffi::meshopt_decodeFilterExp(dst, n, s),
                Filter::Color => meshopt::ffi::meshopt_decodeFilterColor(dst, n, s),
            }
        }
        let mut bytes: Vec<u8> = words.iter().flat_map(|w| w.to_ne_bytes()).collect();
        bytes.truncate(size);
        Ok(bytes)
    }
}
