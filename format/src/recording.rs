//! The `Recording`: what the recorder saw, per frame, at one sample pattern.
//!
//! Its settings ([`RecordSettings`], in `recording/settings.rs`) and the raster profile they
//! assume ([`Robust`], [`RasterProfile`], in `recording/profile.rs`) are re-exported here.

mod profile;
mod settings;

use serde::{Deserialize, Serialize};

pub use profile::{DepthAt, ProfileName, RasterProfile, Robust};
pub use settings::{RecordSettings, SettingsError};

use crate::camera::FrameState;
use crate::geometry::Geometry;
use crate::Hash;

/// The device a recording was made on.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct DeviceInfo {
    /// Adapter name (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
    pub adapter: String,
    /// Driver name and version.
    pub driver: String,
    /// Backend (Vulkan, Gl, Metal, Dx12).
    pub backend: String,
}

/// A depth-order edge at one frame: `from` lies in front of `to` at `weight` samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct Edge {
    /// The triangle in front (scene id in a Recording, G-local id in a Baked file).
    pub from: u32,
    /// The triangle behind.
    pub to: u32,
    /// Number of samples at which `from` is the peel-order neighbour in front of `to`.
    pub weight: u32,
}

/// Which phases a recording holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Phase {
    /// Phase 1 only: per-frame visible sets; `covered` and `edges` are empty.
    Visibility,
    /// Phases 1 and 2: visible sets and the graphs of G.
    Graphs,
}

/// One frame's record.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FrameRecord {
    /// Frame index on the path.
    pub frame: u32,
    /// V_f: visible triangles (scene ids, ascending).
    pub visible: Vec<u32>,
    /// C_f ⊆ G: triangles of G with at least one fragment (ascending; phase 2).
    /// The ignore list is G \ C_f.
    pub covered: Vec<u32>,
    /// E_f: front → back edges between peel-order neighbours, sorted by (from, to), weights
    /// in samples (phase 2).
    pub edges: Vec<Edge>,
    /// Ties: the edges of E_f between fragments of *equal* depth, `from` being the one the
    /// peel put in front (the lower id), weighted by the number of samples showing the tie
    /// (phase 2). A depth-only bake (`merge --depth-only`) keeps only these: with the depth
    /// test on, the draw order matters only where depths are equal.
    pub ties: Vec<Edge>,
    /// Peel passes used (phase 1, phase 2).
    pub layers: [u32; 2],
    /// Whether `max_layers` stopped the peel before it was complete.
    pub truncated: bool,
}

/// A recording of a frame range of one path over one scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Recording {
    /// Version of the tool that wrote it.
    pub tool_version: String,
    /// Hash of the scene (its geometry, materials, textures and nodes).
    pub scene_hash: Hash,
    /// Hash of the path's frames.
    pub path_hash: Hash,
    /// Recording settings.
    pub settings: RecordSettings,
    /// The device it was recorded on.
    pub device: DeviceInfo,
    /// Which phases it holds.
    pub phase: Phase,
    /// Number of triangles in the scene (scene ids are below this).
    pub scene_triangles: u32,
    /// Every frame of the path (camera and poses), not only the recorded range, so frame
    /// ranges recorded on different machines can be merged.
    pub frame_states: Vec<FrameState>,
    /// Recorded frames, ascending by frame index, a contiguous half-open range.
    pub frames: Vec<FrameRecord>,
    /// G: the triangles visible in at least one frame of the whole path (ascending scene
    /// ids). For a `Visibility` recording: the union over its own range only.
    pub unique_visible: Vec<u32>,
    /// Geometry of G (triangle k is scene triangle `unique_visible[k]`); empty for a
    /// `Visibility` recording.
    pub geometry: Geometry,
    /// Frames per second of the path (TOML `fps`, a generator's `--fps`, the glTF sampling
    /// rate), carried into the baked file; `None` where the writer did not know it.
    pub fps: Option<f64>,
    /// The camera paths `frame_states` is made of, in order (one for a single path; a
    /// bundle's several), carried into the baked file ([`crate::Baked::clips`]).
    pub clips: Vec<crate::Clip>,
}

