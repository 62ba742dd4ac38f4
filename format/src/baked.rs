//! The `Baked` file: one sorted triangle list and a sliding window of draws per frame.

use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};

use crate::camera::FrameState;
use crate::geometry::Geometry;
use crate::options::{Bridge, Layout, Seeding, Strategy};
use crate::recording::{DeviceInfo, Edge, RecordSettings};
use crate::Hash;

/// The arguments of one indexed indirect draw, laid out as the GPU reads them
/// (`wgpu::util::DrawIndexedIndirectArgs`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable, Serialize, Deserialize)]
pub struct DrawIndexedIndirectArgs {
    /// Number of indices (3 per triangle).
    pub index_count: u32,
    /// Number of instances (always 1).
    pub instance_count: u32,
    /// First index in the index buffer.
    pub first_index: u32,
    /// Added to every index (always 0).
    pub base_vertex: i32,
    /// First instance (always 0).
    pub first_instance: u32,
}

/// A frame's window: `count` draws starting at `first` in [`Baked::draws`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FrameWindow {
    /// First draw of the frame.
    pub first: u32,
    /// Number of draws.
    pub count: u32,
}

/// How a file was merged.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MergeInfo {
    /// The strategy used (never `auto`: the one `auto` kept).
    pub strategy: Strategy,
    /// The layout used.
    pub layout: Layout,
    /// The bridge policy (what rule 2 allows; the validator checks against it).
    pub bridge: Bridge,
    /// Whether only tie edges were kept (plays only with the depth test).
    pub depth_only: bool,
    /// Segment length in frames, if the path was cut into segments.
    pub segment: Option<u32>,
    /// Seeding used to build the matrix.
    pub seeding: Seeding,
    /// The non-empty cells of the upper-triangular matrix (of every segment), in index-buffer
    /// order: what `trisort inspect --matrix` draws (the paper's Figure 14).
    pub cells: Vec<MatrixCell>,
}

/// One non-empty cell (i, j) of the merge matrix: its copies are drawn in frames i..=j.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct MatrixCell {
    /// First frame (row i).
    pub first_frame: u32,
    /// Last frame (column j), ≥ `first_frame`.
    pub last_frame: u32,
    /// Position of the cell's first copy in [`Baked::copies`].
    pub first_copy: u32,
    /// Number of copies (triangles) in the cell.
    pub triangles: u32,
}

/// Merge figures (the `--json` keys of `trisort merge`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MergeStats {
    /// Triangles in the index buffer (copies).
    pub index_triangles: u64,
    /// Σ |V_f| over all frames.
    pub source_triangles: u64,
    /// |G|.
    pub unique_visible: u64,
    /// Mean draws per frame.
    pub draws_per_frame_mean: f64,
    /// Maximum draws per frame.
    pub draws_per_frame_max: u32,
    /// Mean over frames of triangles drawn but not visible.
    pub drawn_not_visible_mean: f64,
    /// Total weight of the removed intra-frame cycle edges.
    pub unordered_samples: u64,
    /// Merge wall time in seconds. The merger leaves it 0 in the file so identical inputs
    /// give byte-identical files; the CLI reports the time it measured.
    pub seconds: f64,
    /// Edges of the final per-cell constraint graphs (union over the cell's frames).
    pub cell_constraint_edges: u64,
    /// The same after transitive reduction (its gain: how many edges were redundant).
    pub cell_constraint_edges_reduced: u64,
    /// Strongly connected components of the frames' graphs (two or more triangles, summed
    /// over frames) whose cycles were broken by an exact minimum-weight feedback arc set.
    pub exact_components: u64,
    /// Those too big to solve exactly, broken by the weighted Eades–Lin–Smyth heuristic.
    pub heuristic_components: u64,
    /// The part of `unordered_samples` removed in heuristic components (not proven minimal;
    /// the rest is minimum weight per component, self-loops included).
    pub heuristic_unordered_samples: u64,
}

