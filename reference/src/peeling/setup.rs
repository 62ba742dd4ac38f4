//! Setting a [`PeelingRenderer`] up: the device check, the peel and compositing pipelines,
//! the ping-ponged layer targets, the per-[`Keep`] parameters and the layer-count query.

use std::sync::Mutex;

use trisort_format::{FrameState, Geometry};
use trisort_gpu::scene_gpu::{previous_key_entries, Lighting, ScenePipeline, View};
use trisort_gpu::Gpu;
use trisort_gpu::{FrameTarget, TargetConfig, COLOR_FORMAT, DEPTH_FORMAT};
use trisort_player::{blend_state, Mode};
use wgpu::util::DeviceExt;

use super::{Keep, PeelingConfig, PeelingRenderer, ID_FORMAT};
use crate::target::{check_pattern, lit_scene, scene_index};
use crate::ReferenceError;

/// The peel passes' parameters: one uniform slot per [`Keep`] (at `keep as usize` times the
/// returned stride), holding the mode `fs_peeling` reads.
fn keep_params(device: &wgpu::Device) -> (wgpu::Buffer, u64) {
    let params_stride = 256u64.max(device.limits().min_uniform_buffer_offset_alignment as u64);
    let mut params = vec![0u8; params_stride as usize * 4];
    for keep in [Keep::All, Keep::Behind, Keep::InFront, Keep::AtOrInFront] {
        let at = keep as usize * params_stride as usize;
        params[at..at + 16].copy_from_slice(bytemuck::cast_slice(&[keep as u32, 0, 0, 0]));
    }
    let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("peeling params"),
        contents: &params,
        usage: wgpu::BufferUsages::UNIFORM,
    });
    (params, params_stride)
}

/// The occlusion query that counts a frame's layers (does a peel pass draw anything?), with
/// its resolve and readback buffers.
fn occlusion_query(device: &wgpu::Device) -> (wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer) {
    let occlusion = device.create_query_set(&wgpu::QuerySetDescriptor {
        label: Some("peeling layer count"),
        ty: wgpu::QueryType::Occlusion,
        count: 1,
    });
    let occlusion_resolve = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("peeling layer count resolve"),
        size: 8,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let occlusion_staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("peeling layer count readback"),
        size: 8,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    (occlusion, occlusion_resolve, occlusion_staging)
}

/// Rejects what the renderer cannot do: a pattern other than 1× or 4×, `saturate`, a device
/// without `PRIMITIVE_INDEX` or one that cannot multisample the id, depth or colour targets.
fn check_device(gpu: &Gpu, config: &PeelingConfig) -> Result<(), ReferenceError> {
    let PeelingConfig {
        size,
        samples,
        mode,
        ..
    } = *config;
    check_pattern(size, samples)?;
    if mode == Mode::Saturate {
        return Err(ReferenceError::Invalid(
            "depth peeling renders blend and depth; saturate has no peeling renderer".into(),
        ));
    }
    let device = &gpu.device;
    if !device.features().contains(wgpu::Features::PRIMITIVE_INDEX) {
        return Err(ReferenceError::Unsupported(format!(
            "{} lacks PRIMITIVE_INDEX (triangle ids in the fragment shader)",
            gpu.describe()
        )));
    }
    for format in [ID_FORMAT, DEPTH_FORMAT, COLOR_FORMAT] {
        let supported = gpu
            .adapter
            .get_texture_format_features(format)
            .flags
            .sample_count_supported(samples);
        let adapter_specific = device
            .features()
            .contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);
        if !supported || (samples > 1 && format == ID_FORMAT && !adapter_specific) {
            return Err(ReferenceError::Unsupported(format!(
                "{} cannot render {format:?} at {samples}x MSAA",
                gpu.describe()
            )));
        }
    }
    Ok(())
}

/// The two ping-ponged peel targets (ids and depth: each pass reads the other's key) and
/// their bind groups.
struct LayerTargets {
    ids: [wgpu::TextureView; 2],
    depth: [wgpu::TextureView; 2],
    /// `peel_groups[p]`: the peel bind group reading target `p` as the previous key.
    peel_groups: [wgpu::BindGroup; 2],
    /// `composite_groups[p]`: the compositing bind group reading target `p`'s ids.
    composite_groups: [wgpu::BindGroup; 2],
}

