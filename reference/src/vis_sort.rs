//! Object-level visibility ordering with occlusion queries (paper 004, Govindaraju et al.
//! 2005, "Vis-sort"), the run-time rival `bench --methods occlusion-query` measures.
//!
//! **Objects.** The triangles that need an order ([`Geometry::needs_order`]) fall into
//! objects: the connected pieces (triangles sharing a vertex position) of each node, so a
//! windscreen, a side window and a door's window are separate objects and a door's window moves
//! with its door. The opaque rest is drawn first with the depth test, as the paper does.
//!
//! **The sort** ([`vis_sort`], § 3.3 and § 4 of the paper) orders the objects front to back with
//! comparisons made by occlusion queries against a depth buffer: an object is *fully visible*
//! against a set of objects when, drawn with the depth test `Greater` after them, no sample
//! passes. Each iteration scans the unsorted list twice:
//!
//! 1. back to front through the list, each object queried against the objects after it, then
//!    written into the depth buffer: those fully visible form the candidates M;
//! 2. front to back, each candidate queried against the objects before it that stay unsorted;
//!    a fully visible one is occluded by no unsorted object and joins the output. The others
//!    stay, in their order, for the next iteration.
//!
//! The second scan is batched: candidates are queried optimistically up to the end of the list
//! in one submission, and only where one fails (it must then be written into the depth buffer
//! before the candidates after it are queried) is the rest queried again after a readback. An
//! iteration that places nothing means every unsorted object is occluded by another: a
//! **cycle** (interpenetrating or interlocking objects). It is reported and broken by placing
//! the first unsorted object as if it were visible, which is where the method's order goes
//! wrong. **Coherence** (§ 5.2): each frame starts from the previous frame's order, so a
//! coherent path takes one iteration, `2 × objects` queries and two readbacks a frame.
//!
//! **Drawing.** The objects back to front (the reverse of the sort), the triangles within an
//! object by their centroid's view depth, farthest first (the paper's "local visibility sort"
//! within objects, done on the CPU), through [`DefaultRenderer::draw_with`]: the default
//! pipeline's passes with this order.

use std::collections::HashMap;

use petgraph::unionfind::UnionFind;

use trisort_format::{FrameState, Geometry};
use trisort_gpu::scene_gpu::{Lighting, ScenePipeline, View};
use trisort_gpu::Gpu;
use wgpu::util::DeviceExt;

use crate::target::DEPTH_FORMAT;
use crate::{DefaultRenderer, ReferenceError};

/// One step of a query batch, on a depth buffer that persists across a pass's batches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// Clear the depth buffer to the far plane.
    Clear,
    /// Count the samples of object `k` behind the depth buffer (depth test `Greater`, no
    /// writes): zero means fully visible against what was written.
    Query(usize),
    /// Write object `k`'s depth (depth test `Less`, writes).
    Write(usize),
}

/// Runs query batches: the GPU ([`VisSortRenderer`]) or, in tests, another model of depth.
pub trait Oracle {
    /// Runs `ops` in order and returns the sample count of each [`Op::Query`], in order.
    fn run(&mut self, ops: &[Op]) -> Result<Vec<u64>, ReferenceError>;
}

/// What sorting one frame took.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SortOutcome {
    /// Objects front to back.
    pub order: Vec<usize>,
    /// Occlusion queries issued.
    pub queries: u32,
    /// Query batches submitted and read back (each a CPU–GPU round trip).
    pub batches: u32,
    /// Iterations of the two scans.
    pub iterations: u32,
    /// Cycles met: iterations that could place no object, broken by placing the first.
    pub cycles: u32,
    /// Every batch in order, for replaying the frame's GPU work.
    pub ops: Vec<Vec<Op>>,
}

