//! Setting a peeler up: the device check, the peel pipeline (plain or grown), the gather
//! pass and the per-sample targets and buffers.

use trisort_format::{FrameState, Geometry, Robust};
use trisort_gpu::pipeline::{storage_entry, uniform_entry};
use trisort_gpu::scene_gpu::{previous_key_entries, ScenePipeline, View};
use trisort_gpu::Gpu;
use wgpu::util::DeviceExt;

use super::{view_texture, visibility_scene, Peeler, CHUNK_TRIANGLES, DEPTH_FORMAT, ID_FORMAT};
use crate::conservative::{GrowBuffers, PulledStages, PulledTargets};
use crate::RecordError;

/// Rejects a device that cannot peel: no `PRIMITIVE_INDEX`, or no [`ID_FORMAT`] target at the
/// view's sample count.
fn check_device(gpu: &Gpu, view: View) -> Result<(), RecordError> {
    let device = &gpu.device;
    if !device.features().contains(wgpu::Features::PRIMITIVE_INDEX) {
        return Err(RecordError::Unsupported(format!(
            "{} lacks PRIMITIVE_INDEX",
            gpu.describe()
        )));
    }
    let ff = gpu.adapter.get_texture_format_features(ID_FORMAT);
    if !ff.flags.sample_count_supported(view.samples)
        || (view.samples > 1
            && !device
                .features()
                .contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES))
    {
        return Err(RecordError::Unsupported(format!(
            "{} cannot render {ID_FORMAT:?} ids at {}x MSAA",
            gpu.describe(),
            view.samples
        )));
    }
    Ok(())
}

/// The compute pass that gathers a peel layer per sample (ids and depth in; out three arrays
/// of one word a sample, or with `interleaved` one 16-byte slot a sample), and its bind group
/// layout.
fn gather_pipeline(
    device: &wgpu::Device,
    samples: u32,
    interleaved: bool,
) -> (wgpu::BindGroupLayout, wgpu::ComputePipeline) {
    let stages = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
    let tex = |binding, sample_type| {
        trisort_gpu::pipeline::texture_entry(binding, stages, sample_type, samples)
    };
    let gather_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("gather"),
        source: wgpu::ShaderSource::Wgsl(trisort_gpu::gather_shader(samples).into()),
    });
    let gather_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("gather"),
        entries: &[
            tex(0, wgpu::TextureSampleType::Uint),
            tex(1, wgpu::TextureSampleType::Depth),
            storage_entry(2, wgpu::ShaderStages::COMPUTE, false),
            uniform_entry(3, wgpu::ShaderStages::COMPUTE, false, None),
        ],
    });
    let gather_pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("gather"),
        bind_group_layouts: &[Some(&gather_layout)],
        immediate_size: 0,
    });
    let gather_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("gather"),
        layout: Some(&gather_pl),
        module: &gather_module,
        entry_point: Some(if interleaved {
            "gather_interleaved"
        } else {
            "gather"
        }),
        compilation_options: Default::default(),
        cache: None,
    });

    (gather_layout, gather_pipeline)
}

/// The per-sample buffers of the gather pass: which samples are done, the gathered layer, and
/// its readback. Errors where the gathered layer exceeds the device's storage-buffer binding.
fn gather_buffers(
    device: &wgpu::Device,
    view: View,
    interleaved: bool,
) -> Result<(wgpu::Buffer, wgpu::Buffer, wgpu::Buffer), RecordError> {
    let slots = view.width as u64 * view.height as u64 * view.samples as u64;
    let out_size = slots * if interleaved { 16 } else { 12 };
    let max_binding = device.limits().max_storage_buffer_binding_size;
    if out_size > max_binding {
        return Err(RecordError::Unsupported(format!(
            "{}x{} at {}x needs a {out_size}-byte gather buffer; the device binds at most {max_binding}",
            view.width, view.height, view.samples
        )));
    }
    let done = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("done"),
        size: slots * 4,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("gathered"),
        size: out_size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("gathered readback"),
        size: out_size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    Ok((done, out, staging))
}

