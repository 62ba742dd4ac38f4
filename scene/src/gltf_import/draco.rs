//! `KHR_draco_mesh_compression`: a primitive whose attributes and indices are one Draco
//! bitstream in a buffer view, decoded by `draco-core` (a pure-Rust Draco decoder).
//!
//! The extension object on a primitive names the buffer view and, per attribute semantic,
//! the attribute's unique id in the bitstream; the primitive's own accessors (without buffer
//! views) give each attribute's type and count. The decoded values stand for those
//! accessors' data, so the rest of the importer reads them like any other. Decoding happens
//! when a primitive of the imported scene is read, so meshes outside the scene are not
//! decoded (as they are not read otherwise). The decoder's default limits (2 GiB of decoded
//! values) bound what a hostile header can make it allocate.

use std::collections::BTreeMap;

use draco_core::{DecoderBuffer, Mesh, MeshDecoder};
use gltf::accessor::DataType;
use serde_json::Value;

use super::{mesh_label, Importer};
use crate::SceneError;

/// The extension's name.
pub(super) const EXTENSION: &str = "KHR_draco_mesh_compression";

/// One compressed primitive, as its extension object describes it.
#[derive(Clone, Debug)]
pub(super) struct DracoPrimitive {
    /// Buffer view holding the bitstream.
    pub view: usize,
    /// Attribute semantic (`POSITION`, …) → unique id of the attribute in the bitstream.
    attributes: BTreeMap<String, u32>,
}

/// Reads the extension objects of every primitive: `(mesh, primitive)` → its compression.
pub(super) fn read(root: &Value) -> Result<BTreeMap<(usize, usize), DracoPrimitive>, String> {
    let mut out = BTreeMap::new();
    let meshes = root.get("meshes").and_then(Value::as_array);
    for (m, mesh) in meshes.into_iter().flatten().enumerate() {
        let prims = mesh.get("primitives").and_then(Value::as_array);
        for (p, prim) in prims.into_iter().flatten().enumerate() {
            let Some(e) = prim.get("extensions").and_then(|x| x.get(EXTENSION)) else {
                continue;
            };
            let bad = |what: &str| format!("mesh {m} primitive {p}: {EXTENSION}: {what}");
            let view = (e.get("bufferView").and_then(Value::as_u64))
                .and_then(|v| usize::try_from(v).ok())
                .ok_or_else(|| bad("bufferView is missing or not an index"))?;
            let mut attributes = BTreeMap::new();
            let map = (e.get("attributes").and_then(Value::as_object))
                .ok_or_else(|| bad("attributes is missing or not an object"))?;
            for (semantic, id) in map {
                let id = (id.as_u64())
                    .and_then(|v| u32::try_from(v).ok())
                    .ok_or_else(|| bad(&format!("attribute {semantic:?} id {id} is not an id")))?;
                attributes.insert(semantic.clone(), id);
            }
            out.insert((m, p), DracoPrimitive { view, attributes });
        }
    }
    Ok(out)
}

/// `x`, an integer component widened to f32, as the accessor's normalized value.
fn normalize(kind: DataType, x: f32) -> f32 {
    match kind {
        DataType::U8 => x / 255.0,
        DataType::I8 => (x / 127.0).max(-1.0),
        DataType::U16 => x / 65535.0,
        DataType::I16 => (x / 32767.0).max(-1.0),
        DataType::U32 => (f64::from(x) / f64::from(u32::MAX)) as f32,
        DataType::F32 => x,
    }
}

impl Importer<'_> {
    /// Decodes the primitive's Draco bitstream, if it has one, into [`Importer::draco_floats`]
    /// and [`Importer::draco_indices`] for its accessors.
    pub(super) fn decode_draco(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
    ) -> Result<(), SceneError> {
        let Some(d) = self.draco.get(&(mesh.index(), prim.index())).cloned() else {
            return Ok(());
        };
        let err = |problem: String| SceneError::Malformed {
            file: self.file.clone(),
            problem: format!(
                "{} primitive {}: {EXTENSION}: {problem}",
                mesh_label(mesh),
                prim.index()
            ),
        };
        let view = (self.doc.views().nth(d.view))
            .ok_or_else(|| err(format!("buffer view {} does not exist", d.view)))?;
        let bytes = self.view_bytes(&view).map_err(err)?;
        let mut decoded = Mesh::new();
        MeshDecoder::new()
            .decode(&mut DecoderBuffer::new(bytes), &mut decoded)
            .map_err(|e| err(format!("the bitstream does not decode: {e}")))?;
        let points = decoded.num_points();
        let mut floats = Vec::new();
        for (semantic, id) in &d.attributes {
            // Attributes the primitive does not list are not read.
            let Some(accessor) = (prim.attributes()).find(|(s, _)| s.to_string() == *semantic)
            else {
                continue;
            };
            let acc = accessor.1;
            let attribute = (decoded.attribute_by_unique_id(*id))
                .ok_or_else(|| err(format!("{semantic}: no attribute with id {id}")))?;
            if acc.count() != points {
                return Err(err(format!(
                    "{semantic}: accessor {} has {} elements, the bitstream {points} points",
                    acc.index(),
                    acc.count()
                )));
            }
            let comps = acc.dimensions().multiplicity();
            let mut values = attribute.read_f32s(points, comps);
            if acc.normalized() {
                let kind = acc.data_type();
                values.iter_mut().for_each(|x| *x = normalize(kind, *x));
            }
            floats.push((acc.index(), values));
        }
        let Some(indices) = prim.indices() else {
            return Err(err("the primitive has no indices accessor".into()));
        };
        let flat: Vec<u32> = (decoded.faces().iter())
            .flat_map(|f| f.map(|p| p.0))
            .collect();
        if indices.count() != flat.len() {
            return Err(err(format!(
                "indices accessor {} has {} elements, the bitstream {} faces",
                indices.index(),
                indices.count(),
                decoded.num_faces()
            )));
        }
        if let Some(k) = flat.iter().position(|&i| i as usize >= points) {
            return Err(err(format!(
                "index {} at position {k} is out of range ({points} points)",
                flat[k]
            )));
        }
        for (accessor, values) in floats {
            self.draco_floats.insert(accessor, values);
        }
        self.draco_indices.insert(indices.index(), flat);
        Ok(())
    }
}
