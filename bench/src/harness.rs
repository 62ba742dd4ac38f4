//! Timing and counting [`Method`]s.
//!
//! - [`time_methods`]: every (repetition, frame, method) once, methods interleaved and their
//!   order rotated per frame so that ratios come from one run under the same load; per call
//!   the GPU time between two timestamps written into the command encoder around the method's
//!   whole frame (where the device has `TIMESTAMP_QUERY_INSIDE_ENCODERS`), and the wall time
//!   from encoding to the device being idle again.
//! - [`pipeline_statistics`]: the device's own counts (vertex, clipper and fragment-shader
//!   invocations) summed over the method's passes. lavapipe counts rasterized fragments there,
//!   shaded or not, so it overcounts what a GPU with early depth testing shades.
//! - [`FragmentCounter`]: fragments that survive the depth test in submission order, counted
//!   per pixel with the stencil buffer — what a GPU with early depth testing shades — and the
//!   pixels they cover; their ratio is the overdraw (paper 002's measure).

use std::time::Instant;

use serde::Serialize;
use trisort_format::{FrameState, Geometry};
use trisort_gpu::scene_gpu::{SceneGpu, View};
use trisort_gpu::Gpu;
use trisort_gpu::{GpuTimer, COLOR_FORMAT};
use wgpu::util::DeviceExt;

use crate::methods::{Method, Stream};
use crate::BenchError;

/// Mean, 95th percentile (nearest rank) and maximum of a set of times in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Summary {
    /// Mean.
    pub mean: f64,
    /// 95th percentile, nearest rank.
    pub p95: f64,
    /// Maximum.
    pub max: f64,
    /// Number of measurements.
    pub n: usize,
}

impl Summary {
    /// Summarises `values` (all zero when empty).
    pub fn of(values: &[f64]) -> Summary {
        if values.is_empty() {
            return Summary::default();
        }
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let rank = ((0.95 * v.len() as f64).ceil() as usize).clamp(1, v.len());
        Summary {
            mean: v.iter().sum::<f64>() / v.len() as f64,
            p95: v[rank - 1],
            max: v[v.len() - 1],
            n: v.len(),
        }
    }
}

/// One timed call: a method drawing one frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Timing {
    /// Frame.
    pub frame: u32,
    /// GPU time in milliseconds (timestamps), where the device has them.
    pub gpu_ms: Option<f64>,
    /// Wall time in milliseconds: encoding, submission and waiting for the device.
    pub wall_ms: f64,
}

fn wgpu_scope_error(gpu: &Gpu, scope: wgpu::ErrorScopeGuard) -> Result<(), BenchError> {
    match pollster::block_on(scope.pop()) {
        Some(e) => Err(BenchError::Wgpu(format!("{}: {e}", gpu.describe()))),
        None => Ok(()),
    }
}

/// Times one call of `method` on `frame`.
fn time_once(
    method: &dyn Method,
    timer: Option<&GpuTimer>,
    frame: u32,
) -> Result<Timing, BenchError> {
    let gpu = method.gpu();
    let device = &gpu.device;
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let t0 = Instant::now();
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("bench frame"),
    });
    if let Some(t) = timer {
        t.write_start(&mut enc);
    }
    method.encode(&mut enc, frame, None);
    if let Some(t) = timer {
        t.write_end(&mut enc);
        t.resolve(&mut enc);
    }
    gpu.queue.submit([enc.finish()]);
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| BenchError::Wgpu(e.to_string()))?;
    let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
    wgpu_scope_error(gpu, scope)?;
    let gpu_ms = timer.and_then(|t| t.ms(&gpu.map_read(t.staging())));
    Ok(Timing {
        frame,
        gpu_ms,
        wall_ms,
    })
}

/// Times every method on every frame `repeats` times (after one untimed warm-up call per
/// method and frame, which also runs [`Method::prepare`]). Calls are interleaved: for each
/// repetition and frame, every method once, the order rotated by one per frame. Returns, per
/// method, its timings in call order. `progress(done, total)` after each call.
pub fn time_methods(
    methods: &[&dyn Method],
    frames: &[u32],
    repeats: u32,
    progress: &dyn Fn(usize, usize),
) -> Result<Vec<Vec<Timing>>, BenchError> {
    let timers: Vec<Option<GpuTimer>> = methods
        .iter()
        .map(|m| GpuTimer::new(&m.gpu().device, &m.gpu().queue, true))
        .collect();
    let total = methods.len() * frames.len() * (repeats as usize + 1);
    let mut done = 0;
    for &f in frames {
        for (m, t) in methods.iter().zip(&timers) {
            m.prepare(f)?;
            time_once(*m, t.as_ref(), f)?;
            done += 1;
            progress(done, total);
        }
    }
    let mut out = vec![Vec::new(); methods.len()];
    let n = methods.len().max(1);
    for r in 0..repeats as usize {
        for (i, &f) in frames.iter().enumerate() {
            for k in 0..methods.len() {
                let m = (k + i + r) % n;
                out[m].push(time_once(methods[m], timers[m].as_ref(), f)?);
                done += 1;
                progress(done, total);
            }
        }
    }
    Ok(out)
}

