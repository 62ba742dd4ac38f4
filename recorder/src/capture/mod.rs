//! Fragment capture: every fragment of a frame in one render pass (`shaders/record/capture.wgsl`)
//! instead of one depth-peeling pass per layer.
//!
//! A peel layer is, per sample, the next fragment in (depth, id) order among the fragments
//! that pass the peel's facing, MASK and depth-1 rules; fragment keys are unique (a triangle
//! covers a sample once), so the layers of a sample are exactly its captured fragments sorted
//! by (depth, id). [`Capture::frame`] hands each sample's sorted list to the caller, which walks
//! it as the peel's layer callbacks would: the recording is the same, byte for byte (tests
//! `capture_matches_peeling`), and a frame costs one pass over its triangles instead of one per
//! layer plus the last, empty, one.
//!
//! The node pool starts at a fragment a sample (at most 4 Mi) and grows to what a pass asked
//! for (fragments that find it full are counted, and the pass is drawn again); a frame whose
//! fragments exceed one storage-buffer binding is captured in bands of rows (a scissor per
//! band), each band drawing every triangle again.

mod band;
mod build;

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

use trisort_format::{FrameState, Geometry, Robust};
use trisort_gpu::pipeline::bind_group;
use trisort_gpu::scene_gpu::{SceneGpu, View};
use trisort_gpu::Gpu;

use crate::peeler::read_mapped;
use crate::RecordError;

pub(crate) use band::Band;

/// One captured fragment: depth, id + 1 (a position in the drawn list, plus 1), opacity.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fragment {
    pub depth: f32,
    pub id: u32,
    pub alpha: f32,
}

/// Bytes of one pool node (depth, id, alpha, next).
const NODE_BYTES: u64 = 16;

/// Whether the device can capture: writable storage in fragment shaders and primitive ids.
pub(crate) fn supported(gpu: &Gpu) -> bool {
    gpu.device
        .features()
        .contains(wgpu::Features::PRIMITIVE_INDEX)
        && gpu
            .adapter
            .get_downlevel_capabilities()
            .flags
            .contains(wgpu::DownlevelFlags::FRAGMENT_WRITABLE_STORAGE)
}

/// The capture pipeline for one scene at one view.
pub(crate) struct Capture<'g> {
    gpu: &'g Gpu,
    scene: SceneGpu,
    /// The capture pipeline specialised to triangles whose opacity needs no texture, and the
    /// general one; or the grown capture's one pipeline.
    pipelines: Vec<wgpu::RenderPipeline>,
    layout: wgpu::BindGroupLayout,
    /// The drawn triangles, those whose opacity needs no texture first (`draw_order` in
    /// `build.rs`); `None` for the grown capture, which pulls its triangles from storage in
    /// drawn order.
    index: Option<wgpu::Buffer>,
    /// The grown capture's triangle storage (group 2).
    grown: Option<wgpu::BindGroup>,
    /// Per triangle of `index`, its position in the drawn list.
    draw_ids: wgpu::Buffer,
    /// The draws: pipeline (0 or 1) and triangles of `index`; draw k reads parameter slot k.
    draws: Vec<(usize, Range<u32>)>,
    triangles: u32,
    depth: wgpu::TextureView,
    params: wgpu::Buffer,
    params_stride: u64,
    heads: wgpu::Buffer,
    counter: wgpu::Buffer,
    counter_staging: wgpu::Buffer,
    /// The pool (grown on demand), its bind group and its readback buffer.
    pool: Option<Pool>,
    /// Phase 1's depth pass of the always-opaque triangles, drawn before the capture.
    prepass: Option<Prepass>,
    view: View,
    /// First pool and most fragments a pass ([`crate::Internals::pool_limits`]).
    pool_limits: Option<(u64, u64)>,
}