/// A baked path: everything the player needs, and what the validator needs to check it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Baked {
    /// Version of the tool that wrote it.
    pub tool_version: String,
    /// Hash of the scene.
    pub scene_hash: Hash,
    /// Hash of the path.
    pub path_hash: Hash,
    /// Hashes of the recordings it was merged from (in frame order).
    pub recording_hashes: Vec<Hash>,
    /// Recording settings (the sample pattern at which it is exact).
    pub settings: RecordSettings,
    /// Recording device.
    pub device: DeviceInfo,
    /// How it was merged.
    pub merge: MergeInfo,
    /// Merge figures.
    pub stats: MergeStats,
    /// Geometry of G: triangle k is G-local id k.
    pub geometry: Geometry,
    /// Scene id of each G-local triangle (ascending).
    pub scene_ids: Vec<u32>,
    /// The sorted triangle list, front to back: G-local ids, one entry per copy. The index
    /// buffer is `geometry.triangles[copies[k]]` for each k; back-to-front playback reverses it.
    pub copies: Vec<u32>,
    /// Indirect draws over `copies` (index units: 3 per copy), front to back.
    pub draws: Vec<DrawIndexedIndirectArgs>,
    /// Per frame: its window in `draws`.
    pub frames: Vec<FrameWindow>,
    /// Per frame: camera and node poses.
    pub frame_states: Vec<FrameState>,
    /// Per frame: the intra-frame cycle edges the merger removed (G-local ids). Their total
    /// weight is `stats.unordered_samples`.
    pub removed_edges: Vec<Vec<Edge>>,
    /// Frames per second of the path (what a player plays at by default; [`Recording::fps`]),
    /// `None` where the recordings did not know it.
    ///
    /// [`Recording::fps`]: crate::Recording::fps
    pub fps: Option<f64>,
    /// The light the file is shaded with (the built-in studio unless the bake chose another).
    pub environment: crate::Environment,
    /// The camera paths the frames belong to, in frame order (a bundle has several; a file
    /// of one path has one, [`Clip::DEFAULT_NAME`] unless named). Each clip's frames are
    /// windows over the one index buffer shared by all. `fps` above is the first clip's.
    ///
    /// [`Clip::DEFAULT_NAME`]: crate::Clip::DEFAULT_NAME
    pub clips: Vec<crate::Clip>,
}

/// Checks a stored frame rate: absent, or finite and positive (a player divides by it).
pub(crate) fn check_fps(fps: Option<f64>) -> Result<(), crate::StructureError> {
    match fps {
        Some(fps) if !(fps.is_finite() && fps > 0.0) => {
            Err(crate::Part::FrameRate.error(format!("frame rate {fps} is not a positive number")))
        }
        _ => Ok(()),
    }
}

impl Baked {
    /// The index buffer in front-to-back order, as u32.
    pub fn indices(&self) -> Vec<u32> {
        let mut out = Vec::with_capacity(self.copies.len() * 3);
        for &c in &self.copies {
            out.extend_from_slice(&self.geometry.triangles[c as usize]);
        }
        out
    }

    /// Whether the index buffer fits u16 indices.
    pub fn fits_u16(&self) -> bool {
        self.geometry.vertices.len() <= u16::MAX as usize + 1
    }

    /// The draws of frame `f`, front to back.
    pub fn frame_draws(&self, f: usize) -> &[DrawIndexedIndirectArgs] {
        let w = self.frames[f];
        &self.draws[w.first as usize..(w.first + w.count) as usize]
    }

