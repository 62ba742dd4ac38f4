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

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

use trisort_format::{AlphaMode, FrameState, Geometry, Robust};
use trisort_gpu::pipeline::{bind_group, storage_entry, uniform_entry};
use trisort_gpu::scene_gpu::{vertex_layout, SceneGpu, View};
use trisort_gpu::Gpu;
use wgpu::util::DeviceExt;

use crate::conservative::{pulled_pipeline, GrowBuffers};
use crate::peeler::{read_mapped, CHUNK_TRIANGLES};
use crate::RecordError;

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
    /// The drawn triangles, those whose opacity needs no texture first ([`draw_order`]);
    /// `None` for the grown capture, which pulls its triangles from storage in drawn order.
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
    /// with [`Grow::Peel`], the one-pass form of [`crate::Peeler::grown`], whose layers phase 2
    /// of `record --conservative` takes the added triangles' edges from (fragments carry alpha
    /// 1); with [`Grow::Envelope`], phase 1's envelope capture ([`crate::envelope`]): each
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

    fn build(
        gpu: &'g Gpu,
        geometry: &Geometry,
        triangles: &[u32],
        frames: &[FrameState],
        view: View,
        kind: Kind,
        internals: &crate::Internals,
    ) -> Result<Self, RecordError> {
        let (until_opaque, grow) = match kind {
            Kind::Plain { until_opaque } => (until_opaque, None),
            Kind::Grown(grow) => (false, Some(grow)),
        };
        let device = &gpu.device;
        // Before anything is allocated: the list heads must fit one binding.
        let slots = view.width as u64 * view.height as u64 * view.samples as u64;
        let largest = binding_limit(device);
        if slots * 4 > largest {
            return Err(RecordError::Unsupported(format!(
                "{}x{} at {}x needs {} bytes of list heads; the device binds at most {largest}",
                view.width,
                view.height,
                view.samples,
                slots * 4
            )));
        }
        let scene = crate::peeler::visibility_scene(gpu, geometry, frames, view, internals);
        let until_opaque = until_opaque
            && device
                .features()
                .contains(wgpu::Features::SHADER_EARLY_DEPTH_TEST);
        let source = match grow {
            None => trisort_gpu::capture_shader(until_opaque),
            Some(_) => trisort_gpu::capture_grown_shader(),
        };
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("capture"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("capture"),
            entries: &[
                uniform_entry(0, fragment, true, Some(16)),
                storage_entry(1, fragment, false),
                storage_entry(2, fragment, false),
                storage_entry(3, fragment, false),
                storage_entry(4, fragment, true),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("capture"),
            bind_group_layouts: &[Some(&scene.layout), Some(&layout)],
            immediate_size: 0,
        });
        // No colour target. Without the prepass no depth test either: every fragment is kept
        // (the depth attachment only gives the pass its sample count; the grown capture's
        // pulled pipeline writes it, with `Always`, which keeps every fragment too); with it,
        // `LessEqual` against the nearest always-opaque fragment, not written.
        let build = |label,
                     layout: &wgpu::PipelineLayout,
                     cull_mode,
                     depth,
                     fragment: Option<&[(&str, f64)]>| {
            let (write, compare, bias) = depth;
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_record"),
                    compilation_options: Default::default(),
                    buffers: &[Some(vertex_layout())],
                },
                primitive: wgpu::PrimitiveState {
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: wgpu::TextureFormat::Depth32Float,
                    depth_write_enabled: Some(write),
                    depth_compare: Some(compare),
                    stencil: Default::default(),
                    bias,
                }),
                multisample: wgpu::MultisampleState {
                    count: view.samples,
                    ..Default::default()
                },
                fragment: fragment.map(|constants| wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_capture"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants,
                        ..Default::default()
                    },
                    targets: &[],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let compare = if until_opaque {
            wgpu::CompareFunction::LessEqual
        } else {
            wgpu::CompareFunction::Always
        };
        let (pipelines, grown) = match grow {
            None => {
                let pipelines = [0.0, 1.0].map(|reads_alpha| {
                    let constants = [("READS_ALPHA", reads_alpha)];
                    build(
                        "capture",
                        &pipeline_layout,
                        None,
                        (false, compare, wgpu::DepthBiasState::default()),
                        Some(&constants),
                    )
                });
                (Vec::from(pipelines), None)
            }
            Some(grow) => {
                let buffers = GrowBuffers::new(device, geometry, triangles, view, grow.robust());
                let mut layout_entries = GrowBuffers::layout_entries().to_vec();
                let mut entries = buffers.entries().to_vec();
                let opposite = match grow {
                    Grow::Peel(_) => None,
                    Grow::Envelope(_, opposite) => {
                        let empty = [[u32::MAX; 4]];
                        let data = if opposite.is_empty() {
                            &empty[..]
                        } else {
                            opposite
                        };
                        Some(
                            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                                label: Some("envelope opposite vertices"),
                                contents: bytemuck::cast_slice(data),
                                usage: wgpu::BufferUsages::STORAGE,
                            }),
                        )
                    }
                };
                if let Some(opposite) = &opposite {
                    layout_entries.push(storage_entry(3, wgpu::ShaderStages::VERTEX, true));
                    entries.push(wgpu::BindGroupEntry {
                        binding: 3,
                        resource: opposite.as_entire_binding(),
                    });
                }
                let grow_layout =
                    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                        label: Some("grown capture"),
                        entries: &layout_entries,
                    });
                let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("grown capture"),
                    layout: &grow_layout,
                    entries: &entries,
                });
                let stages = match grow {
                    Grow::Peel(_) => ("vs_grown", "fs_capture_grown"),
                    Grow::Envelope(..) => ("vs_envelope", "fs_capture_envelope"),
                };
                let pipeline = pulled_pipeline(
                    device,
                    "grown capture",
                    &[&scene.layout, &layout, &grow_layout],
                    &module,
                    stages,
                    None,
                    Some((wgpu::TextureFormat::Depth32Float, compare)),
                    view.samples,
                );
                (vec![pipeline], Some(group))
            }
        };
        let prepass = until_opaque.then(|| {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("capture prepass"),
                bind_group_layouts: &[Some(&scene.layout)],
                immediate_size: 0,
            });
            // Pushed back a few units of the depth format: the capture's `LessEqual` test then
            // keeps every fragment before a sample's first opaque one even where a device's
            // depth-test value and the shader's `position.z` differ in the last bits (the peel
            // compared only the latter). What else it keeps lies behind that fragment, where
            // the walk never goes.
            let bias = wgpu::DepthBiasState {
                constant: 8,
                slope_scale: 0.0,
                clamp: 0.0,
            };
            let depth = (true, wgpu::CompareFunction::Less, bias);
            let pipelines = [
                build(
                    "capture prepass",
                    &layout,
                    Some(wgpu::Face::Back),
                    depth,
                    None,
                ),
                build("capture prepass", &layout, None, depth, None),
            ];
            let indices = opaque_indices(geometry, triangles, view.glass_opacity)
                .map(|list| (index_buffer(device, &list), (list.len() / 3) as u32));
            Prepass { pipelines, indices }
        });
        let depth = trisort_gpu::pipeline::texture_2d(
            device,
            "capture depth",
            (view.width, view.height),
            view.samples,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());

        // The grown capture pulls triangle k of the drawn list as draw triangle k: one part.
        let (order, without_texture) = match grow {
            None => draw_order(geometry, triangles),
            Some(_) => (
                (0..triangles.len() as u32).collect(),
                triangles.len() as u32,
            ),
        };
        let mut index_data: Vec<u32> = Vec::with_capacity(triangles.len() * 3);
        for &position in &order {
            index_data
                .extend_from_slice(&geometry.triangles[triangles[position as usize] as usize]);
        }
        let index = grow.is_none().then(|| index_buffer(device, &index_data));
        // The grown capture reads no table (its ids are its draw's triangles): one word.
        let ids: &[u32] = if order.is_empty() || grow.is_some() {
            &[0]
        } else {
            &order
        };
        let draw_ids = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("capture draw ids"),
            contents: bytemuck::cast_slice(ids),
            usage: wgpu::BufferUsages::STORAGE,
        });
        // Each part by its pipeline, in draws of at most CHUNK_TRIANGLES.
        let chunked = |r: Range<u32>| {
            (r.start..r.end)
                .step_by(CHUNK_TRIANGLES as usize)
                .map(move |a| a..(a + CHUNK_TRIANGLES).min(r.end))
        };
        let draws: Vec<(usize, Range<u32>)> = chunked(0..without_texture)
            .map(|r| (0, r))
            .chain(chunked(without_texture..order.len() as u32).map(|r| (1, r)))
            .collect();
        let params_stride = device.limits().min_uniform_buffer_offset_alignment.max(16) as u64;
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("capture params"),
            size: draws.len().max(1) as u64 * params_stride,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let buffer = |label, size, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let heads = buffer(
            "capture heads",
            slots * 4,
            wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        );
        let counter = buffer(
            "capture counter",
            16,
            wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        );
        let counter_staging = buffer(
            "capture counter readback",
            16,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        let mut capture = Capture {
            gpu,
            scene,
            pipelines,
            layout,
            index,
            grown,
            draw_ids,
            draws,
            triangles: triangles.len() as u32,
            depth,
            params,
            params_stride,
            heads,
            counter,
            counter_staging,
            pool: None,
            prepass,
            view,
            pool_limits: internals.pool_limits,
        };
        // A fragment a sample to begin with, at most 4 Mi (64 MiB): a frame's pass that asks
        // for more is drawn again with room for what it asked plus an eighth, kept for later
        // frames.
        let first = internals
            .pool_limits
            .map_or(slots.min(1 << 22), |(first, _)| first);
        capture.grow(first.min(capture.pool_limit()));
        Ok(capture)
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

/// An index buffer holding `indices` (one degenerate triangle where there are none: buffers
/// may not be empty).
fn index_buffer(device: &wgpu::Device, indices: &[u32]) -> wgpu::Buffer {
    let empty = [0u32; 3];
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("capture indices"),
        contents: bytemuck::cast_slice(if indices.is_empty() { &empty } else { indices }),
        usage: wgpu::BufferUsages::INDEX,
    })
}

