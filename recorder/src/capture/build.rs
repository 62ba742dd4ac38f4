//! Setting a capture up: its shader, pipelines (plain, grown, and phase 1's prepass of the
//! always-opaque triangles), the draws over the drawn list, and the list heads and counter.

use std::ops::Range;

use trisort_format::{AlphaMode, FrameState, Geometry};
use trisort_gpu::pipeline::storage_entry;
use trisort_gpu::pipeline::uniform_entry;
use trisort_gpu::scene_gpu::{vertex_layout, View};
use trisort_gpu::Gpu;
use wgpu::util::DeviceExt;

use super::{binding_limit, Capture, Grow, Kind, Prepass};
use crate::conservative::{pulled_pipeline, GrowBuffers, PulledStages, PulledTargets};
use crate::peeler::CHUNK_TRIANGLES;
use crate::RecordError;

impl<'g> Capture<'g> {
    /// Sets up a capture of `kind` ([`Capture::new`], [`Capture::grown`]).
    pub(super) fn build(
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
        let slots = heads_fit(device, view)?;
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
        let layout = capture_layout(device);
        let pipelines = Pipelines {
            device,
            module: &module,
            view,
        };
        let compare = if until_opaque {
            wgpu::CompareFunction::LessEqual
        } else {
            wgpu::CompareFunction::Always
        };
        let layouts = [&scene.layout, &layout];
        let (pipelines_built, grown) = match grow {
            None => (pipelines.plain(layouts, compare), None),
            Some(grow) => {
                let (pipeline, group) =
                    pipelines.grown(geometry, triangles, grow, layouts, compare);
                (vec![pipeline], Some(group))
            }
        };
        let prepass = until_opaque.then(|| pipelines.prepass(&scene.layout, geometry, triangles));
        let depth = trisort_gpu::pipeline::texture_2d(
            device,
            "capture depth",
            (view.width, view.height),
            view.samples,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let draws = Draws::new(device, geometry, triangles, grow.is_some());
        let params_stride = device.limits().min_uniform_buffer_offset_alignment.max(16) as u64;
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("capture params"),
            size: draws.draws.len().max(1) as u64 * params_stride,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let readable = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC;
        let heads = buffer(device, "capture heads", slots * 4, readable);
        let counter = buffer(device, "capture counter", 16, readable);
        let counter_staging = buffer(
            device,
            "capture counter readback",
            16,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        let mut capture = Capture {
            gpu,
            scene,
            pipelines: pipelines_built,
            layout,
            index: draws.index,
            grown,
            draw_ids: draws.draw_ids,
            draws: draws.draws,
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
}

/// The samples of `view` (one list head each) if their heads fit one storage binding of
/// `device`.
fn heads_fit(device: &wgpu::Device, view: View) -> Result<u64, RecordError> {
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
    Ok(slots)
}

/// The capture's own bind group (group 1): parameters, heads, counter, node pool, draw ids.
fn capture_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let fragment = wgpu::ShaderStages::FRAGMENT;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("capture"),
        entries: &[
            uniform_entry(0, fragment, true, Some(16)),
            storage_entry(1, fragment, false),
            storage_entry(2, fragment, false),
            storage_entry(3, fragment, false),
            storage_entry(4, fragment, true),
        ],
    })
}

/// A buffer of `size` bytes, not mapped.
fn buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage,
        mapped_at_creation: false,
    })
}

/// What every pipeline of one capture shares: the device, the capture shader and the view
/// (its sample count).
struct Pipelines<'a> {
    device: &'a wgpu::Device,
    module: &'a wgpu::ShaderModule,
    view: View,
}

/// How a capture pipeline tests depth: whether it writes depth, its comparison and its bias.
type DepthTest = (bool, wgpu::CompareFunction, wgpu::DepthBiasState);