/// Pipeline-statistics counts of one frame, summed over a method's passes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PipelineCounts {
    /// Vertex-shader invocations.
    pub vertex_invocations: u64,
    /// Primitives that reached the clipper.
    pub clipper_invocations: u64,
    /// Fragment-shader invocations as the device counts them.
    pub fragment_invocations: u64,
}

/// The device's pipeline statistics for `method` drawing `frame` (after
/// [`Method::prepare`]); `None` where the device lacks `PIPELINE_STATISTICS_QUERY`.
pub fn pipeline_statistics(
    method: &dyn Method,
    frame: u32,
) -> Result<Option<PipelineCounts>, BenchError> {
    let gpu = method.gpu();
    let device = &gpu.device;
    if !device
        .features()
        .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
    {
        return Ok(None);
    }
    let slots = method.stat_slots(frame).max(1);
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let set = device.create_query_set(&wgpu::QuerySetDescriptor {
        label: Some("bench pipeline statistics"),
        ty: wgpu::QueryType::PipelineStatistics(
            wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS
                | wgpu::PipelineStatisticsTypes::CLIPPER_INVOCATIONS
                | wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS,
        ),
        count: slots,
    });
    let size = slots as u64 * 3 * 8;
    let resolve = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("bench statistics"),
        size,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("bench statistics readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    method.encode(&mut enc, frame, Some(&set));
    enc.resolve_query_set(&set, 0..method.stat_slots(frame), &resolve, 0);
    enc.copy_buffer_to_buffer(&resolve, 0, &staging, 0, size);
    gpu.queue.submit([enc.finish()]);
    wgpu_scope_error(gpu, scope)?;
    let bytes = gpu.map_read(&staging);
    let v: &[u64] = bytemuck::cast_slice(&bytes);
    let mut c = PipelineCounts::default();
    for k in 0..method.stat_slots(frame) as usize {
        // Resolved in the order of the flags' bits: vertex, clipper, fragment.
        c.vertex_invocations += v[3 * k];
        c.clipper_invocations += v[3 * k + 1];
        c.fragment_invocations += v[3 * k + 2];
    }
    Ok(Some(c))
}

/// Fragments shaded and pixels covered in one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Overdraw {
    /// Fragments that pass the depth test in submission order (times [`Stream::repeat`], and
    /// times the sample count for per-sample shading).
    pub fragments: u64,
    /// Pixels covered by at least one fragment.
    pub pixels_covered: u64,
    /// `fragments / pixels_covered` (0 when nothing is covered).
    pub overdraw: f64,
}

/// The stencil format of the counting pass.
const COUNT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth24PlusStencil8;

/// Counts the fragments a method's [`Stream`]s produce, one sample per pixel (at pixel
/// centres): each fragment that passes the depth test (and is not discarded by the player's
/// shader: back faces of single-sided materials, cut-outs) increments the pixel's stencil,
/// clamped at 255. Counting at one sample keeps the measure device-independent: MSAA adds
/// fragments only along triangle edges.
pub struct FragmentCounter<'g> {
    gpu: &'g Gpu,
    scene: SceneGpu,
    size: (u32, u32),
    pipelines: [wgpu::RenderPipeline; 3],
    color: wgpu::TextureView,
    stencil: wgpu::Texture,
    row_bytes: u32,
    staging: wgpu::Buffer,
}

