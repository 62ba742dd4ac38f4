//! The wasm side's device-free view of a baked file: [`BakedData`], the typed arrays an app's
//! own renderer draws it from (the npm package's `@trisort/player/three` builds a three.js
//! mesh from them). Every array is a copy in the layout documented on its method; the order
//! and the draw ranges are the native player's ([`trisort_player::commands`]).

use std::cell::OnceCell;
use std::path::Path;

use trisort_format::{AlphaMode, Baked, DrawIndexedIndirectArgs, FrameWindow};
use trisort_player::commands::{frame_commands, index_buffer, Order};
use wasm_bindgen::prelude::*;

use crate::ErrorKind;

/// Floats per material in [`BakedData::material_factors`].
const MATERIAL_FLOATS: usize = 16;

/// A baked file decoded and checked, without a device: its vertex streams, its sorted index
/// buffer, each frame's draw ranges, node matrices and camera, and its materials.
#[wasm_bindgen]
pub struct BakedData {
    baked: Baked,
    /// The player's commands for every frame ([`frame_commands`]), front to back ([0]) and
    /// back to front ([1]), made on the first [`BakedData::frame_ranges`] of that order.
    commands: [OnceCell<Commands>; 2],
}

/// Every frame's draws and each frame's window over them.
type Commands = (Vec<DrawIndexedIndirectArgs>, Vec<FrameWindow>);

fn order(back_to_front: bool) -> Order {
    if back_to_front {
        Order::BackToFront
    } else {
        Order::FrontToBack
    }
}

#[wasm_bindgen]
impl BakedData {
    /// Decodes and checks `bytes` (a baked file; `name` names it in errors). A damaged file
    /// throws an `Error` whose `kind` is `format`.
    pub fn open(bytes: &[u8], name: &str) -> Result<BakedData, JsValue> {
        let baked = trisort_player::baked_from_bytes(bytes, Path::new(name)).map_err(|e| {
            let err = js_sys::Error::new(&e.to_string());
            let _ = js_sys::Reflect::set(&err, &"kind".into(), &ErrorKind::Format.name().into());
            JsValue::from(err)
        })?;
        Ok(BakedData {
            baked,
            commands: Default::default(),
        })
    }

    /// Frames in the file.
    pub fn frame_count(&self) -> u32 {
        self.baked.frames.len() as u32
    }

    /// The recorded width in pixels (the projection's aspect is width / height).
    pub fn width(&self) -> u32 {
        self.baked.settings.width.max(1)
    }

    /// The recorded height in pixels.
    pub fn height(&self) -> u32 {
        self.baked.settings.height.max(1)
    }

    /// Vertices in the vertex streams.
    pub fn vertex_count(&self) -> u32 {
        self.baked.geometry.vertices.len() as u32
    }

    /// Distinct triangles (the file's triangle ids are `0 .. triangle_count`).
    pub fn triangle_count(&self) -> u32 {
        self.baked.geometry.triangles.len() as u32
    }

    /// Triangles in the sorted index buffer (copies: a triangle may appear more than once).
    pub fn copy_count(&self) -> u32 {
        self.baked.copies.len() as u32
    }

    /// Nodes (the node matrices per frame).
    pub fn node_count(&self) -> u32 {
        self.baked.geometry.nodes.len() as u32
    }

    /// Materials.
    pub fn material_count(&self) -> u32 {
        self.baked.geometry.materials.len() as u32
    }

    /// Vertex positions in their node's local space: `Float32Array`, 3 per vertex (x, y, z).
    pub fn positions(&self) -> Vec<f32> {
        self.baked
            .geometry
            .vertices
            .iter()
            .flat_map(|v| v.position)
            .collect()
    }

    /// Unit normals in the node's local space: `Float32Array`, 3 per vertex.
    pub fn normals(&self) -> Vec<f32> {
        self.baked
            .geometry
            .vertices
            .iter()
            .flat_map(|v| v.normal)
            .collect()
    }

    /// First texture coordinates (glTF TEXCOORD_0): `Float32Array`, 2 per vertex.
    pub fn uvs(&self) -> Vec<f32> {
        self.baked
            .geometry
            .vertices
            .iter()
            .flat_map(|v| v.uv)
            .collect()
    }

    /// The node that moves each vertex (an index into the node matrices): `Uint32Array`, 1
    /// per vertex. A triangle's three vertices share it.
    pub fn vertex_nodes(&self) -> Vec<u32> {
        self.baked
            .geometry
            .vertices
            .iter()
            .map(|v| v.node)
            .collect()
    }

    /// Each vertex's material (an index into [`BakedData::material_factors`]): `Uint32Array`,
    /// 1 per vertex. A triangle's three vertices share it.
    pub fn vertex_materials(&self) -> Vec<u32> {
        self.baked
            .geometry
            .vertices
            .iter()
            .map(|v| v.material)
            .collect()
    }

