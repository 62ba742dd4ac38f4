//! The GPU depth peeler: one render pass per layer, then a gather pass and a readback.
//!
//! Public so that the exact reference (`trisort-reference`) peels with the very pipeline the
//! recorder uses: the same shader, the same (depth, id) keys, the same per-sample targets.

mod build;

use std::ops::Range;

use trisort_format::{FrameState, Geometry};
use trisort_gpu::pipeline::bind_group;
use trisort_gpu::scene_gpu::{begin_peel_pass, SceneGpu, View};
use trisort_gpu::Gpu;

use crate::RecordError;

/// One peel layer read back: per sample (id + 1 or 0, alpha, depth). Sample `s` of pixel
/// (x, y) is slot `(y · width + x) · samples + s`.
pub struct Layer {
    /// Per sample: drawn position + 1, 0 where the layer has no fragment.
    pub ids: Vec<u32>,
    /// Per sample: the fragment's opacity; empty unless read back ([`Peeler::with_readback`]).
    pub alpha: Vec<f32>,
    /// Per sample: the fragment's depth; empty unless read back ([`Peeler::with_readback`]).
    pub depth: Vec<f32>,
}

/// The scene as the recorder's shaders read it, which is only what decides visibility:
/// [`SceneGpu::for_visibility`] (or [`SceneGpu::new`], every texture as a player uploads
/// it, with [`crate::Internals::full_texture_upload`]).
pub(crate) fn visibility_scene(
    gpu: &Gpu,
    geometry: &Geometry,
    frames: &[FrameState],
    view: View,
    internals: &crate::Internals,
) -> SceneGpu {
    let (device, queue) = (&gpu.device, &gpu.queue);
    if internals.full_texture_upload {
        SceneGpu::new(device, queue, geometry, frames, view)
    } else {
        SceneGpu::for_visibility(device, queue, geometry, frames, view)
    }
}

/// Layers peeled and bytes read back by every peeler of the process (benchmarks).
static COUNTERS: [std::sync::atomic::AtomicU64; 2] = [
    std::sync::atomic::AtomicU64::new(0),
    std::sync::atomic::AtomicU64::new(0),
];

/// Benchmarks: layers peeled (render, gather and readback each) and bytes read back from the
/// device, by every peeler of this process so far.
#[doc(hidden)]
pub fn readback_counters() -> (u64, u64) {
    let get = |k: usize| COUNTERS[k].load(std::sync::atomic::Ordering::Relaxed);
    (get(0), get(1))
}

/// A texture of `view`'s size and samples that passes both render into and read from.
pub(crate) fn view_texture(
    device: &wgpu::Device,
    view: &View,
    label: &str,
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    trisort_gpu::pipeline::texture_2d(
        device,
        label,
        (view.width, view.height),
        view.samples,
        format,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    )
}

/// Most triangles drawn by one draw call (keeps single draws and primitive ids modest).
pub(crate) const CHUNK_TRIANGLES: u32 = 1 << 22;

/// Maps the first `len` bytes of `buffer` (a `MAP_READ` buffer the last submission wrote),
/// waits, hands them to `f` as words and unmaps.
pub(crate) fn read_mapped<R>(
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
    len: u64,
    f: impl FnOnce(&[u32]) -> R,
) -> Result<R, RecordError> {
    let slice = buffer.slice(..len);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| RecordError::Device(e.to_string()))?;
    let r = {
        let data = slice
            .get_mapped_range()
            .map_err(|e| RecordError::Device(e.to_string()))?;
        f(bytemuck::cast_slice(&data))
    };
    buffer.unmap();
    Ok(r)
}

