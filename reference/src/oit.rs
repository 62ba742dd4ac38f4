//! Order-independent transparency with per-sample linked lists (paper 001), the run-time rival
//! that `trisort bench` compares with the baked player.
//!
//! Every frame draws the *whole scene* (every triangle, ascending ids, one draw, no depth test)
//! once into per-sample linked lists, then resolves them with one full-screen pass:
//!
//! 1. **List pass** (`fs_oit_list` in `shaders/reference/oit.wgsl`): the player's `vs_player`
//!    and `player_colour`, shaded once per covered sample (`@builtin(sample_index)`). Each
//!    fragment with alpha > 0 takes a node of a fixed pool with an atomic counter
//!    (straight-alpha colour as f32, depth, scene triangle id from
//!    `@builtin(primitive_index)`) and pushes it on its sample's list with `atomicExchange`.
//!    Fragments past the pool's end are counted and lost.
//! 2. **Resolve pass** (`fs_oit_resolve`): per sample, the nearest [`OitConfig::max_sorted`]
//!    fragments sorted by (depth, id), the exact reference's peel order, composited back to
//!    front over the player's background with the player's straight-alpha `over`, rounded to
//!    binary16 after every fragment like the reference's `Rgba16Float` target between its
//!    blended layers, from the nearest opaque fragment on (nothing behind it shows). The pass
//!    writes every sample of an MSAA `Rgba16Float` target and resolves it like the player.
//!
//! Within the budgets the frame equals [`crate::ExactReference`]'s `blend` frame bit for bit on
//! lavapipe (the tests assert it on scenes built for it; GlassVaseFlowers, AlphaBlendModeTest
//! and CarConcept orbits at 256² and 512², 1× and 4×, matched too). Both shade with the
//! player's `player_colour` at the pixel centre, order each sample's fragments by (rasterized
//! depth, id), round to binary16 after every `over` and resolve MSAA with the same pass. The
//! one device-specific step is that rounding: lavapipe's blend unit rounds toward zero when it
//! stores to `Rgba16Float` (measured: rounding to nearest left 1/255 differences), other
//! adapters are assumed to round to nearest even; where one does not, expect differences of
//! one binary16 step per layer. Beyond the budgets, [`OitFrame::dropped`] and
//! [`OitFrame::overflowed_samples`] say how much was lost.
//!
//! Memory: the head buffer (4 bytes per sample), the node pool
//! ([`OitConfig::pool_bytes`]: [`NODE_BYTES`] per node, `nodes_per_sample` nodes per sample,
//! split over up to [`NODE_BUFFERS`] storage buffers since one binding is limited: 128 MiB on
//! lavapipe, so the default 16 nodes per sample fit up to 512² at 4×) and the targets.

use trisort_format::Mode;
use trisort_format::{FrameState, Geometry};
use trisort_gpu::scene_gpu::{Lighting, SceneGpu, ScenePipeline, View};
use trisort_gpu::Gpu;
use trisort_gpu::{
    clear_colour, halves, quantize_rgba16f, FrameTarget, TargetConfig, COLOR_FORMAT,
};
use wgpu::util::DeviceExt;

use crate::target::{lit_scene, scene_index};
use crate::ReferenceError;

/// Bytes of one node of the pool: colour (4 × f32), depth (f32), triangle id, next index.
pub const NODE_BYTES: u64 = 28;

/// Storage buffers the node pool may be split over (one binding is limited in size: 128 MiB
/// on lavapipe).
pub const NODE_BUFFERS: u32 = 4;

/// Largest accepted [`OitConfig::max_sorted`] (the sort array lives in each invocation's
/// private memory).
pub const MAX_SORTED_LIMIT: u32 = 1024;

/// Size and budgets of an [`OitRenderer`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OitConfig {
    /// Image size (width, height).
    pub size: (u32, u32),
    /// MSAA samples (1 or 4).
    pub samples: u32,
    /// Node-pool budget: average fragments stored per sample (default 16). The pool holds
    /// `nodes_per_sample × width × height × samples` nodes shared by all samples.
    pub nodes_per_sample: u32,
    /// Length of each sample's sort array (default 32): a sample with more fragments keeps
    /// the nearest ones.
    pub max_sorted: u32,
    /// Opacity transmissive glass is drawn at (default: the recorder's,
    /// `RecordSettings::default().glass_opacity`; a baked file's recorded one to compare with
    /// its player).
    pub glass_opacity: f32,
}

