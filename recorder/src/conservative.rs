//! Conservative visibility by three passes (`record --conservative` on devices that cannot
//! capture, or with [`crate::Internals::conservative_passes`]; where a device captures, phase 1
//! takes the envelope bound of `envelope.rs` instead, which has no sample-spacing blind spot):
//! the triangles that can win a sample when the sample pattern moves by up to the tolerance,
//! found in three render passes per frame (see `shaders/record/conservative.wgsl`):
//! 1. the opaque triangles as rasterized at the recorded pattern write their plane's farthest
//!    depth over a box of ±(tolerance + 0.55) px: the nearest opaque surface, raised by its
//!    slope;
//! 2. per sample, the largest of those depths over the samples within ±(tolerance + 0.55) px
//!    (1 beyond the image): a depth the opaque surface is nearer than everywhere in the
//!    sample's ±tolerance box;
//! 3. every triangle grown by the box sets its flag where its nearest depth over the box is
//!    not behind that depth.
//!
//! The flags are read back per frame and join V_f. Phase 2 takes the edges these triangles
//! need from the layers of the grown triangles: captured in one pass (`capture_grown.wgsl`)
//! where the device can, else peeled (the grown peel, `peel_grown.wgsl`).
//!
//! What it guarantees, and where not: a triangle that wins a sample moved by up to the
//! tolerance is flagged unless the opaque surface in front of it leaves a gap narrower than
//! the sample spacing that no sample of the pattern falls in (pass 2 sees the surface only at
//! samples; a per-triangle test, exact but blind to surfaces made of triangles smaller than
//! the box, kept 12 times too many triangles on CarConcept at 128²). Transparent surfaces never
//! occlude (a stack of them that saturates a sample still lets what lies behind through).
//! What it adds to V_f costs draws, never exactness: a triangle drawn where it is hidden
//! changes no pixel.

use trisort_format::{DepthAt, FrameState, Geometry, Robust};
use trisort_gpu::pipeline::{storage_entry, uniform_entry};
use trisort_gpu::scene_gpu::{SceneGpu, View};
use trisort_gpu::Gpu;
use wgpu::util::DeviceExt;

use crate::RecordError;

const SURFACE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const OCCLUDER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
const MARK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;

/// The conservative visibility passes for one scene at one view.
pub struct Conservative<'g> {
    gpu: &'g Gpu,
    scene: SceneGpu,
    occlude: wgpu::RenderPipeline,
    spread: wgpu::RenderPipeline,
    mark: wgpu::RenderPipeline,
    occlude_group: wgpu::BindGroup,
    spread_group: wgpu::BindGroup,
    mark_group: wgpu::BindGroup,
    surface: wgpu::TextureView,
    occluder: wgpu::TextureView,
    target: wgpu::TextureView,
    flags: wgpu::Buffer,
    staging: wgpu::Buffer,
    triangles: u32,
}

/// The storage a grown or shrunk triangle is pulled from (`grow.wgsl`, bindings 0–2 of its
/// group): the tolerance and pixel scale, every vertex's position and node, and the drawn
/// triangles' vertex indices and material, in draw order.
pub(crate) struct GrowBuffers {
    params: wgpu::Buffer,
    vertices: wgpu::Buffer,
    triangle_buffer: wgpu::Buffer,
    /// Triangles drawn.
    pub(crate) triangles: u32,
}

