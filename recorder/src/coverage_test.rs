//! Coverage test: the ids the recorder peels at each 4× sample equal those of an independent
//! render through the player's vertex stage and primitive state (depth test `Less`, ascending
//! draw order, no per-sample shading), on a scene made for edge cases: vertices on sample
//! positions (so edges run through them), fans of triangles sharing edges, and sub-pixel
//! triangles.

use glam::{DMat4, DVec3};
use trisort_format::{Camera, FrameState, Geometry, Material, Node, Vertex};
use trisort_gpu::scene_gpu::{SceneGpu, ScenePipeline, View};
use trisort_gpu::Gpu;
use trisort_testkit::gpu;

use crate::peeler::Peeler;

const SIZE: u32 = 16;
/// Standard 4× sample positions inside a pixel.
const SAMPLES: [(f32, f32); 4] = [
    (0.375, 0.125),
    (0.875, 0.375),
    (0.125, 0.625),
    (0.625, 0.875),
];

/// Pixel coordinates (x right, y down) → world position on the plane z = −1 seen by
/// `frame()` (fov with tan(fov/2) = 1, aspect 1: x_world = ndc_x).
fn at(px: f32, py: f32, z: f32) -> [f32; 3] {
    let ndc_x = px / SIZE as f32 * 2.0 - 1.0;
    let ndc_y = 1.0 - py / SIZE as f32 * 2.0;
    [ndc_x * -z, ndc_y * -z, z]
}

fn edge_case_scene() -> Geometry {
    let mut g = Geometry {
        materials: vec![Material {
            double_sided: true,
            ..Default::default()
        }],
        nodes: vec![Node {
            name: "root".into(),
            parent: None,
            rest: DMat4::IDENTITY.to_cols_array(),
        }],
        ..Default::default()
    };
    let tri = |g: &mut Geometry, a: [f32; 3], b: [f32; 3], c: [f32; 3]| {
        let base = g.vertices.len() as u32;
        for p in [a, b, c] {
            g.vertices.push(Vertex {
                position: p,
                normal: [0.0, 0.0, 1.0],
                uv: [0.0; 2],
                material: 0,
                node: 0,
                tangent: [0.0; 4],
                uv1: [0.0; 2],
            });
        }
        g.triangles.push([base, base + 1, base + 2]);
    };
    // Background behind everything.
    tri(
        &mut g,
        at(-1.0, -1.0, -3.0),
        at(40.0, -1.0, -3.0),
        at(-1.0, 40.0, -3.0),
    );
    // A grid whose vertices sit on sample positions: every edge passes through samples, and
    // neighbouring triangles share edges (each sample must belong to exactly one of them).
    for gy in 0..6 {
        for gx in 0..6 {
            let (sx, sy) = SAMPLES[(gx + gy) % 4];
            let p = |dx: usize, dy: usize| {
                at(
                    (gx + dx) as f32 * 1.5 + sx,
                    (gy + dy) as f32 * 1.5 + sy,
                    -1.0,
                )
            };
            tri(&mut g, p(0, 0), p(1, 0), p(1, 1));
            tri(&mut g, p(0, 0), p(1, 1), p(0, 1));
        }
    }
    // A fan around a vertex on a sample position.
    let centre = (11.0 + SAMPLES[1].0, 4.0 + SAMPLES[1].1);
    for k in 0..12 {
        let a0 = k as f32 / 12.0 * std::f32::consts::TAU;
        let a1 = (k + 1) as f32 / 12.0 * std::f32::consts::TAU;
        tri(
            &mut g,
            at(centre.0, centre.1, -1.5),
            at(centre.0 + 3.0 * a0.cos(), centre.1 + 3.0 * a0.sin(), -1.5),
            at(centre.0 + 3.0 * a1.cos(), centre.1 + 3.0 * a1.sin(), -1.5),
        );
    }
    // Sub-pixel triangles: even ones straddle a sample position, odd ones sit around the
    // pixel centre, which no 4× sample is near.
    for k in 0..40 {
        let (px, py) = ((k % 8) as f32 * 2.0, 10.0 + (k / 8) as f32);
        let (cx, cy) = if k % 2 == 0 {
            SAMPLES[k % 4]
        } else {
            (0.5, 0.5)
        };
        let s = 0.04 + 0.01 * (k % 5) as f32;
        let (x, y) = (px + cx, py + cy);
        tri(
            &mut g,
            at(x - s, y + s, -0.8),
            at(x + s, y + s, -0.8),
            at(x, y - s, -0.8),
        );
    }
    g
}

fn frame() -> FrameState {
    let view = DMat4::look_at_rh(DVec3::ZERO, -DVec3::Z, DVec3::Y);
    FrameState {
        camera: Camera {
            view: view.to_cols_array(),
            yfov: std::f64::consts::FRAC_PI_2,
            znear: 0.1,
            zfar: Some(10.0),
        },
        poses: vec![],
    }
}