/// Sorts objects front to back starting from `previous` (every object once, the previous
/// frame's order or any order), comparing them through `oracle`. See the module documentation.
pub fn vis_sort(
    previous: &[usize],
    oracle: &mut dyn Oracle,
) -> Result<SortOutcome, ReferenceError> {
    let n = previous.iter().max().map_or(0, |m| m + 1);
    let mut out = SortOutcome::default();
    let mut run = |ops: Vec<Op>, out: &mut SortOutcome| -> Result<Vec<u64>, ReferenceError> {
        let counts = oracle.run(&ops)?;
        out.queries += counts.len() as u32;
        out.batches += 1;
        out.ops.push(ops);
        Ok(counts)
    };
    let mut list: Vec<usize> = previous.to_vec();
    let mut candidate = vec![false; n];
    while !list.is_empty() {
        out.iterations += 1;
        // Scan 1, back to front: fully visible against everything after it in the list.
        let mut ops = vec![Op::Clear];
        for &k in list.iter().rev() {
            ops.extend([Op::Query(k), Op::Write(k)]);
        }
        let counts = run(ops, &mut out)?;
        for (&k, &c) in list.iter().rev().zip(&counts) {
            candidate[k] = c == 0;
        }
        // Scan 2, front to back, in optimistic batches.
        let mut placed = Vec::new();
        let mut kept: Vec<usize> = Vec::new();
        let mut start = 0;
        while start < list.len() {
            let mut ops = vec![Op::Clear];
            ops.extend(kept.iter().map(|&k| Op::Write(k)));
            let mut queried = Vec::new();
            for (i, &k) in list.iter().enumerate().skip(start) {
                if candidate[k] {
                    ops.push(Op::Query(k));
                    queried.push(i);
                } else {
                    ops.push(Op::Write(k));
                }
            }
            let counts = run(ops, &mut out)?;
            let failed = queried
                .iter()
                .zip(&counts)
                .find(|(_, &c)| c > 0)
                .map(|(&i, _)| i);
            let end = failed.unwrap_or(list.len());
            for &k in &list[start..end] {
                if candidate[k] {
                    placed.push(k);
                } else {
                    kept.push(k);
                }
            }
            if let Some(i) = failed {
                kept.push(list[i]);
            }
            start = end + 1;
        }
        if placed.is_empty() {
            // Every unsorted object is behind another somewhere: a cycle.
            out.cycles += 1;
            placed.push(kept.remove(0));
        }
        out.order.extend(placed);
        list = kept;
    }
    Ok(out)
}

/// The objects of `geometry`: the triangles that need an order, grouped into the connected
/// pieces of each node (triangles sharing a vertex position), each piece's triangles in
/// ascending id, pieces in order of their first triangle.
pub fn objects(geometry: &Geometry) -> Vec<Vec<u32>> {
    let sorted: Vec<u32> = (0..geometry.triangles.len() as u32)
        .filter(|&t| geometry.needs_order(t))
        .collect();
    let mut pieces: UnionFind<usize> = UnionFind::new(sorted.len());
    let mut first: HashMap<(u32, [u32; 3]), usize> = HashMap::new();
    for (i, &t) in sorted.iter().enumerate() {
        for &v in &geometry.triangles[t as usize] {
            let p = geometry.vertices[v as usize].position;
            let key = (geometry.triangle_node(t), p.map(f32::to_bits));
            pieces.union(i, *first.entry(key).or_insert(i));
        }
    }
    let mut index: HashMap<usize, usize> = HashMap::new();
    let mut out: Vec<Vec<u32>> = Vec::new();
    for (i, &t) in sorted.iter().enumerate() {
        let k = *index.entry(pieces.find_mut(i)).or_insert_with(|| {
            out.push(Vec::new());
            out.len() - 1
        });
        out[k].push(t);
    }
    out
}

/// The occlusion-query renderer of paper 004 for one scene at one view (blend mode).
pub struct VisSortRenderer<'g> {
    gpu: &'g Gpu,
    default: DefaultRenderer<'g>,
    geometry: Geometry,
    frames: Vec<FrameState>,
    objects: Vec<Vec<u32>>,
    /// Per object: (first index, index count) in `object_index`.
    ranges: Vec<(u32, u32)>,
    object_index: wgpu::Buffer,
    query: wgpu::RenderPipeline,
    write: wgpu::RenderPipeline,
    depth: wgpu::TextureView,
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    staging: wgpu::Buffer,
}