impl LayerTargets {
    fn new(
        device: &wgpu::Device,
        config: &PeelingConfig,
        peel_layout: &wgpu::BindGroupLayout,
        composite_layout: &wgpu::BindGroupLayout,
        params: &wgpu::Buffer,
    ) -> LayerTargets {
        let (size, samples) = (config.size, config.samples);
        let texture = |label, format, sample_count, usage| {
            trisort_gpu::pipeline::texture_2d(device, label, size, sample_count, format, usage)
        };
        let peel_usage =
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let make_view = |t: wgpu::Texture| t.create_view(&Default::default());
        let ids = [
            make_view(texture("peeling ids a", ID_FORMAT, samples, peel_usage)),
            make_view(texture("peeling ids b", ID_FORMAT, samples, peel_usage)),
        ];
        let depth = [
            make_view(texture(
                "peeling depth a",
                DEPTH_FORMAT,
                samples,
                peel_usage,
            )),
            make_view(texture(
                "peeling depth b",
                DEPTH_FORMAT,
                samples,
                peel_usage,
            )),
        ];
        let peel_group = |p: usize| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("peeling peel"),
                layout: peel_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: params,
                            offset: 0,
                            size: wgpu::BufferSize::new(16),
                        }),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&depth[p]),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(&ids[p]),
                    },
                ],
            })
        };
        let composite_group = |p: usize| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("peeling composite"),
                layout: composite_layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&ids[p]),
                }],
            })
        };
        let peel_groups = [peel_group(0), peel_group(1)];
        let composite_groups = [composite_group(0), composite_group(1)];
        LayerTargets {
            ids,
            depth,
            peel_groups,
            composite_groups,
        }
    }
}

impl<'g> PeelingRenderer<'g> {
    /// Uploads `geometry` with the path's `frames` for rendering as `config` says, lit as
    /// `lighting` says.
    ///
    /// Errors: [`ReferenceError::Invalid`] for `Saturate`, an empty size or another sample
    /// count than 1 or 4; [`ReferenceError::Unsupported`] where the device lacks
    /// `PRIMITIVE_INDEX` or cannot multisample the id, depth or colour targets at the sample
    /// count.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        lighting: Lighting<'_>,
        config: PeelingConfig,
    ) -> Result<Self, ReferenceError> {
        let PeelingConfig {
            size,
            samples,
            mode,
            max_layers,
            glass_opacity,
        } = config;
        check_device(gpu, &config)?;
        let device = &gpu.device;
        let triangles = u32::try_from(geometry.triangles.len())
            .map_err(|_| ReferenceError::Invalid("more than 2^32 triangles".into()))?;
        let view = View {
            width: size.0,
            height: size.1,
            samples,
            glass_opacity,
        };
        let shading = lighting.shading;
        let scene = lit_scene(gpu, geometry, frames, view, lighting);
        let index = scene_index(device, geometry, "peeling indices");

        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("peeling"),
            source: wgpu::ShaderSource::Wgsl(trisort_gpu::peeling_shader(samples).into()),
        });
        let peel_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("peeling peel"),
            entries: &previous_key_entries(samples),
        });
        let composite_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("peeling composite"),
            entries: &[trisort_gpu::pipeline::texture_entry(
                3,
                wgpu::ShaderStages::FRAGMENT,
                wgpu::TextureSampleType::Uint,
                samples,
            )],
        });
        let peel_pipeline = |label, compare| {
            ScenePipeline {
                label,
                layouts: &[&scene.layout, &peel_layout],
                module: &module,
                vertex: "vs_player",
                fragment: "fs_peeling",
                target: ID_FORMAT.into(),
                depth: Some((DEPTH_FORMAT, compare, true)),
                samples,
            }
            .build_shaded(device, shading)
        };
        let front = peel_pipeline("peeling front to back", wgpu::CompareFunction::Less);
        let back = peel_pipeline("peeling back to front", wgpu::CompareFunction::GreaterEqual);
        // The player's pipeline state and blend with the masked compositing entry point, as
        // the exact reference's compositing pipeline.
        let composite = ScenePipeline {
            label: "peeling composite",
            layouts: &[&scene.layout, &composite_layout],
            module: &module,
            vertex: "vs_player",
            fragment: "fs_peeling_composite",
            target: wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                blend: Some(blend_state(mode)),
                write_mask: wgpu::ColorWrites::ALL,
            },
            depth: None,
            samples,
        }
        .build_shaded(device, shading);

        let (params, params_stride) = keep_params(device);
        let layers = LayerTargets::new(device, &config, &peel_layout, &composite_layout, &params);
        let target = FrameTarget::new(
            &gpu.adapter,
            device,
            TargetConfig::readback(size, samples, Mode::Blend),
        )?;
        let (occlusion, occlusion_resolve, occlusion_staging) = occlusion_query(device);
        Ok(PeelingRenderer {
            gpu,
            samples,
            mode,
            max_layers,
            triangles,
            scene,
            index,
            front,
            back,
            composite,
            params_stride,
            peel_groups: layers.peel_groups,
            composite_groups: layers.composite_groups,
            ids: layers.ids,
            depth: layers.depth,
            target,
            occlusion,
            occlusion_resolve,
            occlusion_staging,
            counted: Mutex::new(vec![None; frames.len()]),
        })
    }
}
