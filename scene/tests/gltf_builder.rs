//! Builds the small glTF files of the import tests: buffers, views and accessors, embedded
//! (`.gltf` with a `data:` URI) or binary (`.glb`), and a few stock documents.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};
use trisort_scene::{load, Scene, SceneError};

/// Standard base64 with padding, for `data:` URIs.
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Builds the binary side of a small glTF: one buffer, tightly packed views and accessors.
#[derive(Default)]
pub struct Builder {
    pub bin: Vec<u8>,
    pub views: Vec<Value>,
    pub accessors: Vec<Value>,
}

impl Builder {
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.views.push(json!({
            "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()
        }));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    pub fn floats(&mut self, values: &[f32], kind: &str, count: usize) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let comps = values.len() / count.max(1);
        let finite = |c: usize| {
            values
                .iter()
                .skip(c)
                .step_by(comps)
                .filter(|v| v.is_finite())
        };
        let min: Vec<f32> = (0..comps)
            .map(|c| finite(c).fold(f32::MAX, |a, &b| a.min(b)))
            .collect();
        let max: Vec<f32> = (0..comps)
            .map(|c| finite(c).fold(f32::MIN, |a, &b| a.max(b)))
            .collect();
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5126, "count": count, "type": kind,
            "min": min, "max": max
        }));
        self.accessors.len() - 1
    }

    pub fn vec3(&mut self, values: &[[f32; 3]]) -> usize {
        self.floats(values.as_flattened(), "VEC3", values.len())
    }

    pub fn indices(&mut self, values: &[u32]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5125, "count": values.len(), "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }

    /// The document with its buffer embedded as a base64 `data:` URI.
    pub fn gltf(&self, mut root: Value) -> String {
        root["asset"] = json!({"version": "2.0"});
        root["buffers"] = json!([{
            "byteLength": self.bin.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64(&self.bin))
        }]);
        root["bufferViews"] = json!(self.views);
        root["accessors"] = json!(self.accessors);
        root.to_string()
    }

    /// The document as a GLB with the buffer in the binary chunk.
    pub fn glb(&self, mut root: Value) -> Vec<u8> {
        root["asset"] = json!({"version": "2.0"});
        root["buffers"] = json!([{"byteLength": self.bin.len()}]);
        root["bufferViews"] = json!(self.views);
        root["accessors"] = json!(self.accessors);
        let mut text = root.to_string().into_bytes();
        text.resize(text.len().next_multiple_of(4), b' ');
        let mut bin = self.bin.clone();
        bin.resize(bin.len().next_multiple_of(4), 0);
        let total = 12 + 8 + text.len() + 8 + bin.len();
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((text.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(text);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
        out
    }
}

/// A regular tetrahedron around the origin, counter-clockwise seen from outside.
pub fn tetrahedron() -> (Vec<[f32; 3]>, Vec<u32>) {
    let p = vec![
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ];
    let i = vec![0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2];
    (p, i)
}

pub fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

pub fn load_text(dir: &Path, name: &str, text: &str) -> Result<Scene, SceneError> {
    load(&write(dir, name, text))
}

/// A one-mesh document: a tetrahedron named `name` on node 0 of scene 0, with `extra` merged
/// into the primitive.
pub fn tetra_doc(b: &mut Builder, name: &str, extra: Value) -> Value {
    let (p, i) = tetrahedron();
    let pos = b.vec3(&p);
    let idx = b.indices(&i);
    let mut prim = json!({"attributes": {"POSITION": pos}, "indices": idx});
    for (k, v) in extra.as_object().unwrap() {
        prim[k] = v.clone();
    }
    json!({
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "tetra"}],
        "meshes": [{"name": name, "primitives": [prim]}]
    })
}

/// A 2×2 RGBA PNG: red, green / blue, transparent.
pub fn tiny_png() -> Vec<u8> {
    let img = image::RgbaImage::from_raw(
        2,
        2,
        vec![255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 0, 0, 0, 0],
    )
    .unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}