impl OitConfig {
    /// The defaults at `size` and `samples`: 16 nodes per sample, a 32-entry sort, glass at
    /// the recorder's default opacity.
    pub fn new(size: (u32, u32), samples: u32) -> OitConfig {
        OitConfig {
            size,
            samples,
            nodes_per_sample: 16,
            max_sorted: 32,
            glass_opacity: trisort_format::RecordSettings::default().glass_opacity,
        }
    }

    /// Samples per frame (`width × height × samples`).
    pub fn sample_count(&self) -> u64 {
        self.size.0 as u64 * self.size.1 as u64 * self.samples as u64
    }

    /// Nodes in the pool.
    pub fn nodes(&self) -> u64 {
        self.nodes_per_sample as u64 * self.sample_count()
    }

    /// Bytes of the node pool.
    pub fn pool_bytes(&self) -> u64 {
        self.nodes() * NODE_BYTES
    }

    /// One line, e.g. `16 fragments/sample pool (112.0 MiB), 32-entry sort`.
    pub fn describe(&self) -> String {
        format!(
            "{} fragments/sample pool ({:.1} MiB), {}-entry sort",
            self.nodes_per_sample,
            self.pool_bytes() as f64 / (1024.0 * 1024.0),
            self.max_sorted
        )
    }

    /// log2 of the nodes per pool buffer: the largest power of two that one storage buffer
    /// binding holds, or the whole pool where it fits in one.
    fn chunk_shift(&self, limits: &wgpu::Limits) -> u32 {
        let largest = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let per_buffer = (largest / NODE_BYTES).max(1);
        if self.nodes() <= per_buffer {
            return 31;
        }
        63 - per_buffer.leading_zeros()
    }

    fn check(&self, limits: &wgpu::Limits) -> Result<(), ReferenceError> {
        let (w, h) = self.size;
        if w == 0 || h == 0 || !(self.samples == 1 || self.samples == 4) {
            return Err(ReferenceError::Invalid(format!(
                "{w}x{h} at {} samples: sizes must be positive and samples 1 or 4",
                self.samples
            )));
        }
        if self.max_sorted == 0 || self.max_sorted > MAX_SORTED_LIMIT {
            return Err(ReferenceError::Invalid(format!(
                "a sort array of {} entries: it must hold 1 to {MAX_SORTED_LIMIT}",
                self.max_sorted
            )));
        }
        // Node indices + 1 and the attempt counter are u32.
        if self.nodes() >= u32::MAX as u64 {
            return Err(ReferenceError::Invalid(format!(
                "{} nodes ({} per sample × {} samples): the pool holds at most {}",
                self.nodes(),
                self.nodes_per_sample,
                self.sample_count(),
                u32::MAX - 1
            )));
        }
        let largest = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        if 4 * self.sample_count() > largest {
            return Err(ReferenceError::Unsupported(format!(
                "the OIT list heads need {} bytes; the device binds at most {largest} bytes in \
                 one storage buffer: lower the size or samples",
                4 * self.sample_count()
            )));
        }
        let chunk = self.chunk_shift(limits);
        let buffers = self.nodes().div_ceil(1u64 << chunk);
        if buffers > NODE_BUFFERS as u64 {
            return Err(ReferenceError::Unsupported(format!(
                "the OIT node pool needs {} bytes ({}); the device binds at most {largest} bytes \
                 in one storage buffer, {} in {NODE_BUFFERS}: lower nodes_per_sample, the size \
                 or samples",
                self.pool_bytes(),
                self.describe(),
                NODE_BUFFERS as u64 * (1u64 << chunk) * NODE_BYTES
            )));
        }
        Ok(())
    }
}

