//! The `occlusion-query` method (paper 004): objects ordered every frame by occlusion queries
//! ([`trisort_reference::vis_sort`]), starting from the previous frame's order, then drawn
//! like the default pipeline with the transparent objects back to front.

use std::cell::RefCell;
use std::collections::HashMap;
use std::time::Instant;

use serde::Serialize;
use trisort_format::{FrameState, Geometry};
use trisort_gpu::{Gpu, Lighting};
use trisort_player::Mode;
use trisort_reference::vis_sort::{Op, SortOutcome};
use trisort_reference::VisSortRenderer;

use crate::methods::{BenchView, Method, Stream};
use crate::BenchError;

/// What the occlusion-query sort cost along the path, over the frames it walked (frame 0 to
/// the last measured frame, each starting from the previous frame's order).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct QueryStats {
    /// Objects sorted (connected pieces of the nodes' transparent triangles).
    pub objects: u32,
    /// Frames sorted.
    pub frames: u32,
    /// Mean occlusion queries per frame.
    pub queries_per_frame: f64,
    /// Most queries in one frame.
    pub queries_max: u32,
    /// Mean query batches per frame (each a submission and a readback the CPU waits for).
    pub readbacks_per_frame: f64,
    /// Mean iterations (pairs of scans) per frame.
    pub iterations_per_frame: f64,
    /// Cycles met over all frames (each broken by placing an object that is not fully
    /// visible: the order is wrong there).
    pub cycles: u32,
    /// Frames with at least one cycle.
    pub frames_with_cycles: u32,
    /// Mean wall time of a frame's sort (ms), readbacks included: not in the timed frame.
    pub sort_ms_per_frame: f64,
}

/// A prepared frame's transparent draw: its index buffer, index count and indices.
struct FrameDraw {
    buffer: wgpu::Buffer,
    count: u32,
    indices: Vec<u32>,
}

/// One sorted frame: the sort and its wall time.
struct Sorted {
    outcome: SortOutcome,
    wall_ms: f64,
}

/// The `occlusion-query` method.
pub struct OcclusionQueryMethod<'g> {
    gpu: &'g Gpu,
    renderer: VisSortRenderer<'g>,
    target: trisort_gpu::FrameTarget,
    /// Frames sorted so far, from frame 0 on.
    walked: RefCell<Vec<Sorted>>,
    /// Transparent index buffers of the prepared frames.
    draws: RefCell<HashMap<u32, FrameDraw>>,
}

impl<'g> OcclusionQueryMethod<'g> {
    /// Uploads the scene for `frames` at `view` (blend mode), lit by `environment`.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        environment: &trisort_format::Environment,
        view: BenchView,
    ) -> Result<OcclusionQueryMethod<'g>, BenchError> {
        let renderer = VisSortRenderer::new(
            gpu,
            geometry,
            frames,
            view.view(),
            Lighting::pbr(environment),
        )?;
        let target = trisort_gpu::FrameTarget::new(
            &gpu.adapter,
            &gpu.device,
            trisort_gpu::TargetConfig {
                depth: true,
                ..trisort_gpu::TargetConfig::readback(view.size, view.samples, Mode::Blend)
            },
        )?;
        Ok(OcclusionQueryMethod {
            gpu,
            renderer,
            target,
            walked: RefCell::new(Vec::new()),
            draws: RefCell::new(HashMap::new()),
        })
    }

    /// The sort's figures over the frames walked so far.
    pub fn stats(&self) -> QueryStats {
        let walked = self.walked.borrow();
        let n = walked.len().max(1) as f64;
        let sum = |f: &dyn Fn(&Sorted) -> f64| walked.iter().map(f).sum::<f64>() / n;
        QueryStats {
            objects: self.renderer.objects().len() as u32,
            frames: walked.len() as u32,
            queries_per_frame: sum(&|s| s.outcome.queries as f64),
            queries_max: walked.iter().map(|s| s.outcome.queries).max().unwrap_or(0),
            readbacks_per_frame: sum(&|s| s.outcome.batches as f64),
            iterations_per_frame: sum(&|s| s.outcome.iterations as f64),
            cycles: walked.iter().map(|s| s.outcome.cycles).sum(),
            frames_with_cycles: walked.iter().filter(|s| s.outcome.cycles > 0).count() as u32,
            sort_ms_per_frame: sum(&|s| s.wall_ms),
        }
    }

    /// `f` of frame `frame`'s batches (none before [`Method::prepare`]), borrowed: `encode`
    /// runs in the timed loop.
    fn with_batches<R>(&self, frame: u32, f: impl FnOnce(&[Vec<Op>]) -> R) -> R {
        let walked = self.walked.borrow();
        f(walked
            .get(frame as usize)
            .map_or(&[][..], |s| s.outcome.ops.as_slice()))
    }
}

