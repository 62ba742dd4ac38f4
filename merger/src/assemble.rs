//! Assembly: per segment, seed, split and serialize the cells; then lay the cells out in
//! index-buffer order, build every frame's window as merged contiguous ranges of
//! `DrawIndexedIndirectArgs`, and compute the merge statistics.

use std::ops::Range;
use std::sync::atomic::AtomicU64;

use rayon::prelude::*;
use trisort_format::{
    Baked, DrawIndexedIndirectArgs, Edge, FrameWindow, MatrixCell, MergeInfo, MergeStats, Recording,
};

use crate::cells::{cell_edges, CellGraph, CellOrder, Copy, CopyTable, NONE};
use crate::graph::FrameGraph;
use crate::limits::{checked, Limit};
use crate::serialize::serialize_cell;
use crate::split::{seed_intervals, split_until_valid, Budget, Context};
use crate::{paper, Layout, MergeError, MergeOptions, Seeding, Strategy};

/// One strategy × layout, merged.
pub(crate) struct Assembled {
    pub strategy: Strategy,
    pub layout: Layout,
    pub seeding: Seeding,
    /// G-local triangle per index-buffer position.
    pub copies: Vec<u32>,
    /// Non-empty cells in buffer order.
    pub cells: Vec<MatrixCell>,
    /// Every frame's draws, back to back.
    pub draws: Vec<DrawIndexedIndirectArgs>,
    /// Per frame: its window in `draws`.
    pub windows: Vec<FrameWindow>,
    /// Constraint edges of the final cells, before and after transitive reduction.
    pub edges: (u64, u64),
}

impl Assembled {
    /// Draws in the worst frame.
    pub fn draws_per_frame_max(&self) -> u32 {
        self.windows.iter().map(|w| w.count).max().unwrap_or(0)
    }

    /// The Baked file, its light a placeholder (a uniform black environment) that
    /// [`crate::Merged::lit`] replaces.
    pub fn into_baked(
        self,
        first: &Recording,
        recording_hashes: Vec<trisort_format::Hash>,
        graphs: &[FrameGraph],
        opts: &MergeOptions,
    ) -> Baked {
        let frames = self.windows.len().max(1) as f64;
        let mut drawn_not_visible = 0u64;
        for (f, w) in self.windows.iter().enumerate() {
            let drawn: u64 = self.draws[w.first as usize..(w.first + w.count) as usize]
                .iter()
                .map(|d| d.index_count as u64 / 3)
                .sum();
            drawn_not_visible += drawn - graphs[f].visible.len() as u64;
        }
        let removed_edges: Vec<Vec<Edge>> = graphs.iter().map(|g| g.removed.clone()).collect();
        let stats = MergeStats {
            index_triangles: self.copies.len() as u64,
            source_triangles: graphs.iter().map(|g| g.visible.len() as u64).sum(),
            unique_visible: first.unique_visible.len() as u64,
            draws_per_frame_mean: self.windows.iter().map(|w| w.count as f64).sum::<f64>() / frames,
            draws_per_frame_max: self.draws_per_frame_max(),
            drawn_not_visible_mean: drawn_not_visible as f64 / frames,
            unordered_samples: removed_edges
                .iter()
                .flatten()
                .map(|e| e.weight as u64)
                .sum(),
            seconds: 0.0,
            cell_constraint_edges: self.edges.0,
            cell_constraint_edges_reduced: self.edges.1,
            exact_components: graphs.iter().map(|g| g.components.0 as u64).sum(),
            heuristic_components: graphs.iter().map(|g| g.components.1 as u64).sum(),
            heuristic_unordered_samples: graphs.iter().map(|g| g.components.2).sum(),
        };
        Baked {
            tool_version: trisort_format::TOOL_VERSION.to_string(),
            scene_hash: first.scene_hash,
            path_hash: first.path_hash,
            recording_hashes,
            settings: first.settings,
            device: first.device.clone(),
            merge: MergeInfo {
                strategy: self.strategy,
                layout: self.layout,
                bridge: opts.bridge,
                depth_only: opts.depth_only,
                segment: opts.segment,
                seeding: self.seeding,
                cells: self.cells,
            },
            stats,
            geometry: first.geometry.clone(),
            scene_ids: first.unique_visible.clone(),
            copies: self.copies,
            draws: self.draws,
            frames: self.windows,
            frame_states: first.frame_states.clone(),
            removed_edges,
            fps: first.fps,
            environment: trisort_format::Environment::uniform(0.0),
            clips: first.clips.clone(),
        }
    }
}

/// One segment's serialized cells, in layout order: `(first, last, triangles front to back)`.
struct SegmentCells {
    cells: Vec<(u32, u32, Vec<u32>)>,
    edges: (u64, u64),
}

