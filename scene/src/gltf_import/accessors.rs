//! Accessors: bounds-checked reads of buffer views and accessors (strided, normalized,
//! sparse), never through the `gltf` crate's readers, which can panic on hostile data.

use gltf::accessor::{DataType, Dimensions};

use super::Importer;
use crate::SceneError;

/// An accessor without a buffer view holds zeros (plus sparse values); its `count` is then not
/// backed by any data, so it is capped to keep a hostile header from allocating unbounded memory.
const MAX_VIEWLESS_ELEMENTS: usize = 1 << 24;

/// Converts one component of an accessor to f32, applying `normalized` integer scaling.
fn float_reader(kind: DataType, normalized: bool) -> fn(&[u8]) -> f32 {
    match (kind, normalized) {
        (DataType::F32, _) => |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::U8, false) => |b| f32::from(b[0]),
        (DataType::U8, true) => |b| f32::from(b[0]) / 255.0,
        (DataType::I8, false) => |b| f32::from(b[0] as i8),
        (DataType::I8, true) => |b| (f32::from(b[0] as i8) / 127.0).max(-1.0),
        (DataType::U16, false) => |b| f32::from(u16::from_le_bytes([b[0], b[1]])),
        (DataType::U16, true) => |b| f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
        (DataType::I16, false) => |b| f32::from(i16::from_le_bytes([b[0], b[1]])),
        (DataType::I16, true) => {
            |b| (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
        }
        (DataType::U32, false) => |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
        (DataType::U32, true) => |b| {
            (f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])) / f64::from(u32::MAX)) as f32
        },
    }
}