impl Method for OcclusionQueryMethod<'_> {
    fn name(&self) -> &str {
        "occlusion-query"
    }
    fn mode(&self) -> Mode {
        Mode::Blend
    }
    fn gpu(&self) -> &Gpu {
        self.gpu
    }
    fn variant(&self) -> String {
        let s = self.stats();
        format!(
            "paper 004, {} objects (connected pieces of each node's transparent triangles), \
             each frame from the previous frame's order (frames 0–{} walked): {:.1} queries, \
             {:.1} readbacks, {:.2} iterations a frame (most queries {}), {} cycles in {} \
             frames; the sort's wall time {:.2} ms a frame is not in the timed frame, its query \
             passes are",
            s.objects,
            s.frames.saturating_sub(1),
            s.queries_per_frame,
            s.readbacks_per_frame,
            s.iterations_per_frame,
            s.queries_max,
            s.cycles,
            s.frames_with_cycles,
            s.sort_ms_per_frame
        )
    }
    fn query_stats(&self) -> Option<QueryStats> {
        Some(self.stats())
    }
    fn prepare(&self, frame: u32) -> Result<(), BenchError> {
        let mut walked = self.walked.borrow_mut();
        while walked.len() <= frame as usize {
            let f = walked.len() as u32;
            let previous = walked.last().map(|s| s.outcome.order.as_slice());
            let start = Instant::now();
            let outcome = self.renderer.sort(f, previous)?;
            walked.push(Sorted {
                outcome,
                wall_ms: start.elapsed().as_secs_f64() * 1e3,
            });
        }
        self.draws.borrow_mut().entry(frame).or_insert_with(|| {
            let indices = self
                .renderer
                .frame_indices(frame, &walked[frame as usize].outcome.order);
            let (buffer, count) = self.renderer.upload(&indices);
            FrameDraw {
                buffer,
                count,
                indices,
            }
        });
        Ok(())
    }
    fn triangles(&self, frame: u32) -> u64 {
        let (opaque, transparent) = self.renderer.triangles();
        let queries: u64 = self.with_batches(frame, |batches| {
            batches
                .iter()
                .map(|b| self.renderer.batch_triangles(b))
                .sum()
        });
        opaque as u64 + transparent as u64 + queries
    }
    fn draws(&self, frame: u32) -> u32 {
        let ops: usize = self.with_batches(frame, |batches| {
            batches
                .iter()
                .map(|b| b.iter().filter(|o| **o != Op::Clear).count())
                .sum()
        });
        2 + ops as u32
    }
    fn stat_slots(&self, frame: u32) -> u32 {
        self.with_batches(frame, |batches| batches.len() as u32 + 1)
    }
    fn encode(&self, enc: &mut wgpu::CommandEncoder, frame: u32, stats: Option<&wgpu::QuerySet>) {
        // The frame's query passes as the sort ran them (without the readbacks), then the draw.
        let passes = self.with_batches(frame, |batches| {
            for (k, ops) in batches.iter().enumerate() {
                self.renderer
                    .encode_batch(enc, frame, ops, false, stats.map(|s| (s, k as u32)));
            }
            batches.len() as u32
        });
        let draws = self.draws.borrow();
        let Some(draw) = draws.get(&frame) else {
            return;
        };
        let mut pass = self
            .target
            .begin_pass(enc, trisort_gpu::clear_colour(Mode::Blend), None);
        crate::methods::stats_begin(&mut pass, stats, passes);
        self.renderer
            .draw(&mut pass, frame, (&draw.buffer, draw.count));
        crate::methods::stats_end(&mut pass, stats);
    }
    fn image(&self, frame: u32) -> Result<Vec<u8>, BenchError> {
        self.prepare(frame)?;
        Ok(self
            .target
            .read_rgba8(self.gpu, Mode::Blend, |enc| self.encode(enc, frame, None))?)
    }
    fn streams(&self, frame: u32) -> Vec<Stream> {
        // The colour draw only: the query passes write no colour and shade nothing.
        let g = self.renderer.geometry();
        let opaque: Vec<u32> = (0..g.triangles.len() as u32)
            .filter(|&t| !g.needs_order(t))
            .flat_map(|t| g.triangles[t as usize])
            .collect();
        let transparent = self
            .draws
            .borrow()
            .get(&frame)
            .map(|d| d.indices.clone())
            .unwrap_or_default();
        vec![
            Stream {
                indices: opaque,
                depth: Some(true),
                repeat: 1,
                per_sample: false,
            },
            Stream {
                indices: transparent,
                depth: Some(false),
                repeat: 1,
                per_sample: false,
            },
        ]
    }
}