/// The triangles among those drawn whose every fragment is opaque (alpha mode OPAQUE, not glass
/// unless glass is recorded opaque), by facing rule, and the depth-only pipelines that draw them.
struct Prepass {
    /// Single-sided (back faces culled, as the peel discards them) and double-sided.
    pipelines: [wgpu::RenderPipeline; 2],
    indices: [(wgpu::Buffer, u32); 2],
}

/// How a capture grows its triangles, by a tolerance in pixels: as the grown peel's (phase 2
/// of `--conservative`), or with the envelope's depths and flags (its phase 1), with the
/// opposite vertex across each edge of each drawn triangle
/// ([`crate::envelope::Adjacency::opposite`]).
#[derive(Clone, Copy)]
pub(crate) enum Grow<'a> {
    Peel(&'a Robust),
    Envelope(&'a Robust, &'a [[u32; 4]]),
}

/// What a capture captures: the drawn triangles as they are (phase 1 may stop behind the
/// nearest always-opaque one: `until_opaque`), or grown ([`Capture::grown`]).
enum Kind<'a> {
    Plain { until_opaque: bool },
    Grown(Grow<'a>),
}

impl Grow<'_> {
    /// The tolerance and raster profile grown by.
    fn robust(&self) -> &Robust {
        match self {
            Grow::Peel(r) | Grow::Envelope(r, _) => r,
        }
    }
}

struct Pool {
    capacity: u64,
    nodes: wgpu::Buffer,
    staging: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

impl<'g> Capture<'g> {
    /// Sets up capturing `triangles` (ascending indices into `geometry.triangles`; a
    /// fragment's id is its position in this list, as the peeler's). With `until_opaque`
    /// (phase 1, whose walk stops at a sample's first opaque fragment), fragments behind the
    /// nearest always-opaque one are not captured, where the device can force the depth test
    /// before the fragment shader.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        triangles: &[u32],
        frames: &[FrameState],
        view: View,
        until_opaque: bool,
        internals: &crate::Internals,
    ) -> Result<Self, RecordError> {
        let kind = Kind::Plain { until_opaque };
        Capture::build(gpu, geometry, triangles, frames, view, kind, internals)
    }

    /// [`Capture::new`] over the triangles grown by a tolerance box (`capture_grown.wgsl`):
    /// with [`Grow::Peel`], the one-pass form of the grown peel (`Peeler::build` with
    /// `grow`), whose layers phase 2 of `record --conservative` takes the added triangles'
    /// edges from (fragments carry alpha 1); with [`Grow::Envelope`], phase 1's envelope capture ([`crate::envelope`]): each
    /// fragment has its plane's nearest depth over the depth box as its depth, its farthest as
    /// its opacity, and flags above the id (whether it occludes, which of its edges cross the
    /// box and which are closable).
    pub fn grown(
        gpu: &'g Gpu,
        geometry: &Geometry,
        triangles: &[u32],
        frames: &[FrameState],
        view: View,
        grow: Grow,
        internals: &crate::Internals,
    ) -> Result<Self, RecordError> {
        let kind = Kind::Grown(grow);
        Capture::build(gpu, geometry, triangles, frames, view, kind, internals)
    }

    /// [`crate::Peeler::set_frame_subpixel_offset`] for the capture's scene.
    pub fn set_frame_subpixel_offset(&self, frame: u32, offset: [f64; 2]) {
        self.scene
            .set_subpixel_offset_of(&self.gpu.queue, offset, frame..frame + 1);
    }

    /// Number of triangles drawn (ids are positions in this list, plus 1).
    pub fn triangles(&self) -> usize {
        self.triangles as usize
    }

