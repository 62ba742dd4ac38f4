//! The file container: splitting a `.glb` into its chunks, parsing the JSON, reading buffers
//! (GLB binary chunk, external files, `data:` URIs) and noting extensions the importer ignores.

use std::path::{Path, PathBuf};

use std::collections::{BTreeMap, BTreeSet};

use super::draco::{self, DracoPrimitive};
use super::ktx2;
use super::meshopt::{self, Compression};
use super::Importer;
use crate::SceneError;

/// Extensions whose content the importer uses. A file may require these
/// (`extensionsRequired`); requiring any other is an [`SceneError::UnsupportedExtension`].
const HANDLED_EXTENSIONS: &[&str] = &[
    "KHR_materials_transmission",
    "KHR_materials_emissive_strength",
    // Read from the raw JSON of every texture reference (`materials.rs`).
    "KHR_texture_transform",
    // Its factors; its textures are noted per material as not rendered.
    "KHR_materials_clearcoat",
    // Quantized attributes: the accessor reader converts every component type.
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    draco::EXTENSION,
    // A texture's image in another format, preferred to its `source` (see `image_sources`).
    ktx2::EXTENSION,
    WEBP,
    // Each variant's material table is stored with the geometry (`Geometry::variants`).
    VARIANTS,
];

/// The material variants extension, whose names `inspect` lists.
const VARIANTS: &str = "KHR_materials_variants";

/// WebP images (decoded by the `image` crate's pure-Rust WebP decoder).
pub(super) const WEBP: &str = "EXT_texture_webp";

/// The texture extensions that give a texture an image of their own, in order of preference.
pub(super) const IMAGE_EXTENSIONS: [&str; 2] = [ktx2::EXTENSION, WEBP];

/// Points each texture with an image extension ([`IMAGE_EXTENSIONS`]) at that extension's
/// image: it is preferred to the texture's `source`, the fallback for viewers without the
/// extension, which such a texture may lack (gltfpack and glTF Transform write none). The
/// `gltf` crate then validates the index and every reader of `source` sees the image used.
fn image_sources(root: &mut gltf::json::Root, file: &Path) -> Result<(), SceneError> {
    for (t, texture) in root.textures.iter_mut().enumerate() {
        let Some(others) = texture.extensions.as_ref().map(|e| &e.others) else {
            continue;
        };
        let Some((name, ext)) =
            (IMAGE_EXTENSIONS.iter()).find_map(|&name| others.get(name).map(|ext| (name, ext)))
        else {
            continue;
        };
        let source = ext.get("source");
        match source
            .and_then(serde_json::Value::as_u64)
            .map(u32::try_from)
        {
            Some(Ok(image)) if image != u32::MAX => texture.source = gltf::json::Index::new(image),
            _ => {
                return Err(SceneError::Malformed {
                    file: file.to_path_buf(),
                    problem: format!(
                        "texture {t}: {name} source is {}, not an image index",
                        source.map_or_else(|| "missing".to_string(), |v| v.to_string())
                    ),
                })
            }
        }
    }
    Ok(())
}

/// The names of the document's material variants (`extensions.KHR_materials_variants.variants[].name`),
/// `""` for an unnamed one (or one whose name is not a string).
fn variant_names(root: &serde_json::Value) -> Vec<String> {
    let list = (root.get("extensions"))
        .and_then(|e| e.get(VARIANTS))
        .and_then(|v| v.get("variants"))
        .and_then(serde_json::Value::as_array);
    (list.into_iter().flatten())
        .map(|v| {
            let name = v.get("name").and_then(serde_json::Value::as_str);
            name.unwrap_or_default().to_string()
        })
        .collect()
}

/// Per primitive `(mesh, primitive)`: for each variant, the material it shows under that
/// variant (`None`: its default material).
pub(super) type VariantMaps = BTreeMap<(usize, usize), Vec<Option<u32>>>;