/// The peeling pipeline for one scene at one view.
pub struct Peeler<'g> {
    gpu: &'g Gpu,
    scene: SceneGpu,
    pipeline: wgpu::RenderPipeline,
    peel_layout: wgpu::BindGroupLayout,
    gather_pipeline: wgpu::ComputePipeline,
    gather_layout: wgpu::BindGroupLayout,
    index: wgpu::Buffer,
    triangles: u32,
    depth: [wgpu::Texture; 2],
    ids: [wgpu::Texture; 2],
    done: wgpu::Buffer,
    out: wgpu::Buffer,
    staging: wgpu::Buffer,
    params: wgpu::Buffer,
    params_stride: u64,
    dims: wgpu::Buffer,
    view: View,
    plain: wgpu::RenderPipeline,
    /// The grown peel's triangle storage (group 2), for the grown peel.
    grown: Option<wgpu::BindGroup>,
    /// Read back the alpha and depth arrays ([`Peeler::with_readback`]).
    read_alpha: bool,
    read_depth: bool,
    /// The former interleaved gather ([`crate::Internals::interleaved_readback`]).
    interleaved: bool,
}

const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

impl<'g> Peeler<'g> {
    /// Reads back only the per-sample fields asked for (besides the ids, always read back):
    /// `alpha` (phase 1's saturation) and `depth` (phase 2's ties). [`Layer`]'s other fields
    /// stay empty. A new peeler reads back both.
    pub fn with_readback(mut self, alpha: bool, depth: bool) -> Self {
        self.read_alpha = alpha;
        self.read_depth = depth;
        self
    }

    /// Bytes read back from the device per layer: one word a sample for the ids and for each
    /// field read back (16 a sample with [`crate::Internals::interleaved_readback`]).
    pub fn readback_bytes(&self) -> u64 {
        let words = if self.interleaved {
            4
        } else {
            1 + self.read_alpha as u64 + self.read_depth as u64
        };
        self.slots() as u64 * 4 * words
    }

    /// Shifts every frame's projection by `offset` pixels (x right, y down): later layers
    /// are peeled at the sample pattern moved by `-offset` (`record --robust N`'s jittered
    /// patterns, and the reference of `play --subpixel-offset`). `[0.0, 0.0]` restores the
    /// recorded pattern.
    pub fn set_subpixel_offset(&self, offset: [f64; 2]) {
        self.scene.set_subpixel_offset(&self.gpu.queue, offset);
    }

    /// [`Peeler::set_subpixel_offset`] for frame `frame` only: what the recorder's jittered
    /// patterns need, one frame at a time.
    pub fn set_frame_subpixel_offset(&self, frame: u32, offset: [f64; 2]) {
        self.scene
            .set_subpixel_offset_of(&self.gpu.queue, offset, frame..frame + 1);
    }

    /// Number of triangles drawn (ids in a [`Layer`] are positions in this list, plus 1).
    pub fn triangles(&self) -> usize {
        self.triangles as usize
    }

    /// Number of samples in one layer.
    pub fn slots(&self) -> usize {
        self.view.width as usize * self.view.height as usize * self.view.samples as usize
    }