/// Ids per sample (id + 1, 0 for none) from a plain depth-tested render through the player's
/// vertex stage.
fn independent_render(gpu: &Gpu, g: &Geometry, frames: &[FrameState], view: View) -> Vec<u32> {
    let device = &gpu.device;
    let scene = SceneGpu::new(device, &gpu.queue, g, frames, view);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("coverage"),
        source: wgpu::ShaderSource::Wgsl(trisort_gpu::coverage_shader().into()),
    });
    let pipeline = ScenePipeline {
        label: "coverage",
        layouts: &[&scene.layout],
        module: &module,
        vertex: "vs_player",
        fragment: "fs_coverage",
        target: wgpu::TextureFormat::Rg32Uint.into(),
        depth: Some((
            wgpu::TextureFormat::Depth32Float,
            wgpu::CompareFunction::Less,
            true,
        )),
        samples: 4,
    }
    .build(device);
    let tex = |format| {
        trisort_gpu::pipeline::texture_2d(
            device,
            "coverage",
            (SIZE, SIZE),
            4,
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        )
    };
    let ids = tex(wgpu::TextureFormat::Rg32Uint);
    let depth = tex(wgpu::TextureFormat::Depth32Float);
    let (idv, dv) = (
        ids.create_view(&Default::default()),
        depth.create_view(&Default::default()),
    );
    let indices: Vec<u32> = g.triangles.iter().flatten().copied().collect();
    let index = wgpu::util::DeviceExt::create_buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX,
        },
    );
    // Gather with the recorder's own compute shader.
    let gather = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("gather"),
        source: wgpu::ShaderSource::Wgsl(trisort_gpu::gather_shader(4).into()),
    });
    let gather_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &gather,
        entry_point: Some("gather"),
        compilation_options: Default::default(),
        cache: None,
    });
    let slots = (SIZE * SIZE * 4) as u64;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        // Three arrays of one word a sample: ids, alpha, depth (gather.wgsl).
        size: slots * 12,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let dims = wgpu::util::DeviceExt::create_buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(&[SIZE, SIZE, 4, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        },
    );
    let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &gather_pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&idv),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&dv),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: out.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: dims.as_entire_binding(),
            },
        ],
    });
    let mut enc = device.create_command_encoder(&Default::default());
    {
        // The recorder's own pass set-up: ids cleared to 0, depth to 1, both stored.
        let mut pass =
            trisort_gpu::scene_gpu::begin_peel_pass(&mut enc, "coverage", &idv, &dv, 1.0, None);
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &scene.bind_group, &scene.offsets(0));
        pass.set_vertex_buffer(0, scene.vertices.slice(..));
        pass.set_index_buffer(index.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..indices.len() as u32, 0, 0..1);
    }
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&gather_pipeline);
        pass.set_bind_group(0, &bg, &[]);
        pass.dispatch_workgroups(SIZE.div_ceil(8), SIZE.div_ceil(8), 1);
    }
    gpu.queue.submit([enc.finish()]);
    // The ids are the first array.
    let bytes = gpu.read_buffer(&out, 0, slots * 4);
    bytemuck::cast_slice(&bytes).to_vec()
}

#[test]
fn recorded_samples_equal_an_independent_render_through_the_player_state() {
    let Some(gpu) = gpu() else { return };
    let g = edge_case_scene();
    let frames = [frame()];
    let view = View {
        width: SIZE,
        height: SIZE,
        samples: 4,
        glass_opacity: 0.0,
    };
    let all: Vec<u32> = (0..g.triangles.len() as u32).collect();
    let peeler = Peeler::new(&gpu, &g, &all, &frames, view).unwrap();
    let mut recorded = vec![];
    peeler
        .peel(0, 1, |_, layer, _| {
            recorded = layer.ids.clone();
            Ok(false)
        })
        .unwrap();
    let independent = independent_render(&gpu, &g, &frames, view);
    assert_eq!(recorded.len(), independent.len());
    let differing: Vec<usize> = (0..recorded.len())
        .filter(|&i| recorded[i] != independent[i])
        .collect();
    assert!(
        differing.is_empty(),
        "{} of {} samples differ, first at slot {:?}",
        differing.len(),
        recorded.len(),
        differing.first()
    );
    // The scene does exercise the cases: many distinct triangles own samples, some samples
    // of sub-pixel triangles are covered, and each pixel's samples are not all alike.
    let distinct: std::collections::BTreeSet<u32> = recorded.iter().copied().collect();
    assert!(
        distinct.len() > 60,
        "only {} triangles own samples",
        distinct.len()
    );
    // Sub-pixel triangles are scene ids 85..125 (ids + 1 in the samples): the even ones hold
    // exactly one sample each, the odd ones none.
    let first_sub_pixel = 1 + 72 + 12;
    for k in 0..40u32 {
        let n = recorded
            .iter()
            .filter(|&&id| id == first_sub_pixel + k + 1)
            .count();
        assert_eq!(
            n,
            if k % 2 == 0 { 1 } else { 0 },
            "sub-pixel triangle {k} covers {n} samples"
        );
    }
    let mixed = recorded
        .chunks_exact(4)
        .filter(|p| p.iter().any(|&x| x != p[0]))
        .count();
    assert!(mixed > 30, "only {mixed} pixels with differing samples");
}