impl GrowBuffers {
    /// The buffers for drawing `triangles` (indices into `geometry.triangles`, in draw order)
    /// at `view`, grown by `robust`'s tolerance in pixels plus half a step of its raster
    /// profile's coarsest sub-pixel grid (how far a snapped corner moves in x and y), with the
    /// profile for the envelope capture (`grow.wgsl`'s `Cons`).
    pub(crate) fn new(
        device: &wgpu::Device,
        geometry: &Geometry,
        triangles: &[u32],
        view: View,
        robust: &Robust,
    ) -> GrowBuffers {
        let profile = robust.profile;
        let reach = robust.sample_box();
        let params: [f32; 8] = [
            reach,
            reach,
            view.width as f32 / 2.0,
            view.height as f32 / 2.0,
            (profile.depth_at == DepthAt::Pixel) as u32 as f32,
            // The snap's reach along a diagonal (√2 times its reach in x and y), written as
            // the grid step over √2 so that it rounds as it always did.
            2.0 * profile.snap_reach() * std::f32::consts::FRAC_1_SQRT_2,
            profile.subpixel_bits_min as f32,
            profile.subpixel_bits_max as f32,
        ];
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let params = buffer(
            "grow params",
            bytemuck::cast_slice(&params),
            wgpu::BufferUsages::UNIFORM,
        );
        let mut vertices: Vec<[f32; 4]> = geometry
            .vertices
            .iter()
            .map(|v| {
                [
                    v.position[0],
                    v.position[1],
                    v.position[2],
                    f32::from_bits(v.node),
                ]
            })
            .collect();
        if vertices.is_empty() {
            vertices.push([0.0; 4]);
        }
        let mut tris: Vec<[u32; 4]> = triangles
            .iter()
            .map(|&t| {
                let t = geometry.triangles[t as usize];
                [t[0], t[1], t[2], geometry.vertices[t[0] as usize].material]
            })
            .collect();
        let count = tris.len() as u32;
        if tris.is_empty() {
            tris.push([0; 4]);
        }
        GrowBuffers {
            params,
            vertices: buffer(
                "grow vertices",
                bytemuck::cast_slice(&vertices),
                wgpu::BufferUsages::STORAGE,
            ),
            triangle_buffer: buffer(
                "grow triangles",
                bytemuck::cast_slice(&tris),
                wgpu::BufferUsages::STORAGE,
            ),
            triangles: count,
        }
    }

    /// The layout entries of bindings 0–2.
    pub(crate) fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 3] {
        let both = wgpu::ShaderStages::VERTEX_FRAGMENT;
        [
            uniform_entry(0, both, false, None),
            storage_entry(1, both, true),
            storage_entry(2, both, true),
        ]
    }

    /// The bind group entries of bindings 0–2.
    pub(crate) fn entries(&self) -> [wgpu::BindGroupEntry<'_>; 3] {
        [
            wgpu::BindGroupEntry {
                binding: 0,
                resource: self.params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: self.vertices.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: self.triangle_buffer.as_entire_binding(),
            },
        ]
    }
}

/// The shader stages of a [`pulled_pipeline`]: the module and its (vertex, fragment) entry
/// points.
#[derive(Clone, Copy)]
pub(crate) struct PulledStages<'a> {
    pub module: &'a wgpu::ShaderModule,
    pub entries: (&'a str, &'a str),
}

/// What a [`pulled_pipeline`] draws into: an optional colour target (`None`: depth only), an
/// optional depth test (written), and the MSAA sample count.
#[derive(Clone, Copy)]
pub(crate) struct PulledTargets {
    pub target: Option<wgpu::TextureFormat>,
    pub depth: Option<(wgpu::TextureFormat, wgpu::CompareFunction)>,
    pub samples: u32,
}