    /// Replaces the pool with one of `capacity` nodes.
    fn grow(&mut self, capacity: u64) {
        let device = &self.gpu.device;
        let capacity = capacity.max(1);
        let nodes = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("capture nodes"),
            size: capacity * NODE_BYTES,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("capture readback"),
            size: capacity * NODE_BYTES + self.heads.size(),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = bind_group(
            device,
            "capture",
            &self.layout,
            &[
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &self.params,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
                self.heads.as_entire_binding(),
                self.counter.as_entire_binding(),
                nodes.as_entire_binding(),
                self.draw_ids.as_entire_binding(),
            ],
        );
        for (c, (_, r)) in self.draws.iter().enumerate() {
            let p = [
                r.start,
                self.view.width,
                self.view.samples,
                capacity.min(u32::MAX as u64) as u32,
            ];
            self.gpu.queue.write_buffer(
                &self.params,
                c as u64 * self.params_stride,
                bytemuck::cast_slice(&p),
            );
        }
        self.pool = Some(Pool {
            capacity,
            nodes,
            staging,
            bind_group,
        });
    }

    /// Captures frame `frame` and calls `on_rows` with each band of rows captured, a [`Band`]
    /// to read its samples' sorted fragment lists from. Bands cover the image once, top to
    /// bottom; usually one band is the whole image.
    pub fn frame(
        &mut self,
        frame: u32,
        mut on_rows: impl FnMut(&Band) -> Result<(), RecordError>,
    ) -> Result<(), RecordError> {
        // Bands still to capture (a stack: the next is last), starting with the whole image.
        let mut todo: Vec<Range<u32>> = Vec::new();
        todo.push(0..self.view.height);
        while let Some(rows) = todo.pop() {
            let (asked, full) = self.draw(frame, rows.clone())?;
            COUNTERS[0].fetch_add(1, Relaxed);
            let limit = self.pool_limit();
            let capacity = self.pool.as_ref().map_or(0, |p| p.capacity);
            if full {
                // `asked` may have wrapped low on an enormous pass: it is at least one more.
                let asked = asked.max(capacity + 1);
                if asked <= limit {
                    // Room for this many and an eighth more, so a next frame rarely redraws.
                    self.grow((asked + asked / 8).min(limit));
                    COUNTERS[1].fetch_add(1, Relaxed);
                    todo.push(rows);
                } else if rows.len() > 1 {
                    // More fragments than one binding holds: halve the band (bottom half
                    // pushed first, so bands are handed out top to bottom).
                    let mid = rows.start + rows.len() as u32 / 2;
                    COUNTERS[2].fetch_add(1, Relaxed);
                    todo.push(mid..rows.end);
                    todo.push(rows.start..mid);
                } else {
                    return Err(RecordError::Unsupported(format!(
                        "one row of {} pixels at {}x holds {asked} fragments; the device binds \
                         at most {limit} ({} bytes)",
                        self.view.width,
                        self.view.samples,
                        limit * NODE_BYTES
                    )));
                }
                continue;
            }
            self.read(rows, asked, &mut on_rows)?;
        }
        Ok(())
    }

    /// Benchmarks: wall milliseconds of one capture pass over the whole image (submitted and
    /// waited for, the counter read back; the lists are not).
    pub fn time_draw(&self, frame: u32) -> Result<f64, RecordError> {
        let t = std::time::Instant::now();
        self.draw(frame, 0..self.view.height)?;
        Ok(t.elapsed().as_secs_f64() * 1000.0)
    }