/// The order the capture draws `triangles` in, as positions in that list: those whose
/// opacity needs no texture (OPAQUE materials, glass) first, then the rest (MASK, BLEND), each
/// part ascending; and the length of the first part. The GPU's `surface_base` decides glass by
/// transmission before the alpha mode, and so does this.
fn draw_order(geometry: &Geometry, triangles: &[u32]) -> (Vec<u32>, u32) {
    let without_texture = |t: u32| {
        let m = &geometry.materials[geometry.triangle_material(t) as usize];
        m.transmission > 0.0 || m.alpha_mode == AlphaMode::Opaque
    };
    let (mut first, rest): (Vec<u32>, Vec<u32>) =
        (0..triangles.len() as u32).partition(|&p| without_texture(triangles[p as usize]));
    let n = first.len() as u32;
    first.extend(rest);
    (first, n)
}

/// The indices of the triangles among `triangles` whose every fragment has alpha 1 (alpha mode
/// OPAQUE, and not glass unless glass is recorded at opacity 1): single-sided, then
/// double-sided. Their order does not matter: they only set the nearest depth.
fn opaque_indices(geometry: &Geometry, triangles: &[u32], glass_opacity: f32) -> [Vec<u32>; 2] {
    let mut lists = [Vec::new(), Vec::new()];
    for &t in triangles {
        let m = &geometry.materials[geometry.triangle_material(t) as usize];
        let glass = m.transmission > 0.0;
        if m.alpha_mode == AlphaMode::Opaque && (!glass || glass_opacity >= 1.0) {
            lists[m.double_sided as usize].extend_from_slice(&geometry.triangles[t as usize]);
        }
    }
    lists
}