impl<'g> VisSortRenderer<'g> {
    /// Uploads the scene for the path `frames` at `view`, lit as `lighting` says. Errors where
    /// the adapter cannot multisample the targets.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
        lighting: Lighting<'_>,
    ) -> Result<VisSortRenderer<'g>, ReferenceError> {
        let default = DefaultRenderer::new(gpu, geometry, frames, view, lighting)?;
        let device = &gpu.device;
        let objects = objects(geometry);
        let mut indices: Vec<u32> = Vec::new();
        let mut ranges = Vec::new();
        for o in &objects {
            let first = indices.len() as u32;
            indices.extend(o.iter().flat_map(|&t| geometry.triangles[t as usize]));
            ranges.push((first, indices.len() as u32 - first));
        }
        if indices.is_empty() {
            indices.extend_from_slice(&[0; 3]);
        }
        let object_index = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("vis-sort objects"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        // Depth only: no fragment stage, no colour attachment.
        let pipeline = |label: &str, compare, write| {
            ScenePipeline {
                label,
                layouts: &[&default.scene().layout],
                module: default.module(),
                vertex: "vs_player",
                fragment: "",
                target: wgpu::ColorTargetState::from(trisort_gpu::COLOR_FORMAT),
                depth: Some((DEPTH_FORMAT, compare, write)),
                samples: view.samples,
            }
            .build_depth_only(device)
        };
        let query = pipeline("vis-sort query", wgpu::CompareFunction::Greater, false);
        let write = pipeline("vis-sort write", wgpu::CompareFunction::Less, true);
        let depth = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("vis-sort depth"),
                size: wgpu::Extent3d {
                    width: view.width,
                    height: view.height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: view.samples,
                dimension: wgpu::TextureDimension::D2,
                format: DEPTH_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&Default::default());
        let slots = objects.len().max(1) as u32;
        let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("vis-sort queries"),
            ty: wgpu::QueryType::Occlusion,
            count: slots,
        });
        let buffer = |label: &str, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 8 * slots as u64,
                usage,
                mapped_at_creation: false,
            })
        };
        let resolve = buffer(
            "vis-sort resolve",
            wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        );
        let staging = buffer(
            "vis-sort readback",
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        Ok(VisSortRenderer {
            gpu,
            default,
            geometry: geometry.clone(),
            frames: frames.to_vec(),
            objects,
            ranges,
            object_index,
            query,
            write,
            depth,
            queries,
            resolve,
            staging,
        })
    }

    /// The scene.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The objects (their triangles), indexed as [`SortOutcome::order`] names them.
    pub fn objects(&self) -> &[Vec<u32>] {
        &self.objects
    }

    /// Triangles drawn per frame by [`VisSortRenderer::draw`] (opaque, transparent).
    pub fn triangles(&self) -> (u32, u32) {
        self.default.triangles()
    }

    /// Triangles a batch draws (queries and writes).
    pub fn batch_triangles(&self, ops: &[Op]) -> u64 {
        ops.iter()
            .map(|op| match op {
                Op::Clear => 0,
                Op::Query(k) | Op::Write(k) => self.ranges[*k].1 as u64 / 3,
            })
            .sum()
    }

    /// Sorts frame `frame`'s objects front to back starting from `previous` (the previous
    /// frame's order; `None`: object order), with occlusion queries on this device.
    pub fn sort(
        &self,
        frame: u32,
        previous: Option<&[usize]>,
    ) -> Result<SortOutcome, ReferenceError> {
        let start: Vec<usize> = match previous {
            Some(p) => p.to_vec(),
            None => (0..self.objects.len()).collect(),
        };
        vis_sort(
            &start,
            &mut GpuOracle {
                renderer: self,
                frame,
            },
        )
    }

    /// Records one batch of `frame` into `enc`: one depth-only render pass, its queries in
    /// slots 0.. in order, resolved into the resolve buffer when `resolve`; with `stats`, the
    /// pass is bracketed by a pipeline-statistics query at that slot.
    pub fn encode_batch(
        &self,
        enc: &mut wgpu::CommandEncoder,
        frame: u32,
        ops: &[Op],
        resolve: bool,
        stats: Option<(&wgpu::QuerySet, u32)>,
    ) {
        let clear = ops.first() == Some(&Op::Clear);
        let queries = ops.iter().filter(|o| matches!(o, Op::Query(_))).count() as u32;
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("vis-sort batch"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: if clear {
                            wgpu::LoadOp::Clear(1.0)
                        } else {
                            wgpu::LoadOp::Load
                        },
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                occlusion_query_set: Some(&self.queries),
                ..Default::default()
            });
            let scene = self.default.scene();
            pass.set_bind_group(0, &scene.bind_group, &scene.offsets(frame));
            pass.set_vertex_buffer(0, scene.vertices.slice(..));
            pass.set_index_buffer(self.object_index.slice(..), wgpu::IndexFormat::Uint32);
            if let Some((set, k)) = stats {
                pass.begin_pipeline_statistics_query(set, k);
            }
            let mut slot = 0;
            for op in ops {
                match *op {
                    Op::Clear => {}
                    Op::Query(k) => {
                        let (first, count) = self.ranges[k];
                        pass.set_pipeline(&self.query);
                        pass.begin_occlusion_query(slot);
                        pass.draw_indexed(first..first + count, 0, 0..1);
                        pass.end_occlusion_query();
                        slot += 1;
                    }
                    Op::Write(k) => {
                        let (first, count) = self.ranges[k];
                        pass.set_pipeline(&self.write);
                        pass.draw_indexed(first..first + count, 0, 0..1);
                    }
                }
            }
            if stats.is_some() {
                pass.end_pipeline_statistics_query();
            }
        }
        if resolve && queries > 0 {
            enc.resolve_query_set(&self.queries, 0..queries, &self.resolve, 0);
            enc.copy_buffer_to_buffer(&self.resolve, 0, &self.staging, 0, 8 * queries as u64);
        }
    }

    /// Frame `frame`'s transparent indices for the object order `front_to_back`: the objects
    /// back to front, each one's triangles by centroid view depth, farthest first (ties by id).
    pub fn frame_indices(&self, frame: u32, front_to_back: &[usize]) -> Vec<u32> {
        let g = &self.geometry;
        let views =
            trisort_format::camera::node_view_matrices(&g.nodes, &self.frames[frame as usize]);
        let depth = |t: u32| -> f32 {
            let tri = g.triangles[t as usize];
            let m = &views[g.triangle_node(t) as usize];
            let c = tri.iter().fold(glam::Vec3::ZERO, |a, &v| {
                a + glam::Vec3::from(g.vertices[v as usize].position)
            }) / 3.0;
            // View space looks down -z: the depth is -z.
            -m.transform_point3(c).z
        };
        let mut out = Vec::with_capacity(self.ranges.iter().map(|r| r.1 as usize).sum());
        for &k in front_to_back.iter().rev() {
            let mut tris: Vec<(f32, u32)> =
                self.objects[k].iter().map(|&t| (depth(t), t)).collect();
            tris.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            out.extend(tris.iter().flat_map(|&(_, t)| g.triangles[t as usize]));
        }
        out
    }

    /// An index buffer of `indices` (one degenerate triangle where empty) and its count, for
    /// [`VisSortRenderer::draw`].
    pub fn upload(&self, indices: &[u32]) -> (wgpu::Buffer, u32) {
        let data: &[u32] = if indices.is_empty() { &[0; 3] } else { indices };
        let buffer = self
            .gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("vis-sort frame order"),
                contents: bytemuck::cast_slice(data),
                usage: wgpu::BufferUsages::INDEX,
            });
        (buffer, indices.len() as u32)
    }

    /// Records frame `frame` into `pass` (the default pipeline's attachments): the opaque
    /// triangles, then `transparent` (from [`VisSortRenderer::upload`]) in its order.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        frame: u32,
        transparent: (&wgpu::Buffer, u32),
    ) {
        self.default.draw_with(pass, frame, transparent);
    }

    /// Renders frame `frame` with `transparent` as 8-bit sRGB RGBA.
    pub fn render(
        &self,
        frame: u32,
        transparent: (&wgpu::Buffer, u32),
    ) -> Result<Vec<u8>, ReferenceError> {
        self.default.render_with(frame, transparent)
    }
}