impl<'g> FragmentCounter<'g> {
    /// Uploads the scene for counting at `size` with `glass_opacity`.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        size: (u32, u32),
        glass_opacity: f32,
    ) -> Result<FragmentCounter<'g>, BenchError> {
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let view = View {
            width: size.0,
            height: size.1,
            samples: 1,
            glass_opacity,
        };
        let scene = SceneGpu::new(device, &gpu.queue, geometry, frames, view);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("bench fragment counter"),
            source: wgpu::ShaderSource::Wgsl(trisort_gpu::compose(&[], trisort_gpu::PLAYER).into()),
        });
        let pipeline = |compare: wgpu::CompareFunction, write: bool| {
            let face = wgpu::StencilFaceState {
                compare: wgpu::CompareFunction::Always,
                fail_op: wgpu::StencilOperation::Keep,
                depth_fail_op: wgpu::StencilOperation::Keep,
                pass_op: wgpu::StencilOperation::IncrementClamp,
            };
            let layouts: [Option<&wgpu::BindGroupLayout>; 1] = [Some(&scene.layout)];
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("bench fragment counter"),
                bind_group_layouts: &layouts,
                immediate_size: 0,
            });
            // The shared pipeline state (`ScenePipeline`: CCW, no hardware culling) with a
            // stencil that counts.
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("bench fragment counter"),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_player"),
                    compilation_options: Default::default(),
                    buffers: &[Some(trisort_gpu::scene_gpu::vertex_layout())],
                },
                primitive: wgpu::PrimitiveState {
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: COUNT_FORMAT,
                    depth_write_enabled: Some(write),
                    depth_compare: Some(compare),
                    stencil: wgpu::StencilState {
                        front: face,
                        back: face,
                        read_mask: 0xff,
                        write_mask: 0xff,
                    },
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_player_straight"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: COLOR_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::empty(),
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let pipelines = [
            pipeline(wgpu::CompareFunction::Always, false),
            pipeline(wgpu::CompareFunction::Less, true),
            pipeline(wgpu::CompareFunction::Less, false),
        ];
        let texture = |format, usage| {
            trisort_gpu::pipeline::texture_2d(
                device,
                "bench fragment counter",
                size,
                1,
                format,
                usage,
            )
        };
        let color = texture(COLOR_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT)
            .create_view(&Default::default());
        let stencil = texture(
            COUNT_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let row_bytes = size.0.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bench fragment counter readback"),
            size: row_bytes as u64 * size.1 as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        wgpu_scope_error(gpu, scope)?;
        Ok(FragmentCounter {
            gpu,
            scene,
            size,
            pipelines,
            color,
            stencil,
            row_bytes,
            staging,
        })
    }

    /// Counts `streams` drawn in order at frame `frame`, each stream's count multiplied by its
    /// [`Stream::repeat`] and, for per-sample shading, by `samples`.
    pub fn count(
        &self,
        frame: u32,
        streams: &[Stream],
        samples: u32,
    ) -> Result<Overdraw, BenchError> {
        let device = &self.gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let pixels = self.size.0 as usize * self.size.1 as usize;
        let mut fragments = 0u64;
        let mut covered = vec![false; pixels];
        // One pass per stream so each stream's own count is known (repeat and per-sample
        // factors differ); the depth buffer carries over between streams of one frame.
        let stencil_view = self.stencil.create_view(&Default::default());
        for (k, s) in streams.iter().enumerate() {
            let mut enc = device.create_command_encoder(&Default::default());
            let buffer = (!s.indices.is_empty()).then(|| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("bench counted indices"),
                    contents: bytemuck::cast_slice(&s.indices),
                    usage: wgpu::BufferUsages::INDEX,
                })
            });
            {
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("bench fragment count"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &self.color,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Discard,
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &stencil_view,
                        depth_ops: Some(wgpu::Operations {
                            load: if k == 0 {
                                wgpu::LoadOp::Clear(1.0)
                            } else {
                                wgpu::LoadOp::Load
                            },
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(0),
                            store: wgpu::StoreOp::Store,
                        }),
                    }),
                    ..Default::default()
                });
                if let Some(buffer) = &buffer {
                    let p = match s.depth {
                        None => &self.pipelines[0],
                        Some(true) => &self.pipelines[1],
                        Some(false) => &self.pipelines[2],
                    };
                    pass.set_pipeline(p);
                    pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
                    pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
                    pass.set_index_buffer(buffer.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..s.indices.len() as u32, 0, 0..1);
                }
            }
            enc.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture: &self.stencil,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::StencilOnly,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &self.staging,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(self.row_bytes),
                        rows_per_image: Some(self.size.1),
                    },
                },
                self.stencil.size(),
            );
            self.gpu.queue.submit([enc.finish()]);
            let bytes = self.gpu.map_read(&self.staging);
            let factor = s.repeat as u64 * if s.per_sample { samples as u64 } else { 1 };
            let mut stream_fragments = 0u64;
            for y in 0..self.size.1 as usize {
                let row = &bytes[y * self.row_bytes as usize..][..self.size.0 as usize];
                for (x, &c) in row.iter().enumerate() {
                    let p = y * self.size.0 as usize + x;
                    if c > 0 {
                        covered[p] = true;
                    }
                    stream_fragments += c as u64;
                }
            }
            fragments += stream_fragments * factor;
        }
        wgpu_scope_error(self.gpu, scope)?;
        let pixels_covered = covered.iter().filter(|&&c| c).count() as u64;
        Ok(Overdraw {
            fragments,
            pixels_covered,
            overdraw: if pixels_covered == 0 {
                0.0
            } else {
                fragments as f64 / pixels_covered as f64
            },
        })
    }
}