    /// Peels one frame: calls `on_layer` with each layer; it updates `done` (per sample, true
    /// once the sample needs no further layers) and returns whether to continue. Stops when a
    /// layer has no fragment, `on_layer` says stop, or after `max_layers` layers. Returns the
    /// number of layers peeled and whether fragments remained after the last one allowed.
    pub fn peel(
        &self,
        frame: u32,
        max_layers: u32,
        mut on_layer: impl FnMut(u32, &Layer, &mut [u32]) -> Result<bool, RecordError>,
    ) -> Result<(u32, bool), RecordError> {
        let gpu = self.gpu;
        let slots = self.slots();
        let mut done = vec![0u32; slots];
        gpu.queue
            .write_buffer(&self.done, 0, bytemuck::cast_slice(&done));
        let chunk_ranges = self.chunks();
        let n = chunk_ranges.len();
        for (first, offset_group) in [(1u32, 0usize), (0, n)] {
            for (c, r) in chunk_ranges.iter().enumerate() {
                let p = [r.start, self.view.width, self.view.samples, first];
                gpu.queue.write_buffer(
                    &self.params,
                    (offset_group + c) as u64 * self.params_stride,
                    bytemuck::cast_slice(&p),
                );
            }
        }
        let mut layer_no = 0u32;
        loop {
            if layer_no == max_layers {
                // Is anything left? Peel one more layer without keeping it.
                let layer = self.layer(frame, layer_no, &chunk_ranges)?;
                let left = layer
                    .ids
                    .iter()
                    .zip(&done)
                    .any(|(&id, &d)| id != 0 && d == 0);
                return Ok((layer_no, left));
            }
            let layer = self.layer(frame, layer_no, &chunk_ranges)?;
            layer_no += 1;
            if layer
                .ids
                .iter()
                .zip(&done)
                .all(|(&id, &d)| id == 0 || d != 0)
            {
                return Ok((layer_no - 1, false));
            }
            // A sample with no fragment in this layer has none in any later one.
            for (d, &id) in done.iter_mut().zip(&layer.ids) {
                if id == 0 {
                    *d = 1;
                }
            }
            let go_on = on_layer(layer_no - 1, &layer, &mut done)?;
            if !go_on || done.iter().all(|&d| d != 0) {
                return Ok((layer_no, false));
            }
            gpu.queue
                .write_buffer(&self.done, 0, bytemuck::cast_slice(&done));
        }
    }

    fn chunks(&self) -> Vec<Range<u32>> {
        (0..self.triangles.div_ceil(CHUNK_TRIANGLES).max(1))
            .map(|c| c * CHUNK_TRIANGLES..((c + 1) * CHUNK_TRIANGLES).min(self.triangles))
            .collect()
    }