    /// The sorted index buffer: `Uint32Array`, 3 vertex indices per copy (counter-clockwise
    /// front faces), front to back as stored, or reversed copy by copy with `back_to_front`
    /// (what `blend` plays, as the native player does).
    pub fn indices(&self, back_to_front: bool) -> Vec<u32> {
        match index_buffer(&self.baked, order(back_to_front), true) {
            trisort_player::commands::Indices::U32(v) => v,
            trisort_player::commands::Indices::U16(v) => v.into_iter().map(u32::from).collect(),
        }
    }

    /// The triangle id of each copy of [`BakedData::indices`] in the same order: `Uint32Array`,
    /// 1 per copy (what an id-colour rendering encodes).
    pub fn copy_triangles(&self, back_to_front: bool) -> Vec<u32> {
        if back_to_front {
            self.baked.copies.iter().rev().copied().collect()
        } else {
            self.baked.copies.clone()
        }
    }

    /// Frame `frame`'s draws over [`BakedData::indices`] of the same order, in the order the
    /// native player issues them: `Uint32Array`, 2 per draw, `[first_index, index_count]` (in
    /// indices, multiples of 3). Empty beyond the last frame.
    pub fn frame_ranges(&self, frame: u32, back_to_front: bool) -> Vec<u32> {
        if frame >= self.frame_count() {
            return Vec::new();
        }
        let (draws, windows) = self.commands[usize::from(back_to_front)]
            .get_or_init(|| frame_commands(&self.baked, order(back_to_front)));
        let w = windows[frame as usize];
        draws[w.first as usize..(w.first + w.count) as usize]
            .iter()
            .flat_map(|d| [d.first_index, d.index_count])
            .collect()
    }

    /// Frame `frame`'s node matrices, camera-relative (view × world, computed in f64 and cast
    /// to f32, as every trisort pipeline does): `Float32Array`, 16 per node, column-major.
    /// Empty beyond the last frame.
    pub fn node_view_matrices(&self, frame: u32) -> Vec<f32> {
        let Some(state) = self.baked.frame_states.get(frame as usize) else {
            return Vec::new();
        };
        trisort_format::camera::node_view_matrices(&self.baked.geometry.nodes, state)
            .iter()
            .flat_map(|m| m.to_cols_array())
            .collect()
    }

    /// Frame `frame`'s projection at the recorded aspect, column-major, cast to f32 once:
    /// `Float32Array` of 16. Clip depth is wgpu's `[0, 1]`, the near plane at 0 (WebGL's
    /// `[-1, 1]` is `z' = 2z − w`; x, y and w are the same). Empty beyond the last frame.
    pub fn projection(&self, frame: u32) -> Vec<f32> {
        let Some(state) = self.baked.frame_states.get(frame as usize) else {
            return Vec::new();
        };
        let aspect = self.width() as f64 / self.height() as f64;
        state
            .camera
            .projection(aspect)
            .as_mat4()
            .to_cols_array()
            .to_vec()
    }

    /// Frame `frame`'s camera view (world → view) matrix, column-major, in f64:
    /// `Float64Array` of 16. Empty beyond the last frame.
    pub fn view(&self, frame: u32) -> Vec<f64> {
        self.baked
            .frame_states
            .get(frame as usize)
            .map(|s| s.camera.view.to_vec())
            .unwrap_or_default()
    }

    /// Frame `frame`'s lens: `Float64Array` `[yfov (radians), znear, zfar]`, zfar 0 for an
    /// infinite far plane.
    pub fn camera_lens(&self, frame: u32) -> Vec<f64> {
        self.baked
            .frame_states
            .get(frame as usize)
            .map(|s| vec![s.camera.yfov, s.camera.znear, s.camera.zfar.unwrap_or(0.0)])
            .unwrap_or_default()
    }

    /// The materials' factors (textures are not included): `Float32Array`, 16 per material:
    /// base colour RGBA (linear), emissive RGB (linear, × strength), metallic, roughness,
    /// alpha mode (0 opaque, 1 mask, 2 blend), alpha cutoff, double-sided (0 or 1),
    /// transmission, the opacity the file is played with (glass at the bake's glass opacity,
    /// blend its alpha, else 1), clearcoat, clearcoat roughness.
    pub fn material_factors(&self) -> Vec<f32> {
        let glass = self.baked.settings.glass_opacity;
        let mut out = Vec::with_capacity(self.baked.geometry.materials.len() * MATERIAL_FLOATS);
        for m in &self.baked.geometry.materials {
            let alpha_mode = match m.alpha_mode {
                AlphaMode::Opaque => 0.0,
                AlphaMode::Mask => 1.0,
                AlphaMode::Blend => 2.0,
            };
            out.extend_from_slice(&m.base_color);
            out.extend_from_slice(&m.emissive);
            out.extend_from_slice(&[
                m.metallic,
                m.roughness,
                alpha_mode,
                m.alpha_cutoff,
                if m.double_sided { 1.0 } else { 0.0 },
                m.transmission,
                m.factor_opacity(glass),
                m.clearcoat,
                m.clearcoat_roughness,
            ]);
        }
        out
    }

    /// Material `m`'s name from the source file (may be empty).
    pub fn material_name(&self, m: u32) -> String {
        self.baked
            .geometry
            .materials
            .get(m as usize)
            .map(|m| m.name.clone())
            .unwrap_or_default()
    }
}