impl<'g> Peeler<'g> {
    /// Sets up peeling of `triangles` (indices into `geometry.triangles`, ascending: this is
    /// the draw order, and a fragment's id is its position in this list).
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        triangles: &[u32],
        frames: &[FrameState],
        view: View,
    ) -> Result<Self, RecordError> {
        Peeler::build(
            gpu,
            geometry,
            triangles,
            frames,
            view,
            None,
            &Default::default(),
        )
    }

    /// [`Peeler::new`] (`grow` `None`), or with `grow` the peel over the triangles grown by
    /// `robust`'s tolerance in pixels (`peel_grown.wgsl`): each sample's layers list every
    /// triangle that could cover it when the pattern moves within the tolerance, by the depth
    /// of its plane at the sample, with alpha 1; phase 2 of a conservative recording takes the
    /// edges of the triangles it adds from there. Built as `internals` say.
    pub(crate) fn build(
        gpu: &'g Gpu,
        geometry: &Geometry,
        triangles: &[u32],
        frames: &[FrameState],
        view: View,
        grow: Option<&Robust>,
        internals: &crate::Internals,
    ) -> Result<Self, RecordError> {
        let device = &gpu.device;
        check_device(gpu, view)?;
        let scene = visibility_scene(gpu, geometry, frames, view, internals);
        let source = match grow {
            None => trisort_gpu::peel_shader(view.samples),
            Some(_) => trisort_gpu::peel_grown_shader(view.samples),
        };
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("peel"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let previous = previous_key_entries(view.samples);
        let peel_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("peel"),
            entries: &[
                previous[0],
                previous[1],
                previous[2],
                storage_entry(3, wgpu::ShaderStages::FRAGMENT, true),
            ],
        });
        let depth_less = Some((DEPTH_FORMAT, wgpu::CompareFunction::Less, true));
        let (pipeline, grown) = match grow {
            None => (
                ScenePipeline {
                    label: "peel",
                    layouts: &[&scene.layout, &peel_layout],
                    module: &module,
                    vertex: "vs_record",
                    fragment: "fs_peel",
                    target: ID_FORMAT.into(),
                    depth: depth_less,
                    samples: view.samples,
                }
                .build(device),
                None,
            ),
            Some(robust) => {
                let (layout, group) = grown_group(device, geometry, triangles, view, robust);
                let pipeline = crate::conservative::pulled_pipeline(
                    device,
                    "grown peel",
                    &[&scene.layout, &peel_layout, &layout],
                    PulledStages {
                        module: &module,
                        entries: ("vs_grown", "fs_peel_grown"),
                    },
                    PulledTargets {
                        target: Some(ID_FORMAT),
                        depth: depth_less.map(|(f, c, _)| (f, c)),
                        samples: view.samples,
                    },
                );
                (pipeline, Some(group))
            }
        };

        let interleaved = internals.interleaved_readback;
        let (gather_layout, gather_pipeline) = gather_pipeline(device, view.samples, interleaved);

        let index = index_buffer(device, geometry, triangles);
        let target = |label, format| view_texture(device, &view, label, format);
        let (done, out, staging) = gather_buffers(device, view, interleaved)?;
        let chunks = (triangles.len() as u64)
            .div_ceil(CHUNK_TRIANGLES as u64)
            .max(1)
            * 2;
        let params_stride = 256u64.max(device.limits().min_uniform_buffer_offset_alignment as u64);
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("peel params"),
            size: params_stride * chunks,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let dims = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("dims"),
            contents: bytemuck::cast_slice(&[view.width, view.height, view.samples, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let plain = plain_pipeline(device, &scene.layout, view.samples);
        Ok(Peeler {
            plain,
            gpu,
            scene,
            pipeline,
            peel_layout,
            gather_pipeline,
            gather_layout,
            index,
            triangles: triangles.len() as u32,
            depth: [
                target("depth a", DEPTH_FORMAT),
                target("depth b", DEPTH_FORMAT),
            ],
            ids: [target("ids a", ID_FORMAT), target("ids b", ID_FORMAT)],
            done,
            out,
            staging,
            params,
            params_stride,
            dims,
            view,
            grown,
            read_alpha: true,
            read_depth: true,
            interleaved,
        })
    }
}

/// The grown peel's triangle storage (group 2) for `triangles` grown by `robust`'s
/// tolerance, and its layout.
fn grown_group(
    device: &wgpu::Device,
    geometry: &Geometry,
    triangles: &[u32],
    view: View,
    robust: &Robust,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let buffers = GrowBuffers::new(device, geometry, triangles, view, robust);
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("grown peel"),
        entries: &GrowBuffers::layout_entries(),
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("grown peel"),
        layout: &layout,
        entries: &buffers.entries(),
    });
    (layout, group)
}

/// The peel's index buffer: `triangles` in drawn order (one degenerate triangle where there
/// are none: buffers may not be empty).
fn index_buffer(device: &wgpu::Device, geometry: &Geometry, triangles: &[u32]) -> wgpu::Buffer {
    let mut index_data: Vec<u32> = Vec::with_capacity(triangles.len() * 3);
    for &t in triangles {
        index_data.extend_from_slice(&geometry.triangles[t as usize]);
    }
    if index_data.is_empty() {
        index_data.extend_from_slice(&[0, 0, 0]);
    }
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("peel indices"),
        contents: bytemuck::cast_slice(&index_data),
        usage: wgpu::BufferUsages::INDEX,
    })
}

/// A plain pass over the same triangles for benchmarks: the peel's vertex stage and depth
/// test, one colour per pixel.
fn plain_pipeline(
    device: &wgpu::Device,
    scene_layout: &wgpu::BindGroupLayout,
    samples: u32,
) -> wgpu::RenderPipeline {
    let plain_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("plain"),
        source: wgpu::ShaderSource::Wgsl(trisort_gpu::plain_shader().into()),
    });
    ScenePipeline {
        label: "plain",
        layouts: &[scene_layout],
        module: &plain_module,
        vertex: "vs_plain",
        fragment: "fs_plain",
        target: ID_FORMAT.into(),
        depth: Some((DEPTH_FORMAT, wgpu::CompareFunction::Less, true)),
        samples,
    }
    .build(device)
}