/// A pipeline whose vertex stage pulls triangles from storage (no vertex buffers, the
/// triangle is `vertex_index / 3`): counter-clockwise front faces, no hardware culling (the
/// shader discards culled faces), the MSAA samples of `targets`, its optional colour target
/// with writes off unless it is the peel's id target, its optional depth test (written).
pub(crate) fn pulled_pipeline(
    device: &wgpu::Device,
    label: &str,
    layouts: &[&wgpu::BindGroupLayout],
    stages: PulledStages,
    targets: PulledTargets,
) -> wgpu::RenderPipeline {
    let PulledStages { module, entries } = stages;
    let PulledTargets {
        target,
        depth,
        samples,
    } = targets;
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|l| Some(*l)).collect();
    let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    });
    let targets: Vec<Option<wgpu::ColorTargetState>> = target
        .map(|format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: if format == MARK_FORMAT {
                    wgpu::ColorWrites::empty()
                } else {
                    wgpu::ColorWrites::ALL
                },
            })
        })
        .into_iter()
        .collect();
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&pl),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(entries.0),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState {
            front_face: wgpu::FrontFace::Ccw,
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: depth.map(|(format, compare)| wgpu::DepthStencilState {
            format,
            depth_write_enabled: Some(true),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: samples,
            mask: !0,
            alpha_to_coverage_enabled: false,
        },
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(entries.1),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl<'g> Conservative<'g> {
    /// Sets up the passes over every triangle of `geometry` for the path's `frames` at `view`
    /// with `robust`'s tolerance in pixels (the passes take no other part of its raster
    /// profile: they compare depths over ±(tolerance + 0.55) px, wider than any profile's box,
    /// and assume no snapping beyond the tolerance).
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
        robust: &Robust,
        internals: &crate::Internals,
    ) -> Result<Conservative<'g>, RecordError> {
        let device = &gpu.device;
        let scene = crate::peeler::visibility_scene(gpu, geometry, frames, view, internals);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("conservative"),
            source: wgpu::ShaderSource::Wgsl(trisort_gpu::conservative_shader(view.samples).into()),
        });
        let all: Vec<u32> = (0..geometry.triangles.len() as u32).collect();
        let grow = GrowBuffers::new(device, geometry, &all, view, robust);
        let count = grow.triangles;
        let flags_size = 4 * count.max(1) as u64;
        let flags = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("conservative flags"),
            size: flags_size,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("conservative flags readback"),
            size: flags_size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let [occlude_layout, spread_layout, mark_layout] = pass_layouts(device, view.samples);
        let texture = |label, format| {
            crate::peeler::view_texture(device, &view, label, format)
                .create_view(&Default::default())
        };
        let surface = texture("conservative surface", SURFACE_FORMAT);
        let occluder = texture("conservative occluders", OCCLUDER_FORMAT);
        let target = texture("conservative mark target", MARK_FORMAT);
        let base_entries = grow.entries();
        let occlude_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("conservative occluders"),
            layout: &occlude_layout,
            entries: &base_entries,
        });
        let spread_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("conservative spread"),
            layout: &spread_layout,
            entries: &[
                base_entries[0].clone(),
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::TextureView(&surface),
                },
            ],
        });
        let mut mark_entries = base_entries.to_vec();
        mark_entries.push(wgpu::BindGroupEntry {
            binding: 3,
            resource: wgpu::BindingResource::TextureView(&occluder),
        });
        mark_entries.push(wgpu::BindGroupEntry {
            binding: 4,
            resource: flags.as_entire_binding(),
        });
        let mark_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("conservative mark"),
            layout: &mark_layout,
            entries: &mark_entries,
        });
        // Each pass's pipeline: the scene (group 0) and its own group 1.
        let pulled = |label, layout, entries, target, depth| {
            pulled_pipeline(
                device,
                label,
                &[&scene.layout, layout],
                PulledStages {
                    module: &module,
                    entries,
                },
                PulledTargets {
                    target,
                    depth,
                    samples: view.samples,
                },
            )
        };
        let occlude = pulled(
            "conservative occluders",
            &occlude_layout,
            ("vs_occlude", "fs_occlude"),
            None,
            Some((SURFACE_FORMAT, wgpu::CompareFunction::Less)),
        );
        let spread = pulled(
            "conservative spread",
            &spread_layout,
            ("vs_full", "fs_spread"),
            Some(OCCLUDER_FORMAT),
            None,
        );
        let mark = pulled(
            "conservative mark",
            &mark_layout,
            ("vs_dilate", "fs_mark"),
            Some(MARK_FORMAT),
            None,
        );
        Ok(Conservative {
            gpu,
            scene,
            occlude,
            spread,
            mark,
            occlude_group,
            spread_group,
            mark_group,
            surface,
            occluder,
            target,
            flags,
            staging,
            triangles: count,
        })
    }
    /// Records one pass of frame `frame`: `draw`, into the color target `color` (view, clear
    /// color, store) or, without one, into `surface`'s depth cleared to 1 and stored.
    fn pass(
        &self,
        enc: &mut wgpu::CommandEncoder,
        frame: u32,
        color: Option<(&wgpu::TextureView, wgpu::Color, wgpu::StoreOp)>,
        draw: PassDraw,
    ) {
        let PassDraw {
            label,
            pipeline,
            group,
            vertices,
        } = draw;
        let color = color.map(|(view, clear, store)| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clear),
                    store,
                },
            })
        });
        let depth = color
            .is_none()
            .then_some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.surface,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            });
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            // No color slot at all for the depth-only pass (its pipeline has no target).
            color_attachments: color.as_slice(),
            depth_stencil_attachment: depth,
            ..Default::default()
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
        pass.set_bind_group(1, group, &[]);
        pass.draw(vertices, 0..1);
    }

    /// The triangles (indices into the geometry) that may win a sample of frame `frame` when
    /// the pattern moves within the tolerance, ascending.
    pub fn visible(&self, frame: u32) -> Result<Vec<u32>, RecordError> {
        if self.triangles == 0 {
            return Ok(vec![]);
        }
        let device = &self.gpu.device;
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("conservative"),
        });
        enc.clear_buffer(&self.flags, 0, None);
        let triangles = 0..3 * self.triangles;
        // The occluders' depth, then spread over the tolerance, then the marks (flags only).
        self.pass(
            &mut enc,
            frame,
            None,
            PassDraw {
                label: "conservative occluders",
                pipeline: &self.occlude,
                group: &self.occlude_group,
                vertices: triangles.clone(),
            },
        );
        let spread = (&self.occluder, wgpu::Color::WHITE, wgpu::StoreOp::Store);
        self.pass(
            &mut enc,
            frame,
            Some(spread),
            PassDraw {
                label: "conservative spread",
                pipeline: &self.spread,
                group: &self.spread_group,
                vertices: 0..3,
            },
        );
        let mark = (
            &self.target,
            wgpu::Color::TRANSPARENT,
            wgpu::StoreOp::Discard,
        );
        self.pass(
            &mut enc,
            frame,
            Some(mark),
            PassDraw {
                label: "conservative mark",
                pipeline: &self.mark,
                group: &self.mark_group,
                vertices: triangles,
            },
        );
        enc.copy_buffer_to_buffer(&self.flags, 0, &self.staging, 0, self.flags.size());
        self.gpu.queue.submit([enc.finish()]);
        let bytes = trisort_gpu::map_read_all(device, &[&self.staging])
            .map_err(|e| RecordError::Device(e.to_string()))?;
        // One u32 flag a triangle (the bytes need not be 4-aligned: no cast).
        Ok(bytes[0]
            .chunks_exact(4)
            .take(self.triangles as usize)
            .enumerate()
            .filter(|(_, f)| *f != [0; 4])
            .map(|(t, _)| t as u32)
            .collect())
    }
}