    /// Benchmarks: wall milliseconds of one render pass (submitted and waited for): a peel
    /// layer (`layer_no` 0: the first, else a later one against whatever the previous-layer
    /// textures hold) or, with `plain`, the plain pass over the same triangles.
    pub fn time_render(&self, frame: u32, layer_no: u32, plain: bool) -> Result<f64, RecordError> {
        let device = &self.gpu.device;
        let chunks = self.chunks();
        let cur = (layer_no % 2) as usize;
        let prev = 1 - cur;
        let dv = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (depth_views, id_views) = (
            [dv(&self.depth[0]), dv(&self.depth[1])],
            [dv(&self.ids[0]), dv(&self.ids[1])],
        );
        let peel_bg = self.peel_bind_group(&depth_views[prev], &id_views[prev]);
        let t = std::time::Instant::now();
        let mut enc = device.create_command_encoder(&Default::default());
        {
            let mut pass = begin_peel_pass(
                &mut enc,
                "peel layer",
                &id_views[cur],
                &depth_views[cur],
                1.0,
                None,
            );
            pass.set_pipeline(if plain { &self.plain } else { &self.pipeline });
            pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
            pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
            pass.set_index_buffer(self.index.slice(..), wgpu::IndexFormat::Uint32);
            let group = if layer_no == 0 { 0 } else { chunks.len() };
            for (c, r) in chunks.iter().enumerate() {
                if !plain {
                    pass.set_bind_group(
                        1,
                        &peel_bg,
                        &[((group + c) as u64 * self.params_stride) as u32],
                    );
                }
                pass.draw_indexed(r.start * 3..r.end * 3, 0, 0..1);
            }
        }
        self.gpu.queue.submit([enc.finish()]);
        self.gpu
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RecordError::Device(e.to_string()))?;
        Ok(t.elapsed().as_secs_f64() * 1000.0)
    }

    fn peel_bind_group(
        &self,
        prev_depth: &wgpu::TextureView,
        prev_ids: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        bind_group(
            &self.gpu.device,
            "peel",
            &self.peel_layout,
            &[
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &self.params,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
                wgpu::BindingResource::TextureView(prev_depth),
                wgpu::BindingResource::TextureView(prev_ids),
                self.done.as_entire_binding(),
            ],
        )
    }

    fn layer(
        &self,
        frame: u32,
        layer_no: u32,
        chunks: &[Range<u32>],
    ) -> Result<Layer, RecordError> {
        let device = &self.gpu.device;
        let cur = (layer_no % 2) as usize;
        let prev = 1 - cur;
        let dv = |t: &wgpu::Texture| t.create_view(&Default::default());
        let depth_views = [dv(&self.depth[0]), dv(&self.depth[1])];
        let id_views = [dv(&self.ids[0]), dv(&self.ids[1])];
        let peel_bg = self.peel_bind_group(&depth_views[prev], &id_views[prev]);
        let gather_bg = bind_group(
            device,
            "gather",
            &self.gather_layout,
            &[
                wgpu::BindingResource::TextureView(&id_views[cur]),
                wgpu::BindingResource::TextureView(&depth_views[cur]),
                self.out.as_entire_binding(),
                self.dims.as_entire_binding(),
            ],
        );
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("peel layer"),
        });
        {
            let mut pass = begin_peel_pass(
                &mut enc,
                "peel layer",
                &id_views[cur],
                &depth_views[cur],
                1.0,
                None,
            );
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
            pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
            pass.set_index_buffer(self.index.slice(..), wgpu::IndexFormat::Uint32);
            if let Some(g) = &self.grown {
                pass.set_bind_group(2, g, &[]);
            }
            let group = if layer_no == 0 { 0 } else { chunks.len() };
            for (c, r) in chunks.iter().enumerate() {
                if r.is_empty() {
                    continue;
                }
                pass.set_bind_group(
                    1,
                    &peel_bg,
                    &[((group + c) as u64 * self.params_stride) as u32],
                );
                if self.grown.is_some() {
                    // Pulled from storage: the triangle is vertex_index / 3, no index buffer.
                    pass.draw(r.start * 3..r.end * 3, 0..1);
                } else {
                    pass.draw_indexed(r.start * 3..r.end * 3, 0, 0..1);
                }
            }
        }
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.gather_pipeline);
            pass.set_bind_group(0, &gather_bg, &[]);
            pass.dispatch_workgroups(self.view.width.div_ceil(8), self.view.height.div_ceil(8), 1);
        }
        let slots = self.slots();
        let array = slots as u64 * 4;
        if self.interleaved {
            enc.copy_buffer_to_buffer(&self.out, 0, &self.staging, 0, self.out.size());
        } else {
            // The ids, then only the arrays asked for, each to its own offset.
            enc.copy_buffer_to_buffer(&self.out, 0, &self.staging, 0, array);
            for (k, wanted) in [(1u64, self.read_alpha), (2, self.read_depth)] {
                if wanted {
                    enc.copy_buffer_to_buffer(
                        &self.out,
                        k * array,
                        &self.staging,
                        k * array,
                        array,
                    );
                }
            }
        }
        self.gpu.queue.submit([enc.finish()]);
        COUNTERS[0].fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        COUNTERS[1].fetch_add(self.readback_bytes(), std::sync::atomic::Ordering::Relaxed);
        let mut layer = Layer {
            ids: Vec::new(),
            alpha: Vec::new(),
            depth: Vec::new(),
        };
        read_mapped(self.gpu, &self.staging, self.staging.size(), |words| {
            if self.interleaved {
                layer.ids.reserve(slots);
                layer.alpha.reserve(slots);
                layer.depth.reserve(slots);
                for s in words.chunks_exact(4) {
                    layer.ids.push(s[0]);
                    layer.alpha.push(f32::from_bits(s[1]));
                    layer.depth.push(f32::from_bits(s[2]));
                }
            } else {
                let array = |k: usize| &words[k * slots..(k + 1) * slots];
                layer.ids = array(0).to_vec();
                if self.read_alpha {
                    layer.alpha = bytemuck::cast_slice(array(1)).to_vec();
                }
                if self.read_depth {
                    layer.depth = bytemuck::cast_slice(array(2)).to_vec();
                }
            }
        })?;
        Ok(layer)
    }
}