/// The primitives' `KHR_materials_variants` mappings, for `variants` variants over
/// `materials` materials, and a note per mapping left out (a material or variant index
/// outside the file's, a variant mapped twice in one primitive: the first mapping counts).
fn variant_maps(
    root: &serde_json::Value,
    variants: usize,
    materials: usize,
) -> (VariantMaps, Vec<String>) {
    let mut maps = VariantMaps::new();
    let mut notes = Vec::new();
    if variants == 0 {
        return (maps, notes);
    }
    let meshes = root.get("meshes").and_then(serde_json::Value::as_array);
    for (m, mesh) in meshes.into_iter().flatten().enumerate() {
        let prims = mesh.get("primitives").and_then(serde_json::Value::as_array);
        for (p, prim) in prims.into_iter().flatten().enumerate() {
            let mappings = (prim.get("extensions"))
                .and_then(|e| e.get(VARIANTS))
                .and_then(|v| v.get("mappings"))
                .and_then(serde_json::Value::as_array);
            let Some(mappings) = mappings else { continue };
            let mut map = vec![None; variants];
            for mapping in mappings {
                let material = mapping.get("material").and_then(serde_json::Value::as_u64);
                let list = mapping
                    .get("variants")
                    .and_then(serde_json::Value::as_array);
                let Some(material) = material.filter(|&i| (i as usize) < materials) else {
                    notes.push(format!(
                        "mesh {m} primitive {p}: a {VARIANTS} mapping names no material of the \
                         file's {materials}; left out"
                    ));
                    continue;
                };
                for v in list.into_iter().flatten() {
                    match v.as_u64().map(|v| v as usize) {
                        Some(v) if v < variants && map[v].is_none() => {
                            map[v] = Some(material as u32)
                        }
                        _ => notes.push(format!(
                            "mesh {m} primitive {p}: {VARIANTS} mapping of material {material} \
                             names variant {v}, which is not one of the file's {variants} or is \
                             mapped already; left out"
                        )),
                    }
                }
            }
            maps.insert((m, p), map);
        }
    }
    (maps, notes)
}

/// A parsed file: its glTF document, for GLB its binary chunk, and its meshopt-compressed
/// buffer views.
pub(super) struct Parsed<'a> {
    /// The document (validated by the `gltf` crate).
    pub doc: gltf::Document,
    /// The GLB binary chunk.
    pub bin: Option<&'a [u8]>,
    /// `EXT_meshopt_compression` / `KHR_meshopt_compression` views and fallback buffers.
    pub compression: Compression,
    /// `KHR_draco_mesh_compression` primitives by `(mesh, primitive)`.
    pub draco: BTreeMap<(usize, usize), DracoPrimitive>,
    /// Accessors of Draco primitives that have no data of their own (their buffer view is a
    /// placeholder in `doc`).
    pub placeholders: BTreeSet<usize>,
    /// Names of the `KHR_materials_variants` variants.
    pub variants: Vec<String>,
    /// The primitives' variant mappings.
    pub variant_maps: VariantMaps,
    /// Notes on mappings left out.
    pub variant_notes: Vec<String>,
}

/// Parses a file into its glTF document and, for GLB, its binary chunk. A required extension
/// outside [`HANDLED_EXTENSIONS`] is an error naming it.
pub(super) fn parse<'a>(bytes: &'a [u8], file: &Path) -> Result<Parsed<'a>, SceneError> {
    let (json, bin) = split_container(bytes, file)?;
    let json = json.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(json);
    let mut root = gltf::json::Root::from_slice(json).map_err(|e| SceneError::Malformed {
        file: file.to_path_buf(),
        problem: format!("invalid JSON: {e}"),
    })?;
    if let Some(name) =
        (root.extensions_required.iter()).find(|e| !HANDLED_EXTENSIONS.contains(&e.as_str()))
    {
        return Err(SceneError::UnsupportedExtension {
            file: file.to_path_buf(),
            name: name.clone(),
            hint: "the file requires it and trisort does not implement it".into(),
        });
    }
    image_sources(&mut root, file)?;
    // The `gltf` crate's validation refuses required extensions it does not know itself;
    // these are handled here.
    root.extensions_required
        .retain(|e| gltf::json::extensions::ENABLED_EXTENSIONS.contains(&e.as_str()));
    let uses = |names: &[&str]| (root.extensions_used.iter()).any(|e| names.contains(&e.as_str()));
    let (compression, draco, variants, (variant_maps, variant_notes)) =
        if uses(&meshopt::EXTENSIONS) || uses(&[draco::EXTENSION, VARIANTS]) {
            // The `gltf` crate drops extension objects it does not know: read them from the JSON.
            let raw: serde_json::Value =
                serde_json::from_slice(json).map_err(|e| SceneError::Malformed {
                    file: file.to_path_buf(),
                    problem: format!("invalid JSON: {e}"),
                })?;
            let draco = draco::read(&raw).map_err(|problem| SceneError::Malformed {
                file: file.to_path_buf(),
                problem,
            })?;
            let names = variant_names(&raw);
            let maps = variant_maps(&raw, names.len(), root.materials.len());
            (meshopt::read(&raw, file)?, draco, names, maps)
        } else {
            Default::default()
        };
    // A Draco primitive's accessors have no data of their own, which the `gltf` crate's
    // validation refuses: point them at the primitive's bitstream view for validation's sake.
    // They are never read from there ([`Importer::read_floats`] takes the decoded values).
    let mut placeholders = BTreeSet::new();
    for (&(m, p), d) in &draco {
        let Some(prim) = root.meshes.get(m).and_then(|mesh| mesh.primitives.get(p)) else {
            continue;
        };
        let used: Vec<usize> = (prim.attributes.values().map(|i| i.value()))
            .chain(prim.indices.map(|i| i.value()))
            .collect();
        for a in used {
            if let Some(acc) = root.accessors.get_mut(a) {
                if acc.buffer_view.is_none() && acc.sparse.is_none() {
                    acc.buffer_view = Some(gltf::json::Index::new(d.view as u32));
                    placeholders.insert(a);
                }
            }
        }
    }
    // gltf-json's validation indexes the POSITION accessor before checking that it exists
    // (gltf-json 1.4.1, mesh.rs); check it first so a dangling index is an error, not a panic.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &prim.attributes {
                if index.value() >= root.accessors.len() {
                    return Err(SceneError::Malformed {
                        file: file.to_path_buf(),
                        problem: format!(
                            "mesh {m} primitive {p}: attribute {semantic:?} names accessor {}, \
                             the file has {}",
                            index.value(),
                            root.accessors.len()
                        ),
                    });
                }
            }
        }
    }
    let doc = gltf::Document::from_json(root).map_err(|e| SceneError::Malformed {
        file: file.to_path_buf(),
        problem: e.to_string(),
    })?;
    Ok(Parsed {
        doc,
        bin,
        compression,
        draco,
        placeholders,
        variants,
        variant_maps,
        variant_notes,
    })
}