impl Pipelines<'_> {
    /// A pipeline drawing from the scene's vertex buffer with `vs_record`, into no colour
    /// target, with `depth` as its depth test and, given constants, the capturing fragment
    /// stage `fs_capture` (without: depth only).
    fn pipeline(
        &self,
        label: &str,
        layout: &wgpu::PipelineLayout,
        cull_mode: Option<wgpu::Face>,
        depth: DepthTest,
        fragment: Option<&[(&str, f64)]>,
    ) -> wgpu::RenderPipeline {
        let (write, compare, bias) = depth;
        let module = self.module;
        self.device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
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
                    count: self.view.samples,
                    ..Default::default()
                },
                fragment: fragment.map(|constants| wgpu::FragmentState {
                    module,
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
    }

    /// The plain capture's two pipelines: for triangles whose opacity needs no texture, and
    /// the general one. No colour target. Without the prepass no depth test either
    /// (`compare` is `Always`): every fragment is kept (the depth attachment only gives the
    /// pass its sample count); with it, `LessEqual` against the nearest always-opaque
    /// fragment, not written.
    fn plain(
        &self,
        layouts: [&wgpu::BindGroupLayout; 2],
        compare: wgpu::CompareFunction,
    ) -> Vec<wgpu::RenderPipeline> {
        let layout = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("capture"),
                bind_group_layouts: &layouts.map(Some),
                immediate_size: 0,
            });
        let pipelines = [0.0, 1.0].map(|reads_alpha| {
            let constants = [("READS_ALPHA", reads_alpha)];
            self.pipeline(
                "capture",
                &layout,
                None,
                (false, compare, wgpu::DepthBiasState::default()),
                Some(&constants),
            )
        });
        Vec::from(pipelines)
    }

    /// The grown capture's one pipeline, which pulls the drawn triangles from storage (group
    /// 2, returned with it) and writes depth with `compare` (`Always`, which keeps every
    /// fragment); the envelope's also reads each triangle's opposite vertices.
    fn grown(
        &self,
        geometry: &Geometry,
        triangles: &[u32],
        grow: Grow,
        layouts: [&wgpu::BindGroupLayout; 2],
        compare: wgpu::CompareFunction,
    ) -> (wgpu::RenderPipeline, wgpu::BindGroup) {
        let device = self.device;
        let buffers = GrowBuffers::new(device, geometry, triangles, self.view, grow.robust());
        let mut layout_entries = GrowBuffers::layout_entries().to_vec();
        let mut entries = buffers.entries().to_vec();
        let opposite = match grow {
            Grow::Peel(_) => None,
            Grow::Envelope(_, opposite) => Some(opposite_buffer(device, opposite)),
        };
        if let Some(opposite) = &opposite {
            layout_entries.push(storage_entry(3, wgpu::ShaderStages::VERTEX, true));
            entries.push(wgpu::BindGroupEntry {
                binding: 3,
                resource: opposite.as_entire_binding(),
            });
        }
        let grow_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("grown capture"),
            entries: &layout_entries,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("grown capture"),
            layout: &grow_layout,
            entries: &entries,
        });
        let entries = match grow {
            Grow::Peel(_) => ("vs_grown", "fs_capture_grown"),
            Grow::Envelope(..) => ("vs_envelope", "fs_capture_envelope"),
        };
        let pipeline = pulled_pipeline(
            device,
            "grown capture",
            &[layouts[0], layouts[1], &grow_layout],
            PulledStages {
                module: self.module,
                entries,
            },
            PulledTargets {
                target: None,
                depth: Some((wgpu::TextureFormat::Depth32Float, compare)),
                samples: self.view.samples,
            },
        );
        (pipeline, group)
    }

    /// Phase 1's depth prepass: the always-opaque triangles among `triangles`, single- and
    /// double-sided, drawn depth only before the capture.
    fn prepass(
        &self,
        scene_layout: &wgpu::BindGroupLayout,
        geometry: &Geometry,
        triangles: &[u32],
    ) -> Prepass {
        let device = self.device;
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("capture prepass"),
            bind_group_layouts: &[Some(scene_layout)],
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
            self.pipeline(
                "capture prepass",
                &layout,
                Some(wgpu::Face::Back),
                depth,
                None,
            ),
            self.pipeline("capture prepass", &layout, None, depth, None),
        ];
        let indices = opaque_indices(geometry, triangles, self.view.glass_opacity)
            .map(|list| (index_buffer(device, &list), (list.len() / 3) as u32));
        Prepass { pipelines, indices }
    }
}

/// The envelope's opposite vertices in a storage buffer (one unused entry where there are
/// none: buffers may not be empty).
fn opposite_buffer(device: &wgpu::Device, opposite: &[[u32; 4]]) -> wgpu::Buffer {
    let empty = [[u32::MAX; 4]];
    let data = if opposite.is_empty() {
        &empty[..]
    } else {
        opposite
    };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("envelope opposite vertices"),
        contents: bytemuck::cast_slice(data),
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// How a capture draws its triangles: the index buffer (none for the grown capture, which
/// pulls its triangles from storage), each drawn triangle's position in the drawn list, and
/// the draws (pipeline, triangles of the index buffer).
struct Draws {
    index: Option<wgpu::Buffer>,
    draw_ids: wgpu::Buffer,
    draws: Vec<(usize, Range<u32>)>,
}

impl Draws {
    /// The draws over `triangles` ([`draw_order`]; `grown`: in drawn order, one part).
    fn new(device: &wgpu::Device, geometry: &Geometry, triangles: &[u32], grown: bool) -> Draws {
        // The grown capture pulls triangle k of the drawn list as draw triangle k: one part.
        let (order, without_texture) = if grown {
            (
                (0..triangles.len() as u32).collect(),
                triangles.len() as u32,
            )
        } else {
            draw_order(geometry, triangles)
        };
        let mut index_data: Vec<u32> = Vec::with_capacity(triangles.len() * 3);
        for &position in &order {
            index_data
                .extend_from_slice(&geometry.triangles[triangles[position as usize] as usize]);
        }
        let index = (!grown).then(|| index_buffer(device, &index_data));
        // The grown capture reads no table (its ids are its draw's triangles): one word.
        let ids: &[u32] = if order.is_empty() || grown {
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
        Draws {
            index,
            draw_ids,
            draws,
        }
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