    /// Checks the structural consistency a reader must rely on before using the file: settings
    /// a recorder could have recorded with ([`crate::RecordSettings::check_stored`]), the
    /// geometry ([`Geometry::check_structure`]: indices in range, finite positions), scene ids
    /// ascending, draws inside the index buffer, windows inside the draw list, per-frame work
    /// within what a merge can produce (at most one draw per copy and each copy drawn at most
    /// once per frame, counted: a frame draws no more triangles than the buffer holds), one frame state
    /// and one removed-edge list per frame, finite cameras and poses of existing nodes
    /// ([`crate::camera::check_frame_state`]). Returns the first problem found.
    pub fn check_structure(&self) -> Result<(), crate::StructureError> {
        self.settings.check_stored()?;
        let g = &self.geometry;
        g.check_structure()?;
        if self.scene_ids.len() != g.triangles.len() {
            return Err(crate::Part::Layout.error("scene_ids and triangles differ in length"));
        }
        if self.scene_ids.windows(2).any(|w| w[0] >= w[1]) {
            return Err(crate::Part::Layout.error("scene_ids are not strictly ascending"));
        }
        let ntri = g.triangles.len() as u64;
        if let Some(k) = self.copies.iter().position(|&c| c as u64 >= ntri) {
            return Err(
                crate::Part::Layout.error(format!("copy {k} refers to a triangle beyond {ntri}"))
            );
        }
        let nidx = self.copies.len() as u64 * 3;
        for (k, d) in self.draws.iter().enumerate() {
            if d.index_count % 3 != 0
                || d.first_index % 3 != 0
                || d.first_index as u64 + d.index_count as u64 > nidx
                || d.instance_count != 1
                || d.base_vertex != 0
                || d.first_instance != 0
            {
                return Err(crate::Part::Layout
                    .error(format!("draw {k} is malformed or outside the index buffer")));
            }
        }
        // Per-frame work is bounded by what a merge can produce: a merge draws each copy at
        // most once per frame, in at most one draw per copy (without this bound a 4 MB file of
        // 200,000 draws of the whole buffer per frame holds the player for minutes). Prefix
        // sums keep this O(draws + frames) however the windows overlap.
        let mut drawn = Vec::with_capacity(self.draws.len() + 1);
        drawn.push(0u64);
        for d in &self.draws {
            drawn.push(drawn.last().copied().unwrap_or(0) + d.index_count as u64 / 3);
        }
        let ncopies = self.copies.len() as u64;
        for (f, w) in self.frames.iter().enumerate() {
            let (a, b) = (w.first as u64, w.first as u64 + w.count as u64);
            if b > self.draws.len() as u64 {
                return Err(crate::Part::Layout
                    .error(format!("frame {f}'s window lies outside the draw list")));
            }
            if w.count as u64 > ncopies + 1 {
                return Err(crate::Part::Layout.error(format!(
                    "frame {f} has {} draws, more than a merge gives a buffer of {ncopies} copies (at most one draw per copy)",
                    w.count
                )));
            }
            let triangles = drawn[b as usize] - drawn[a as usize];
            if triangles > ncopies {
                return Err(crate::Part::Layout.error(format!(
                    "frame {f} draws {triangles} triangles, more than the {ncopies} copies of the index buffer (a merge draws each copy at most once per frame)"
                )));
            }
        }
        if self.frame_states.len() != self.frames.len()
            || self.removed_edges.len() != self.frames.len()
        {
            return Err(crate::Part::Layout.error("per-frame lists differ in length"));
        }
        for (f, s) in self.frame_states.iter().enumerate() {
            crate::camera::check_frame_state(f, s, Some(g.nodes.len()))?;
        }
        self.environment.check_structure()?;
        crate::clip::check_clips(&self.clips, self.frames.len())?;
        check_fps(self.fps)
    }

    /// The clip named `name`, or an error listing the file's clips.
    pub fn clip(&self, name: &str) -> Result<&crate::Clip, String> {
        self.clips.iter().find(|c| c.name == name).ok_or_else(|| {
            let names: Vec<&str> = self.clips.iter().map(|c| c.name.as_str()).collect();
            format!(
                "no clip named {name:?}; the file's clips: {}",
                names.join(", ")
            )
        })
    }

    /// The clip frame `f` belongs to, with its index.
    pub fn clip_of_frame(&self, f: u32) -> Option<(usize, &crate::Clip)> {
        self.clips
            .iter()
            .enumerate()
            .find(|(_, c)| c.frames().contains(&f))
    }
}