/// Whether the adapter's blend unit rounds to binary16 toward zero when it stores to an
/// `Rgba16Float` target: lavapipe (llvmpipe) does, measured by the tests; other adapters are
/// assumed to round to nearest even. The resolve shader rounds the same way after each
/// Rejects a device or scene the renderer cannot run: `config` over the device's limits, no
/// `PRIMITIVE_INDEX` or fragment-writable storage, or more triangles than one draw holds.
fn check_device(gpu: &Gpu, geometry: &Geometry, config: &OitConfig) -> Result<(), ReferenceError> {
    let device = &gpu.device;
    config.check(&device.limits())?;
    if !device.features().contains(wgpu::Features::PRIMITIVE_INDEX) {
        return Err(ReferenceError::Unsupported(format!(
            "{}: OIT needs PRIMITIVE_INDEX (depth ties are broken by triangle id)",
            gpu.describe()
        )));
    }
    if !gpu
        .adapter
        .get_downlevel_capabilities()
        .flags
        .contains(wgpu::DownlevelFlags::FRAGMENT_WRITABLE_STORAGE)
    {
        return Err(ReferenceError::Unsupported(format!(
            "{}: OIT needs writable storage buffers in fragment shaders",
            gpu.describe()
        )));
    }
    if geometry.triangles.len() as u64 >= u32::MAX as u64 / 3 {
        return Err(ReferenceError::Invalid(format!(
            "{} triangles: one draw holds fewer than {}",
            geometry.triangles.len(),
            u32::MAX / 3
        )));
    }
    Ok(())
}

/// The per-sample lists: head pointers, the node pool, the counters and their bind group
/// (binding 0 the parameters, then heads, counters and the pool buffers).
struct Lists {
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    heads: wgpu::Buffer,
    counters: wgpu::Buffer,
    counters_staging: wgpu::Buffer,
}

impl Lists {
    fn new(gpu: &Gpu, config: &OitConfig) -> Lists {
        let device = &gpu.device;
        let w = config.size.0;
        let buffer = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let heads = buffer("oit heads", 4 * config.sample_count(), storage);
        // The pool over up to NODE_BUFFERS buffers of 2^shift nodes; unused bindings get a
        // one-node dummy.
        let shift = config.chunk_shift(&device.limits());
        let chunk = 1u64 << shift;
        let nodes: Vec<wgpu::Buffer> = (0..NODE_BUFFERS as u64)
            .map(|k| {
                let count = config.nodes().saturating_sub(k * chunk).min(chunk).max(1);
                buffer("oit nodes", count * NODE_BYTES, wgpu::BufferUsages::STORAGE)
            })
            .collect();
        let counters = buffer("oit counters", 8, storage | wgpu::BufferUsages::COPY_SRC);
        let counters_staging = buffer(
            "oit counters readback",
            8,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        let clear = clear_colour(Mode::Blend);
        let mut params = [0u8; 48];
        params[..16].copy_from_slice(bytemuck::cast_slice(&[
            w,
            config.samples,
            config.nodes() as u32,
            blend_rounds_to_zero(&gpu.info) as u32,
        ]));
        params[16..32].copy_from_slice(bytemuck::cast_slice(&[
            clear.r as f32,
            clear.g as f32,
            clear.b as f32,
            clear.a as f32,
        ]));
        params[32..40].copy_from_slice(bytemuck::cast_slice(&[shift, (chunk - 1) as u32]));
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("oit params"),
            contents: &params,
            usage: wgpu::BufferUsages::UNIFORM,
        });

        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty,
            count: None,
        };
        let rw = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: false },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let mut layout_entries = vec![entry(
            0,
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: wgpu::BufferSize::new(48),
            },
        )];
        layout_entries.extend((1..3 + NODE_BUFFERS).map(|b| entry(b, rw)));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("oit"),
            entries: &layout_entries,
        });
        let resources = [&params, &heads, &counters].into_iter().chain(&nodes);
        let entries: Vec<wgpu::BindGroupEntry> = resources
            .enumerate()
            .map(|(binding, buffer)| wgpu::BindGroupEntry {
                binding: binding as u32,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("oit"),
            layout: &layout,
            entries: &entries,
        });
        Lists {
            layout,
            bind_group,
            heads,
            counters,
            counters_staging,
        }
    }
}