/// Splits a file into its JSON text and, for GLB, its binary chunk.
fn split_container<'a>(
    bytes: &'a [u8],
    file: &Path,
) -> Result<(&'a [u8], Option<&'a [u8]>), SceneError> {
    let malformed = |problem: String| SceneError::Malformed {
        file: file.to_path_buf(),
        problem,
    };
    let is_glb_name = file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if !bytes.starts_with(b"glTF") {
        if is_glb_name {
            return Err(malformed(
                "not a binary glTF file (it does not start with the magic \"glTF\")".into(),
            ));
        }
        return Ok((bytes, None));
    }
    if bytes.len() < 12 {
        return Err(malformed(format!(
            "truncated: {} bytes, shorter than the 12-byte GLB header",
            bytes.len()
        )));
    }
    let word =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let version = word(4);
    if version != 2 {
        return Err(malformed(format!("GLB version {version}, expected 2")));
    }
    let length = word(8) as usize;
    if length > bytes.len() {
        return Err(malformed(format!(
            "truncated: the GLB header declares {length} bytes, the file has {}",
            bytes.len()
        )));
    }
    if length < 12 {
        return Err(malformed(format!(
            "the GLB header declares a length of {length} bytes, less than the header itself"
        )));
    }
    let mut json = None;
    let mut bin = None;
    let mut at = 12;
    while at < length {
        if length - at < 8 {
            return Err(malformed(format!("truncated chunk header at byte {at}")));
        }
        let chunk_len = word(at) as usize;
        let kind = &bytes[at + 4..at + 8];
        let start = at + 8;
        if chunk_len > length - start {
            return Err(malformed(format!(
                "truncated: the chunk at byte {at} declares {chunk_len} bytes, {} remain",
                length - start
            )));
        }
        let data = &bytes[start..start + chunk_len];
        match (json.is_none(), kind) {
            (true, b"JSON") => json = Some(data),
            (true, _) => return Err(malformed("the first GLB chunk is not JSON".into())),
            (false, b"BIN\0") if bin.is_none() => bin = Some(data),
            // Unknown chunks must be ignored (glTF 2.0 § 4.4.3.1).
            _ => {}
        }
        at = start + chunk_len;
    }
    match json {
        Some(json) => Ok((json, bin)),
        None => Err(malformed("the GLB file has no JSON chunk".into())),
    }
}

/// Standard base64 (also accepting the URL-safe alphabet), padding optional, whitespace
/// ignored. `None` on any other character.
fn base64_decode(text: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    let mut acc: u32 = 0;
    let mut bits = 0;
    for &c in text.as_bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            b' ' | b'\n' | b'\r' | b'\t' => continue,
            _ => return None,
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// Decodes `%XX` escapes of a relative URI. `None` for a bad escape or non-UTF-8 result.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes.get(i + 1..i + 3)?;
            let hex = std::str::from_utf8(hex).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Reads the bytes a URI names: a base64 `data:` URI, or a path relative to `base`.
/// The error is a sentence without the glTF file's name.
pub(super) fn read_uri(uri: &str, base: Option<&Path>) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err("data: URI is not base64-encoded".into());
        };
        return base64_decode(payload).ok_or_else(|| "data: URI holds invalid base64".into());
    }
    let scheme = uri.split(['/', '\\']).next().unwrap_or("");
    if scheme.contains(':') {
        return Err(format!(
            "unsupported URI scheme in {uri:?} (only relative paths and data: URIs)"
        ));
    }
    let rel = percent_decode(uri).ok_or_else(|| format!("URI {uri:?} has a bad %-escape"))?;
    let path = match base {
        Some(base) => base.join(rel),
        None => PathBuf::from(rel),
    };
    std::fs::read(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}