/// Reads one unsigned integer component (u8, u16 or u32).
fn index_reader(kind: DataType) -> Option<fn(&[u8]) -> u32> {
    match kind {
        DataType::U8 => Some(|b| u32::from(b[0])),
        DataType::U16 => Some(|b| u32::from(u16::from_le_bytes([b[0], b[1]]))),
        DataType::U32 => Some(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        _ => None,
    }
}

impl Importer<'_> {
    /// The bytes of a buffer view, checked against its buffer.
    /// For a meshopt-compressed view, its decoded bytes.
    pub(super) fn view_bytes(&self, view: &gltf::buffer::View) -> Result<&[u8], String> {
        if let Some(Some(decoded)) = self.decoded.get(view.index()) {
            return Ok(decoded);
        }
        let data = &self.buffers[view.buffer().index()];
        let start = view.offset();
        start
            .checked_add(view.length())
            .and_then(|end| data.get(start..end))
            .ok_or_else(|| {
                format!(
                    "buffer view {} (bytes {start}+{}) exceeds buffer {} of {} bytes",
                    view.index(),
                    view.length(),
                    view.buffer().index(),
                    data.len()
                )
            })
    }

    /// Reads every component of an accessor (flattened, `count × components`), including
    /// sparse substitution, with bounds checks. `convert` decodes one component.
    fn read_components<T: Copy + Default>(
        &self,
        accessor: &gltf::Accessor,
        usage: &str,
        convert: impl Fn(&[u8]) -> T,
    ) -> Result<Vec<T>, SceneError> {
        let err = |problem: String| SceneError::Accessor {
            file: self.file.clone(),
            accessor: accessor.index(),
            usage: usage.to_string(),
            problem,
        };
        let comps = accessor.dimensions().multiplicity();
        let csize = accessor.data_type().size();
        let elem = comps * csize;
        let count = accessor.count();
        let mut out: Vec<T>;
        match accessor.view() {
            Some(view) => {
                let data = self.view_bytes(&view).map_err(err)?;
                let stride = view.stride().unwrap_or(elem);
                if stride < elem {
                    return Err(err(format!(
                        "byte stride {stride} is smaller than the element size {elem}"
                    )));
                }
                let start = accessor.offset();
                if count > 0 {
                    let end = (count - 1)
                        .checked_mul(stride)
                        .and_then(|x| x.checked_add(start))
                        .and_then(|x| x.checked_add(elem));
                    if end.is_none_or(|end| end > data.len()) {
                        return Err(err(format!(
                            "{count} elements from byte {start} (stride {stride}) exceed buffer \
                             view {} of {} bytes",
                            view.index(),
                            data.len()
                        )));
                    }
                }
                out = Vec::with_capacity(count * comps);
                for i in 0..count {
                    let at = start + i * stride;
                    for c in 0..comps {
                        out.push(convert(&data[at + c * csize..at + (c + 1) * csize]));
                    }
                }
            }
            None => {
                if count > MAX_VIEWLESS_ELEMENTS {
                    return Err(err(format!(
                        "{count} elements without a buffer view (more than {MAX_VIEWLESS_ELEMENTS})"
                    )));
                }
                out = vec![T::default(); count * comps];
            }
        }
        if let Some(sparse) = accessor.sparse() {
            let n = sparse.count();
            let indices = sparse.indices();
            let read_index = match indices.index_type() {
                gltf::accessor::sparse::IndexType::U8 => index_reader(DataType::U8),
                gltf::accessor::sparse::IndexType::U16 => index_reader(DataType::U16),
                gltf::accessor::sparse::IndexType::U32 => index_reader(DataType::U32),
            }
            .ok_or_else(|| err("bad sparse index type".into()))?;
            let isize = match indices.index_type() {
                gltf::accessor::sparse::IndexType::U8 => 1,
                gltf::accessor::sparse::IndexType::U16 => 2,
                gltf::accessor::sparse::IndexType::U32 => 4,
            };
            let idata = self.view_bytes(&indices.view()).map_err(err)?;
            let values = sparse.values();
            let vdata = self.view_bytes(&values.view()).map_err(err)?;
            let fits = |data: &[u8], offset: usize, size: usize| {
                n.checked_mul(size)
                    .and_then(|x| x.checked_add(offset))
                    .is_some_and(|end| end <= data.len())
            };
            if !fits(idata, indices.offset(), isize) || !fits(vdata, values.offset(), elem) {
                return Err(err(format!("{n} sparse entries exceed their buffer views")));
            }
            for k in 0..n {
                let at = indices.offset() + k * isize;
                let target = read_index(&idata[at..at + isize]) as usize;
                if target >= count {
                    return Err(err(format!(
                        "sparse index {target} is out of range (count {count})"
                    )));
                }
                let at = values.offset() + k * elem;
                for c in 0..comps {
                    out[target * comps + c] = convert(&vdata[at + c * csize..at + (c + 1) * csize]);
                }
            }
        }
        Ok(out)
    }

    /// An accessor of a Draco primitive that the primitive's bitstream did not give values
    /// to has no data: an error rather than the bitstream's bytes.
    fn check_not_placeholder(
        &self,
        accessor: &gltf::Accessor,
        usage: &str,
    ) -> Result<(), SceneError> {
        if self.draco_placeholders.contains(&accessor.index()) {
            return Err(SceneError::Accessor {
                file: self.file.clone(),
                accessor: accessor.index(),
                usage: usage.to_string(),
                problem: "has no buffer view, and its KHR_draco_mesh_compression primitive \
                          does not carry it"
                    .into(),
            });
        }
        Ok(())
    }

    /// Reads a float accessor of one of the given shapes; returns the flattened values.
    pub(super) fn read_floats(
        &self,
        accessor: &gltf::Accessor,
        usage: &str,
        shapes: &[Dimensions],
    ) -> Result<Vec<f32>, SceneError> {
        if !shapes.contains(&accessor.dimensions()) {
            return Err(SceneError::Accessor {
                file: self.file.clone(),
                accessor: accessor.index(),
                usage: usage.to_string(),
                problem: format!(
                    "type {:?}, expected one of {shapes:?}",
                    accessor.dimensions()
                ),
            });
        }
        if let Some(values) = self.draco_floats.get(&accessor.index()) {
            return Ok(values.clone());
        }
        self.check_not_placeholder(accessor, usage)?;
        let convert = float_reader(accessor.data_type(), accessor.normalized());
        self.read_components(accessor, usage, convert)
    }

    pub(super) fn read_vec3(
        &self,
        accessor: &gltf::Accessor,
        usage: &str,
    ) -> Result<Vec<[f32; 3]>, SceneError> {
        let flat = self.read_floats(accessor, usage, &[Dimensions::Vec3])?;
        Ok(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    }

    pub(super) fn read_indices(
        &self,
        accessor: &gltf::Accessor,
        usage: &str,
    ) -> Result<Vec<u32>, SceneError> {
        if let Some(values) = self.draco_indices.get(&accessor.index()) {
            return Ok(values.clone());
        }
        self.check_not_placeholder(accessor, usage)?;
        let convert = index_reader(accessor.data_type())
            .filter(|_| accessor.dimensions() == Dimensions::Scalar)
            .ok_or_else(|| SceneError::Accessor {
                file: self.file.clone(),
                accessor: accessor.index(),
                usage: usage.to_string(),
                problem: format!(
                    "indices must be unsigned scalar integers, found {:?} {:?}",
                    accessor.data_type(),
                    accessor.dimensions()
                ),
            })?;
        self.read_components(accessor, usage, convert)
    }
}