/// fragment, so that it composites exactly like the reference's blended layers.
fn blend_rounds_to_zero(info: &wgpu::AdapterInfo) -> bool {
    info.device_type == wgpu::DeviceType::Cpu && info.name.contains("llvmpipe")
}

/// One resolved OIT frame and what its budgets lost.
#[derive(Clone, Debug, PartialEq)]
pub struct OitFrame {
    /// `width × height` pixels, RGBA8, sRGB-encoded, alpha 255 (like the player's frames:
    /// [`quantize_rgba16f`] of the resolved `Rgba16Float` frame).
    pub rgba8: Vec<u8>,
    /// Fragments the list pass tried to store: shaded fragments (covered samples of triangles
    /// not discarded for facing or cut-out) with alpha > 0 (a fully transparent fragment
    /// leaves `over` unchanged, so it is not stored).
    pub fragments: u64,
    /// Fragments lost because the node pool was full.
    pub dropped: u64,
    /// Samples whose list held more than `max_sorted` fragments (the farthest were dropped;
    /// the sample is still exact where an opaque fragment is among the nearest kept).
    pub overflowed_samples: u64,
}

/// The per-sample linked-list OIT renderer for one scene at one size.
pub struct OitRenderer<'g> {
    gpu: &'g Gpu,
    config: OitConfig,
    triangles: u32,
    scene: SceneGpu,
    index: wgpu::Buffer,
    list_pipeline: wgpu::RenderPipeline,
    resolve_pipeline: wgpu::RenderPipeline,
    bind_group: wgpu::BindGroup,
    heads: wgpu::Buffer,
    counters: wgpu::Buffer,
    counters_staging: wgpu::Buffer,
    dummy: wgpu::TextureView,
    target: FrameTarget,
}

