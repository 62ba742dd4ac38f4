//! Conservative visibility (`record --conservative`, [`trisort_format::Robust`]): the
//! triangles that can win a sample when the sample pattern moves by up to the tolerance, found
//! in two render passes per frame (see `gpu/src/wgsl/conservative.wgsl`):
//! 1. the opaque triangles shrunk by the tolerance box write their farthest depth over the box
//!    (depth test `Less`): per sample, a depth that some opaque surface is nearer than under
//!    every placement of the sample within the box;
//! 2. every triangle grown by the box sets its flag where its nearest depth over the box is not
//!    behind that depth.
//!
//! The flags are read back per frame. This over-approximates "wins a sample under some
//! placement": transparent surfaces never occlude (a stack of them that saturates the sample
//! still lets what lies behind through), and the grown triangle is the edge-offset triangle
//! clipped to its grown bounding box, a superset of the exact Minkowski sum. What it adds to
//! V_f costs draws, never exactness: a triangle drawn where it is hidden changes no pixel.

use trisort_format::{FrameState, Geometry};
use trisort_gpu::scene_gpu::{SceneGpu, View};
use trisort_gpu::Gpu;
use wgpu::util::DeviceExt;

use crate::RecordError;

const OCCLUDER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const MARK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;

/// The conservative visibility passes for one scene at one view.
pub struct Conservative<'g> {
    gpu: &'g Gpu,
    scene: SceneGpu,
    erode: wgpu::RenderPipeline,
    mark: wgpu::RenderPipeline,
    erode_group: wgpu::BindGroup,
    mark_group: wgpu::BindGroup,
    occluder: wgpu::TextureView,
    target: wgpu::TextureView,
    flags: wgpu::Buffer,
    staging: wgpu::Buffer,
    triangles: u32,
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl<'g> Conservative<'g> {
    /// Sets up the passes over every triangle of `geometry` for the path's `frames` at `view`
    /// with a tolerance of `tolerance` pixels.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        view: View,
        tolerance: f32,
    ) -> Result<Conservative<'g>, RecordError> {
        let device = &gpu.device;
        let scene = SceneGpu::new(device, &gpu.queue, geometry, frames, view);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("conservative"),
            source: wgpu::ShaderSource::Wgsl(trisort_gpu::conservative_shader(view.samples).into()),
        });
        let params: [f32; 4] = [
            tolerance,
            tolerance,
            view.width as f32 / 2.0,
            view.height as f32 / 2.0,
        ];
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let params = buffer(
            "conservative params",
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
        let mut triangles: Vec<[u32; 4]> = geometry
            .triangles
            .iter()
            .map(|t| [t[0], t[1], t[2], geometry.vertices[t[0] as usize].material])
            .collect();
        let count = triangles.len() as u32;
        if triangles.is_empty() {
            triangles.push([0; 4]);
        }
        let vertices = buffer(
            "conservative vertices",
            bytemuck::cast_slice(&vertices),
            wgpu::BufferUsages::STORAGE,
        );
        let triangle_buffer = buffer(
            "conservative triangles",
            bytemuck::cast_slice(&triangles),
            wgpu::BufferUsages::STORAGE,
        );
        let flags_size = 4 * triangles.len() as u64;
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
        let uniform = wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let base = [uniform, storage_entry(1, true), storage_entry(2, true)];
        let erode_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("conservative erode"),
            entries: &base,
        });
        let mut mark_layout_entries = base.to_vec();
        mark_layout_entries.push(wgpu::BindGroupLayoutEntry {
            binding: 3,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: view.samples > 1,
            },
            count: None,
        });
        let mut flags_entry = storage_entry(4, false);
        flags_entry.visibility = wgpu::ShaderStages::FRAGMENT;
        mark_layout_entries.push(flags_entry);
        let mark_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("conservative mark"),
            entries: &mark_layout_entries,
        });
        let texture = |label, format| {
            trisort_gpu::pipeline::texture_2d(
                device,
                label,
                (view.width, view.height),
                view.samples,
                format,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            )
            .create_view(&Default::default())
        };
        let occluder = texture("conservative occluders", OCCLUDER_FORMAT);
        let target = texture("conservative mark target", MARK_FORMAT);
        let base_entries = [
            wgpu::BindGroupEntry {
                binding: 0,
                resource: params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: vertices.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: triangle_buffer.as_entire_binding(),
            },
        ];
        let erode_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("conservative erode"),
            layout: &erode_layout,
            entries: &base_entries,
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
        let pipeline =
            |label, layout: &wgpu::BindGroupLayout, entries: (&str, &str), erode: bool| {
                let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some(label),
                    bind_group_layouts: &[Some(&scene.layout), Some(layout)],
                    immediate_size: 0,
                });
                let mark_target = [Some(wgpu::ColorTargetState {
                    format: MARK_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::empty(),
                })];
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(label),
                    layout: Some(&pl),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some(entries.0),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    primitive: wgpu::PrimitiveState {
                        front_face: wgpu::FrontFace::Ccw,
                        cull_mode: None,
                        ..Default::default()
                    },
                    depth_stencil: erode.then_some(wgpu::DepthStencilState {
                        format: OCCLUDER_FORMAT,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::Less),
                        stencil: Default::default(),
                        bias: Default::default(),
                    }),
                    multisample: wgpu::MultisampleState {
                        count: view.samples,
                        mask: !0,
                        alpha_to_coverage_enabled: false,
                    },
                    fragment: Some(wgpu::FragmentState {
                        module: &module,
                        entry_point: Some(entries.1),
                        compilation_options: Default::default(),
                        targets: if erode { &[] } else { &mark_target },
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            };
        let erode = pipeline(
            "conservative erode",
            &erode_layout,
            ("vs_erode", "fs_erode"),
            true,
        );
        let mark = pipeline(
            "conservative mark",
            &mark_layout,
            ("vs_dilate", "fs_mark"),
            false,
        );
        Ok(Conservative {
            gpu,
            scene,
            erode,
            mark,
            erode_group,
            mark_group,
            occluder,
            target,
            flags,
            staging,
            triangles: count,
        })
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
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("conservative erode"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.occluder,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.erode);
            pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
            pass.set_bind_group(1, &self.erode_group, &[]);
            pass.draw(0..3 * self.triangles, 0..1);
        }
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("conservative mark"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &self.target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Discard,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.mark);
            pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
            pass.set_bind_group(1, &self.mark_group, &[]);
            pass.draw(0..3 * self.triangles, 0..1);
        }
        enc.copy_buffer_to_buffer(&self.flags, 0, &self.staging, 0, self.flags.size());
        self.gpu.queue.submit([enc.finish()]);
        let slice = self.staging.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RecordError::Device(e.to_string()))?;
        let out = {
            let data = slice
                .get_mapped_range()
                .map_err(|e| RecordError::Device(e.to_string()))?;
            let flags: &[u32] = bytemuck::cast_slice(&data);
            flags[..self.triangles as usize]
                .iter()
                .enumerate()
                .filter(|(_, &f)| f != 0)
                .map(|(t, _)| t as u32)
                .collect()
        };
        self.staging.unmap();
        Ok(out)
    }
}