impl Importer<'_> {
    /// Reads every buffer (a meshopt fallback buffer without data of its own stays empty),
    /// then decodes every meshopt-compressed buffer view.
    pub(super) fn load_buffers(&mut self, bin: Option<&[u8]>) -> Result<(), SceneError> {
        let mut bin = bin;
        for buffer in self.doc.buffers() {
            let err = |problem: String| SceneError::Buffer {
                file: self.file.clone(),
                buffer: buffer.index(),
                problem,
            };
            let fallback = self.compression.fallback.get(buffer.index()) == Some(&true);
            if fallback && matches!(buffer.source(), gltf::buffer::Source::Bin) {
                // Its views are decoded from other buffers; it has no bytes of its own.
                self.buffers.push(Vec::new());
                continue;
            }
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => bin
                    .take()
                    .ok_or_else(|| {
                        err(
                            "has no URI and there is no (unused) GLB binary chunk to hold it"
                                .into(),
                        )
                    })?
                    .to_vec(),
                gltf::buffer::Source::Uri(uri) => {
                    read_uri(uri, self.base.as_deref()).map_err(err)?
                }
            };
            if data.len() < buffer.length() {
                return Err(err(format!(
                    "holds {} bytes, {} declared (truncated?)",
                    data.len(),
                    buffer.length()
                )));
            }
            self.buffers.push(data);
        }
        self.decode_views()
    }

    /// Decodes the meshopt-compressed buffer views into [`Importer::decoded`].
    fn decode_views(&mut self) -> Result<(), SceneError> {
        let views = std::mem::take(&mut self.compression.views);
        self.decoded = Vec::with_capacity(views.len());
        for (i, v) in views.iter().enumerate() {
            let Some(v) = v else {
                self.decoded.push(None);
                continue;
            };
            let err = |problem: String| SceneError::Malformed {
                file: self.file.clone(),
                problem: format!("buffer view {i}: {problem}"),
            };
            let declared = self.doc.views().nth(i).map(|view| view.length());
            if declared != Some(v.decoded_len()) {
                return Err(err(format!(
                    "decodes to {} bytes, the view declares {declared:?}",
                    v.decoded_len()
                )));
            }
            let data = self.buffers.get(v.buffer).ok_or_else(|| {
                err(format!(
                    "compressed data in buffer {}, the file has {}",
                    v.buffer,
                    self.buffers.len()
                ))
            })?;
            let compressed = (v.offset.checked_add(v.length))
                .and_then(|end| data.get(v.offset..end))
                .ok_or_else(|| {
                    err(format!(
                        "compressed bytes {}+{} exceed buffer {} of {} bytes",
                        v.offset,
                        v.length,
                        v.buffer,
                        data.len()
                    ))
                })?;
            self.decoded.push(Some(v.decode(compressed).map_err(err)?));
        }
        Ok(())
    }

    /// Notes every extension the file uses that the importer ignores, and what is lost.
    pub(super) fn note_ignored_extensions(&mut self) {
        for ext in self.doc.extensions_used() {
            if !HANDLED_EXTENSIONS.contains(&ext) {
                let what = match ext {
                    "KHR_materials_volume" => "glass thickness and attenuation are not modelled",
                    _ => "not supported",
                };
                self.notes.push(format!("extension {ext} ignored: {what}"));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_known_text() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64_decode("aGVsbG8h").unwrap(), b"hello!");
        assert_eq!(base64_decode("aGk").unwrap(), b"hi");
        assert!(base64_decode("a*b").is_none());
    }

    #[test]
    fn percent_escapes_decode() {
        assert_eq!(percent_decode("a%20b.bin").unwrap(), "a b.bin");
        assert!(percent_decode("bad%2").is_none());
        assert!(percent_decode("%FF").is_none());
    }

    #[test]
    fn glb_header_lies_are_errors() {
        let file = Path::new("x.glb");
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(4u32.to_le_bytes());
        assert!(split_container(&glb, file).is_err());
        glb[8..12].copy_from_slice(&1000u32.to_le_bytes());
        assert!(split_container(&glb, file).is_err());
        glb[8..12].copy_from_slice(&12u32.to_le_bytes());
        assert!(split_container(&glb, file).is_err(), "no JSON chunk");
    }
}