impl<'g> OitRenderer<'g> {
    /// Uploads the full scene `geometry` with the path's `frames`, lit as `lighting` says, and
    /// allocates the lists at `config`. Errors where the configuration is invalid, the pool or head buffer exceeds the
    /// device's storage-buffer limits, or the device lacks `PRIMITIVE_INDEX`, writable storage
    /// in fragment shaders or multisampled `Rgba16Float` targets.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        lighting: Lighting<'_>,
        config: OitConfig,
    ) -> Result<OitRenderer<'g>, ReferenceError> {
        let device = &gpu.device;
        check_device(gpu, geometry, &config)?;
        let (w, h) = config.size;
        let target = FrameTarget::new(
            &gpu.adapter,
            device,
            TargetConfig::readback(config.size, config.samples, Mode::Blend),
        )
        .map_err(|e| ReferenceError::Unsupported(format!("{}: {e}", gpu.describe())))?;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let view = View {
            width: w,
            height: h,
            samples: config.samples,
            glass_opacity: config.glass_opacity,
        };
        let shading = lighting.shading;
        let scene = lit_scene(gpu, geometry, frames, view, lighting);
        let index = scene_index(device, geometry, "oit indices");
        let lists = Lists::new(gpu, &config);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("oit"),
            source: wgpu::ShaderSource::Wgsl(trisort_gpu::oit_shader(config.max_sorted).into()),
        });
        // The list pass writes nothing to its colour attachment, which only gives the pass its
        // size and sample count: the smallest format that multisamples.
        let dummy_format = [wgpu::TextureFormat::R8Unorm, COLOR_FORMAT]
            .into_iter()
            .find(|&f| {
                gpu.adapter
                    .get_texture_format_features(f)
                    .flags
                    .sample_count_supported(config.samples)
            })
            .unwrap_or(COLOR_FORMAT);
        // The player's pipeline state (CCW, no hardware culling, its MSAA count, no depth).
        let list_pipeline = ScenePipeline {
            label: "oit lists",
            layouts: &[&scene.layout, &lists.layout],
            module: &module,
            vertex: "vs_player",
            fragment: "fs_oit_list",
            target: wgpu::ColorTargetState {
                format: dummy_format,
                blend: None,
                write_mask: wgpu::ColorWrites::empty(),
            },
            depth: None,
            samples: config.samples,
        }
        .build_shaded(device, shading);
        let resolve_pipeline = trisort_gpu::pipeline::fullscreen(
            device,
            "oit resolve",
            &[&scene.layout, &lists.layout],
            &module,
            ("vs_oit_fullscreen", "fs_oit_resolve"),
            wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            },
            config.samples,
        );
        let dummy = trisort_gpu::pipeline::texture_2d(
            device,
            "oit list pass attachment",
            (w, h),
            config.samples,
            dummy_format,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(ReferenceError::Wgpu(e.to_string()));
        }
        Ok(OitRenderer {
            gpu,
            config,
            triangles: geometry.triangles.len() as u32,
            scene,
            index,
            list_pipeline,
            resolve_pipeline,
            bind_group: lists.bind_group,
            heads: lists.heads,
            counters: lists.counters,
            counters_staging: lists.counters_staging,
            dummy,
            target,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &OitConfig {
        &self.config
    }

    /// Triangles submitted per frame (the whole scene).
    pub fn triangles(&self) -> u64 {
        self.triangles as u64
    }

    /// Render passes with scene geometry per frame (the list pass; the resolve pass draws one
    /// full-screen triangle): the pipeline-statistics query slots [`OitRenderer::encode`]
    /// uses.
    pub fn passes(&self) -> u32 {
        1
    }

    /// Records every GPU command of frame `frame` into `enc`: the clears of the list heads and
    /// counters, the list-building pass and the resolve pass, leaving the resolved
    /// single-sample `Rgba16Float` frame in the renderer's own target. With `stats`, scene
    /// geometry pass `k` (`k < passes()`) is bracketed by
    /// `begin/end_pipeline_statistics_query(stats, k)`. No readback, no CPU sync. Panics if
    /// `frame` is not a frame of the path (as [`SceneGpu::offsets`]).
    pub fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        frame: u32,
        stats: Option<&wgpu::QuerySet>,
    ) {
        enc.clear_buffer(&self.heads, 0, None);
        enc.clear_buffer(&self.counters, 0, None);
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("oit lists"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &self.dummy,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Discard,
                    },
                })],
                ..Default::default()
            });
            if let Some(q) = stats {
                pass.begin_pipeline_statistics_query(q, 0);
            }
            if self.triangles > 0 {
                pass.set_pipeline(&self.list_pipeline);
                pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
                pass.set_bind_group(1, &self.bind_group, &[]);
                pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
                pass.set_index_buffer(self.index.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..self.triangles * 3, 0, 0..1);
            }
            if stats.is_some() {
                pass.end_pipeline_statistics_query();
            }
        }
        let mut pass = self.target.begin_pass(enc, clear_colour(Mode::Blend), None);
        pass.set_pipeline(&self.resolve_pipeline);
        pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
        pass.set_bind_group(1, &self.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }

    /// [`OitRenderer::encode`], submitted and read back with the frame's counters.
    pub fn render(&self, frame: u32) -> Result<OitFrame, ReferenceError> {
        if frame >= self.scene.frames().max(1) {
            return Err(ReferenceError::Invalid(format!(
                "frame {frame}: the path has {}",
                self.scene.frames()
            )));
        }
        let device = &self.gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("oit frame"),
        });
        self.encode(&mut enc, frame, None);
        enc.copy_buffer_to_buffer(&self.counters, 0, &self.counters_staging, 0, 8);
        self.target.copy_to_staging(&mut enc);
        self.gpu.queue.submit([enc.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(ReferenceError::Wgpu(e.to_string()));
        }
        let staging = self.target.staging().expect("created with readback");
        let bytes = self.target.unpad(&self.gpu.map_read(staging));
        let counters: Vec<u32> =
            bytemuck::pod_collect_to_vec(&self.gpu.map_read(&self.counters_staging));
        let fragments = counters[0] as u64;
        Ok(OitFrame {
            rgba8: quantize_rgba16f(&halves(&bytes), None),
            fragments,
            dropped: fragments.saturating_sub(self.config.nodes()),
            overflowed_samples: counters[1] as u64,
        })
    }
}