/// Merges every segment with one strategy and layout and lays the result out; `None` when
/// its copies exceed `limit` while splitting (see [`Budget`]); an error when its copies or
/// draws exceed what the baked file's u32 offsets address ([`Limit`]).
pub(crate) fn build(
    cx: &Context<'_>,
    segments: &[Range<u32>],
    strategy: Strategy,
    layout: Layout,
    seeding: Seeding,
    triangles: &[[u32; 3]],
    limit: u64,
) -> Result<Option<Assembled>, MergeError> {
    let budget = Budget {
        limit,
        used: AtomicU64::new(0),
    };
    let per_segment: Option<Vec<SegmentCells>> = segments
        .par_iter()
        .map(|seg| {
            let order = CellOrder {
                strategy,
                layout,
                start: seg.start,
                len: seg.end - seg.start,
            };
            let seeds = match seeding {
                Seeding::Interval => seed_intervals(cx, seg.clone()),
                Seeding::Paper => paper::seed_diagonal_merge(cx, seg.clone(), order),
            };
            let split = split_until_valid(cx, seg.clone(), order, seeds, &budget)?;
            Some(serialize_segment(
                cx,
                seg.clone(),
                order,
                &split.copies,
                triangles,
            ))
        })
        .collect();
    let Some(per_segment) = per_segment else {
        return Ok(None);
    };
    let total: usize = per_segment
        .iter()
        .flat_map(|s| &s.cells)
        .map(|c| c.2.len())
        .sum();
    checked(Limit::Copies, total as u64)?;
    let mut copies = Vec::with_capacity(total);
    let mut cells = Vec::new();
    let mut edges = (0, 0);
    let mut seg_cells: Vec<Range<usize>> = Vec::new();
    for s in per_segment {
        edges.0 += s.edges.0;
        edges.1 += s.edges.1;
        let start = cells.len();
        for (first, last, tris) in s.cells {
            cells.push(MatrixCell {
                first_frame: first,
                last_frame: last,
                first_copy: copies.len() as u32,
                triangles: tris.len() as u32,
            });
            copies.extend(tris);
        }
        seg_cells.push(start..cells.len());
    }
    let mut draws = Vec::new();
    let mut windows = Vec::new();
    for (seg, range) in segments.iter().zip(&seg_cells) {
        for f in seg.clone() {
            let first = checked(Limit::Draws, draws.len() as u64)?;
            let mut open: Option<(u32, u32)> = None; // (first copy, count)
            for c in &cells[range.clone()] {
                if c.first_frame > f || f > c.last_frame {
                    continue;
                }
                open = match open {
                    Some((a, n)) if a + n == c.first_copy => Some((a, n + c.triangles)),
                    Some((a, n)) => {
                        draws.push(draw(a, n));
                        Some((c.first_copy, c.triangles))
                    }
                    None => Some((c.first_copy, c.triangles)),
                };
            }
            if let Some((a, n)) = open {
                draws.push(draw(a, n));
            }
            windows.push(FrameWindow {
                first,
                count: (draws.len() - first as usize) as u32,
            });
        }
    }
    checked(Limit::Draws, draws.len() as u64)?;
    Ok(Some(Assembled {
        strategy,
        layout,
        seeding,
        copies,
        cells,
        draws,
        windows,
        edges,
    }))
}

fn draw(first_copy: u32, count: u32) -> DrawIndexedIndirectArgs {
    DrawIndexedIndirectArgs {
        index_count: count * 3,
        instance_count: 1,
        first_index: first_copy * 3,
        base_vertex: 0,
        first_instance: 0,
    }
}

/// Serializes every non-empty cell of a valid segment; cells in layout order.
fn serialize_segment(
    cx: &Context<'_>,
    seg: Range<u32>,
    order: CellOrder,
    copies: &[Copy],
    triangles: &[[u32; 3]],
) -> SegmentCells {
    let mut by_cell: Vec<(u64, u32)> = copies
        .iter()
        .enumerate()
        .map(|(k, c)| (order.key(c.first, c.last), k as u32))
        .collect();
    by_cell.sort_unstable();
    let groups: Vec<&[(u64, u32)]> = by_cell.chunk_by(|a, b| a.0 == b.0).collect();
    let mut cell_of = vec![NONE; copies.len()];
    for (c, g) in groups.iter().enumerate() {
        if g.len() >= 2 {
            for &(_, k) in g.iter() {
                cell_of[k as usize] = c as u32;
            }
        }
    }
    let table = CopyTable::new(cx.graphs, seg.clone(), cx.visible_frames.len(), copies);
    let edges = cell_edges(cx.graphs, seg, &table, &cell_of);
    let mut edge_groups: Vec<&[crate::cells::CellEdge]> = vec![&[]; groups.len()];
    for g in edges.chunk_by(|a, b| a.cell == b.cell) {
        edge_groups[g[0].cell as usize] = g;
    }
    let serialized: Vec<(u32, u32, Vec<u32>, u64, u64)> = groups
        .par_iter()
        .zip(edge_groups.par_iter())
        .map(|(g, e)| {
            let c = copies[g[0].1 as usize];
            let members: Vec<u32> = g.iter().map(|x| x.1).collect();
            let graph = CellGraph::new(e, &members);
            let s = serialize_cell(&graph, copies, triangles);
            let tris = s.order.iter().map(|&k| copies[k as usize].t).collect();
            (c.first, c.last, tris, s.edges, s.reduced_edges)
        })
        .collect();
    let edges = serialized
        .iter()
        .fold((0, 0), |acc, s| (acc.0 + s.3, acc.1 + s.4));
    SegmentCells {
        cells: serialized.into_iter().map(|s| (s.0, s.1, s.2)).collect(),
        edges,
    }
}