impl Recording {
    /// The edges of frame `fr` that a frame played in depth mode (front to back, depth test
    /// `Less` with depth writes, *over*) must hold, and so all that a depth-only bake
    /// (`merge --depth-only`) keeps: every tie (equal depths: the first drawn wins the depth
    /// test), and every edge x → y whose x is a triangle that may have a fragment with alpha
    /// below 1 (a `Blend` material, or glass recorded below opacity 1) or lies behind one in
    /// E_f. A translucent a drawn after something behind it blends over it where the exact
    /// reference shows a alone; so everything behind a, opaque triangles between included
    /// (a → b → c: c drawn before a shows through it), must come after a. Behind opaque
    /// triangles only, the order does not matter: the nearest opaque fragment is what remains
    /// whichever is drawn first. Sorted; a tie that is also a kept edge is listed once, with
    /// the edge's weight. A triangle outside G counts as translucent. `fr`'s edges and ties
    /// are sorted, as [`Recording::check_structure`] requires.
    pub fn depth_mode_edges(&self, fr: &FrameRecord) -> Vec<Edge> {
        let g = &self.geometry;
        let opaque = |t: u32| {
            self.unique_visible
                .binary_search(&t)
                .ok()
                .and_then(|k| g.triangles.get(k))
                .and_then(|tri| g.vertices.get(tri[0] as usize))
                .and_then(|v| g.materials.get(v.material as usize))
                .is_some_and(|m| m.every_fragment_opaque(self.settings.glass_opacity))
        };
        let edges = &fr.edges;
        // Triangles translucent or behind a translucent one (reachable in E_f).
        let mut behind = std::collections::HashSet::new();
        let mut stack: Vec<u32> = Vec::new();
        for e in edges {
            if !opaque(e.from) && behind.insert(e.from) {
                stack.push(e.from);
            }
        }
        while let Some(t) = stack.pop() {
            let first = edges.partition_point(|e| e.from < t);
            for e in edges[first..].iter().take_while(|e| e.from == t) {
                if behind.insert(e.to) {
                    stack.push(e.to);
                }
            }
        }
        let mut out: Vec<Edge> = edges
            .iter()
            .filter(|e| behind.contains(&e.from))
            .copied()
            .collect();
        let kept = out.len();
        for t in &fr.ties {
            let i = out[..kept].partition_point(|e| (e.from, e.to) < (t.from, t.to));
            let listed = out[..kept]
                .get(i)
                .is_some_and(|e| (e.from, e.to) == (t.from, t.to));
            if !listed {
                out.push(*t);
            }
        }
        out.sort_unstable();
        out
    }

    /// The recording's identity: BLAKE3 of its postcard encoding (what a [`crate::Baked`]
    /// stores in `recording_hashes`; independent of the container's compression).
    pub fn content_hash(&self) -> Hash {
        crate::hash_bytes(&postcard::to_allocvec(self).expect("a Recording always serializes"))
    }

    /// Checks the structural consistency a reader relies on before using the recording, and
    /// returns the first problem found:
    /// - settings a recorder could have recorded with ([`RecordSettings::check_stored`]: size,
    ///   samples, saturation, glass opacity, layers, robust patterns, tolerance, sub-pixel
    ///   bits);
    /// - `unique_visible` (G) strictly ascending, every id below `scene_triangles`;
    /// - frames ascending and contiguous, inside the path's `frame_states`;
    /// - per frame: visible and covered sets strictly ascending and inside G; edges and ties
    ///   sorted by (from, to) without duplicates, between distinct triangles of G, with a
    ///   positive weight; a `Visibility` recording has no covered set, edges or ties;
    /// - a `Graphs` recording's geometry holds one triangle per member of G and passes
    ///   [`Geometry::check_structure`]; a `Visibility` recording holds none;
    /// - every frame state passes [`crate::camera::check_frame_state`] (finite cameras; poses
    ///   of existing nodes when the geometry is present).
    ///
    /// O(size of the recording).
    pub fn check_structure(&self) -> Result<(), crate::StructureError> {
        self.settings.check_stored()?;
        let g = &self.unique_visible;
        if g.windows(2).any(|w| w[0] >= w[1]) {
            return Err(crate::Part::Graphs.error("the visible set G is not strictly ascending"));
        }
        if let Some(&t) = g.last().filter(|&&t| t >= self.scene_triangles) {
            return Err(crate::Part::Graphs.error(format!(
                "G names triangle {t}, but the scene has {}",
                self.scene_triangles
            )));
        }
        let in_g = |t: u32| g.binary_search(&t).is_ok();
        let path_frames = self.frame_states.len() as u64;
        let first = self.frames.first().map_or(0, |f| f.frame);
        for (k, fr) in self.frames.iter().enumerate() {
            let f = fr.frame;
            if f as u64 != first as u64 + k as u64 {
                return Err(crate::Part::Graphs.error(format!(
                    "frame record {k} is frame {f}; frames must be contiguous from {first}"
                )));
            }
            if f as u64 >= path_frames {
                return Err(crate::Part::Graphs.error(format!(
                    "frame {f} lies beyond the path's {path_frames} frames"
                )));
            }
            for (what, set) in [("visible", &fr.visible), ("covered", &fr.covered)] {
                if set.windows(2).any(|w| w[0] >= w[1]) {
                    return Err(crate::Part::Graphs.error(format!(
                        "frame {f}: the {what} set is not strictly ascending"
                    )));
                }
                if let Some(&t) = set.iter().find(|&&t| !in_g(t)) {
                    return Err(crate::Part::Graphs
                        .error(format!("frame {f}: {what} triangle {t} is not in G")));
                }
            }
            for (what, list) in [("edges", &fr.edges), ("ties", &fr.ties)] {
                if list
                    .windows(2)
                    .any(|w| (w[0].from, w[0].to) >= (w[1].from, w[1].to))
                {
                    return Err(crate::Part::Graphs.error(format!(
                        "frame {f}: {what} are not sorted without duplicates"
                    )));
                }
                if let Some(e) = list
                    .iter()
                    .find(|e| e.from == e.to || e.weight == 0 || !in_g(e.from) || !in_g(e.to))
                {
                    return Err(crate::Part::Graphs.error(format!(
                        "frame {f}: edge {} → {} (weight {}) is a loop, has no weight or leaves G",
                        e.from, e.to, e.weight
                    )));
                }
            }
            if self.phase == Phase::Visibility
                && !(fr.covered.is_empty() && fr.edges.is_empty() && fr.ties.is_empty())
            {
                return Err(crate::Part::Graphs
                    .error(format!("frame {f}: a visibility recording holds graphs")));
            }
        }
        let nodes = match self.phase {
            Phase::Graphs => {
                if self.geometry.triangles.len() != g.len() {
                    return Err(crate::Part::Graphs.error(format!(
                        "the geometry holds {} triangles for the {} of G",
                        self.geometry.triangles.len(),
                        g.len()
                    )));
                }
                self.geometry.check_structure()?;
                Some(self.geometry.nodes.len())
            }
            Phase::Visibility => {
                if !self.geometry.triangles.is_empty() {
                    return Err(crate::Part::Graphs.error("a visibility recording holds geometry"));
                }
                None
            }
        };
        for (f, st) in self.frame_states.iter().enumerate() {
            crate::camera::check_frame_state(f, st, nodes)?;
        }
        crate::clip::check_clips(&self.clips, self.frame_states.len())?;
        crate::baked::check_fps(self.fps)
    }