/// What one of [`Conservative`]'s passes draws: `vertices` of `pipeline`, with `group` in
/// group 1.
struct PassDraw<'a> {
    label: &'a str,
    pipeline: &'a wgpu::RenderPipeline,
    group: &'a wgpu::BindGroup,
    vertices: std::ops::Range<u32>,
}

/// The bind group layouts (group 1) of the three passes: occluders (the grown triangles),
/// spread (the occluders' depth) and mark (the grown triangles, the spread occluders and the
/// flags).
fn pass_layouts(device: &wgpu::Device, samples: u32) -> [wgpu::BindGroupLayout; 3] {
    let base = GrowBuffers::layout_entries();
    let occlude_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("conservative occluders"),
        entries: &base,
    });
    let texture_entry = |binding, sample_type| {
        trisort_gpu::pipeline::texture_entry(
            binding,
            wgpu::ShaderStages::FRAGMENT,
            sample_type,
            samples,
        )
    };
    let spread_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("conservative spread"),
        entries: &[base[0], texture_entry(5, wgpu::TextureSampleType::Depth)],
    });
    let mut mark_layout_entries = base.to_vec();
    mark_layout_entries.push(texture_entry(
        3,
        wgpu::TextureSampleType::Float { filterable: false },
    ));
    mark_layout_entries.push(storage_entry(4, wgpu::ShaderStages::FRAGMENT, false));
    let mark_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("conservative mark"),
        entries: &mark_layout_entries,
    });
    [occlude_layout, spread_layout, mark_layout]
}