/// Runs batches on the renderer's device: one submission and one readback each.
struct GpuOracle<'r, 'g> {
    renderer: &'r VisSortRenderer<'g>,
    frame: u32,
}

impl Oracle for GpuOracle<'_, '_> {
    fn run(&mut self, ops: &[Op]) -> Result<Vec<u64>, ReferenceError> {
        let r = self.renderer;
        let gpu = r.gpu;
        let queries = ops.iter().filter(|o| matches!(o, Op::Query(_))).count();
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("vis-sort batch"),
            });
        r.encode_batch(&mut enc, self.frame, ops, true, None);
        gpu.queue.submit([enc.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(ReferenceError::Invalid(format!("vis-sort batch: {e}")));
        }
        if queries == 0 {
            return Ok(Vec::new());
        }
        let bytes = gpu.map_read(&r.staging);
        Ok(bytes[..8 * queries]
            .chunks_exact(8)
            .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's 1D model (§ 3.3): object k is the number `values[k]`, the depth buffer
    /// holds the minimum written, and a query passes where the object is greater.
    struct Numbers {
        values: Vec<f64>,
        min: f64,
    }

    impl Oracle for Numbers {
        fn run(&mut self, ops: &[Op]) -> Result<Vec<u64>, ReferenceError> {
            let mut counts = Vec::new();
            for op in ops {
                match *op {
                    Op::Clear => self.min = f64::INFINITY,
                    Op::Query(k) => counts.push((self.values[k] > self.min) as u64),
                    Op::Write(k) => self.min = self.min.min(self.values[k]),
                }
            }
            Ok(counts)
        }
    }

    fn numbers(values: &[f64]) -> Numbers {
        Numbers {
            values: values.to_vec(),
            min: f64::INFINITY,
        }
    }

    #[test]
    fn sorts_the_papers_example_in_two_iterations() {
        // Table 1: I = {1, 3, 2, 4}; the first iteration places 1 and 2, the second 3 and 4.
        let mut oracle = numbers(&[1.0, 3.0, 2.0, 4.0]);
        let out = vis_sort(&[0, 1, 2, 3], &mut oracle).unwrap();
        assert_eq!(out.order, vec![0, 2, 1, 3]);
        assert_eq!(out.iterations, 2);
        assert_eq!(out.cycles, 0);
        // Iteration 1: scan 1 queries 4, scan 2 queries M = {1, 2, 4} and fails at 4;
        // iteration 2: scan 1 queries 2, scan 2 queries both.
        assert_eq!(out.queries, 4 + 3 + 2 + 2);
    }

    #[test]
    fn a_sorted_list_takes_one_iteration_and_two_readbacks() {
        let values: Vec<f64> = (0..50).map(f64::from).collect();
        let order: Vec<usize> = (0..50).collect();
        let out = vis_sort(&order, &mut numbers(&values)).unwrap();
        assert_eq!(out.order, order);
        assert_eq!((out.iterations, out.batches, out.queries), (1, 2, 100));
    }

    #[test]
    fn any_order_of_distinct_numbers_comes_out_sorted() {
        // A fixed pseudo-random permutation, and its reverse (the worst case).
        let mut values: Vec<f64> = (0..40).map(|i| ((i * 17 + 5) % 40) as f64).collect();
        for _ in 0..2 {
            let out = vis_sort(&(0..40).collect::<Vec<_>>(), &mut numbers(&values)).unwrap();
            let sorted: Vec<f64> = out.order.iter().map(|&k| values[k]).collect();
            assert!(sorted.windows(2).all(|w| w[0] <= w[1]), "{sorted:?}");
            assert_eq!(out.cycles, 0);
            values.reverse();
        }
    }

    /// Objects that each occlude the next, round a ring: no order exists.
    struct Ring(usize);

    impl Oracle for Ring {
        fn run(&mut self, ops: &[Op]) -> Result<Vec<u64>, ReferenceError> {
            let mut written = vec![false; self.0];
            let mut counts = Vec::new();
            for op in ops {
                match *op {
                    Op::Clear => written.fill(false),
                    // k is behind k - 1 (mod n).
                    Op::Query(k) => counts.push(written[(k + self.0 - 1) % self.0] as u64),
                    Op::Write(k) => written[k] = true,
                }
            }
            Ok(counts)
        }
    }

    #[test]
    fn a_cycle_is_detected_broken_and_every_object_still_placed() {
        let out = vis_sort(&[0, 1, 2], &mut Ring(3)).unwrap();
        assert_eq!(out.cycles, 1);
        let mut placed = out.order.clone();
        placed.sort();
        assert_eq!(placed, vec![0, 1, 2]);
        // Broken at the first object; then 1 (behind only 0, placed) and 2 follow.
        assert_eq!(out.order, vec![0, 1, 2]);
    }
}