    /// The half-open range of recorded frames.
    pub fn frame_range(&self) -> std::ops::Range<u32> {
        match (self.frames.first(), self.frames.last()) {
            (Some(a), Some(b)) => a.frame..b.frame + 1,
            _ => 0..0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;

    /// A phase-1 recording of frames 1..3 of a 4-frame path over a 10-triangle scene.
    fn visibility() -> Recording {
        let state = FrameState {
            camera: Camera {
                view: glam::DMat4::IDENTITY.to_cols_array(),
                yfov: 1.0,
                znear: 0.1,
                zfar: Some(100.0),
            },
            poses: vec![],
        };
        let frame = |f: u32, visible: Vec<u32>| FrameRecord {
            frame: f,
            visible,
            ..Default::default()
        };
        Recording {
            tool_version: crate::TOOL_VERSION.into(),
            scene_hash: [0; 32],
            path_hash: [0; 32],
            settings: RecordSettings::default(),
            device: DeviceInfo::default(),
            phase: Phase::Visibility,
            scene_triangles: 10,
            frame_states: vec![state; 4],
            frames: vec![frame(1, vec![2, 5]), frame(2, vec![5, 9])],
            unique_visible: vec![2, 5, 9],
            geometry: Geometry::default(),
            fps: Some(30.0),
            clips: vec![crate::Clip::whole(4, Some(30.0), [0; 32])],
        }
    }

    #[test]
    fn check_structure_accepts_a_valid_recording_and_names_each_fault() {
        visibility().check_structure().unwrap();
        type Edit = fn(&mut Recording);
        let faults: [(Edit, &str); 9] = [
            (|r| r.fps = Some(f64::INFINITY), "frame rate inf"),
            (|r| r.unique_visible.push(10), "but the scene has 10"),
            (|r| r.unique_visible.swap(0, 1), "not strictly ascending"),
            (|r| r.frames[1].frame = 3, "contiguous"),
            (|r| r.frames[1].visible = vec![4], "not in G"),
            (|r| r.frame_states.truncate(2), "beyond the path"),
            (|r| r.frame_states[3].camera.znear = f64::NAN, "znear NaN"),
            (
                |r| {
                    r.frames[0].edges = vec![Edge {
                        from: 2,
                        to: 5,
                        weight: 1,
                    }]
                },
                "holds graphs",
            ),
            (|r| r.settings.saturation = f32::NAN, "saturation NaN"),
        ];
        for (edit, needle) in faults {
            let mut r = visibility();
            edit(&mut r);
            let err = r.check_structure().unwrap_err().problem;
            assert!(err.contains(needle), "{err:?} lacks {needle:?}");
        }
    }
}