    /// Draws every triangle into the lists of `rows` (a scissor) and returns how many
    /// fragments asked for a node and whether any found the pool full.
    fn draw(&self, frame: u32, rows: Range<u32>) -> Result<(u64, bool), RecordError> {
        let gpu = self.gpu;
        let pool = self.pool.as_ref().expect("a pool exists");
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("capture"),
            });
        enc.clear_buffer(&self.heads, 0, None);
        enc.clear_buffer(&self.counter, 0, None);
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("capture"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
            pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
            pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
            pass.set_scissor_rect(0, rows.start, self.view.width, rows.len() as u32);
            if let Some(pre) = &self.prepass {
                for (pipeline, (index, count)) in pre.pipelines.iter().zip(&pre.indices) {
                    if *count > 0 {
                        pass.set_pipeline(pipeline);
                        pass.set_index_buffer(index.slice(..), wgpu::IndexFormat::Uint32);
                        pass.draw_indexed(0..count * 3, 0, 0..1);
                    }
                }
            }
            if let Some(index) = &self.index {
                pass.set_index_buffer(index.slice(..), wgpu::IndexFormat::Uint32);
            }
            if let Some(group) = &self.grown {
                pass.set_bind_group(2, group, &[]);
            }
            for (c, (pipeline, r)) in self.draws.iter().enumerate() {
                pass.set_pipeline(&self.pipelines[*pipeline]);
                pass.set_bind_group(
                    1,
                    &pool.bind_group,
                    &[(c as u64 * self.params_stride) as u32],
                );
                if self.index.is_some() {
                    pass.draw_indexed(r.start * 3..r.end * 3, 0, 0..1);
                } else {
                    // Pulled from storage: the triangle is vertex_index / 3.
                    pass.draw(r.start * 3..r.end * 3, 0..1);
                }
            }
        }
        enc.copy_buffer_to_buffer(&self.counter, 0, &self.counter_staging, 0, 16);
        gpu.queue.submit([enc.finish()]);
        read_mapped(gpu, &self.counter_staging, 16, |w| {
            (w[0] as u64 + w[1] as u64, w[2] != 0)
        })
    }

    /// Reads back the heads of `rows` and the first `nodes` nodes of the pool and hands them
    /// to `on_rows` while mapped (no copy).
    fn read(
        &self,
        rows: Range<u32>,
        nodes: u64,
        on_rows: &mut impl FnMut(&Band) -> Result<(), RecordError>,
    ) -> Result<(), RecordError> {
        let gpu = self.gpu;
        let pool = self.pool.as_ref().expect("a pool exists");
        let row_slots = self.view.width as u64 * self.view.samples as u64;
        let heads_at = rows.start as u64 * row_slots * 4;
        let heads_len = rows.len() as u64 * row_slots * 4;
        let nodes_len = nodes * NODE_BYTES;
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(&self.heads, heads_at, &pool.staging, 0, heads_len);
        if nodes_len > 0 {
            enc.copy_buffer_to_buffer(&pool.nodes, 0, &pool.staging, heads_len, nodes_len);
        }
        gpu.queue.submit([enc.finish()]);
        let total = heads_len + nodes_len;
        COUNTERS[3].fetch_add(total, Relaxed);
        let split = (heads_len / 4) as usize;
        let first = (rows.start as u64 * row_slots) as usize;
        read_mapped(gpu, &pool.staging, total, |words| {
            on_rows(&Band {
                words,
                split,
                first,
            })
        })?
    }
}

/// Capture passes drawn, pools grown, bands split, bytes read back (see [`capture_counters`]).
static COUNTERS: [AtomicU64; 4] = [const { AtomicU64::new(0) }; 4];

/// What every capture of this process did so far: passes drawn, passes drawn again after the
/// pool grew, bands split in two, and bytes read back (tests and benchmarks).
#[doc(hidden)]
pub fn capture_counters() -> [u64; 4] {
    std::array::from_fn(|k| COUNTERS[k].load(Relaxed))
}

impl Capture<'_> {
    /// Most nodes one pool holds: one storage binding, a readback buffer of the pool and the
    /// heads within the device's largest buffer, node indices + 1 in a u32
    /// ([`crate::Internals::pool_limits`] may lower it).
    fn pool_limit(&self) -> u64 {
        let limits = self.gpu.device.limits();
        let nodes = (binding_limit(&self.gpu.device) / NODE_BYTES)
            .min(limits.max_buffer_size.saturating_sub(self.heads.size()) / NODE_BYTES)
            .min(u32::MAX as u64 - 1);
        self.pool_limits.map_or(nodes, |(_, most)| most.min(nodes))
    }
}

/// The largest storage buffer one binding holds on `device`.
fn binding_limit(device: &wgpu::Device) -> u64 {
    let l = device.limits();
    l.max_storage_buffer_binding_size.min(l.max_buffer_size)
}