/// One band of rows read back: list heads and the node pool, as words of the mapped readback.
pub(crate) struct Band<'a> {
    words: &'a [u32],
    /// Heads are `words[..split]`, nodes (4 words each) `words[split..]`.
    split: usize,
    /// The image's slot of the band's first sample (`(y · width + x) · samples + s`).
    first: usize,
}

impl Band<'_> {
    /// Samples in this band.
    pub fn slots(&self) -> usize {
        self.split
    }

    /// Walks every sample's sorted fragment list ([`Band::sorted`]) with `walk` (which also gets
    /// the sample's slot in the image, `(y · width + x) · samples + s`), in parallel
    /// over runs of samples, each run into its own state made by `init`; returns the states
    /// (in run order) for the caller to merge. What the caller merges must not depend on how
    /// samples were split into runs (sums, unions, maxima), so recordings stay identical
    /// whatever the thread count.
    pub fn walk<S: Send>(
        &self,
        init: impl Fn() -> S + Sync,
        walk: impl Fn(&mut S, usize, &[Fragment]) + Sync,
    ) -> Vec<S> {
        use rayon::prelude::*;
        let runs = (rayon::current_num_threads() * 4).max(1);
        let per_run = self.slots().div_ceil(runs).max(1);
        (0..self.slots())
            .step_by(per_run)
            .collect::<Vec<usize>>()
            .into_par_iter()
            .map(|start| {
                let mut state = init();
                let mut list = Vec::new();
                for slot in start..(start + per_run).min(self.slots()) {
                    self.sorted(slot, &mut list);
                    walk(&mut state, self.first + slot, &list);
                }
                state
            })
            .collect()
    }

    /// The fragments of the band's sample `slot` (0-based within the band) sorted by
    /// (depth, id), the order the peel's layers give them, into `out` (cleared first).
    pub fn sorted(&self, slot: usize, out: &mut Vec<Fragment>) {
        out.clear();
        let nodes = &self.words[self.split..];
        let mut n = self.words[slot];
        while n != 0 {
            let node = &nodes[(n as usize - 1) * 4..n as usize * 4];
            out.push(Fragment {
                depth: f32::from_bits(node[0]),
                id: node[1],
                alpha: f32::from_bits(node[2]),
            });
            n = node[3];
        }
        // The peel's order: a fragment comes after another when its depth is greater, or equal
        // (as `==` compares: -0 and +0 are equal) with a greater id. Depths are never NaN.
        out.sort_unstable_by(|a, b| {
            a.depth
                .partial_cmp(&b.depth)
                .unwrap_or(std::cmp::Ordering::Equal)
                .then(a.id.cmp(&b.id))
        });
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
