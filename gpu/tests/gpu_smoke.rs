//! GPU smoke test: a device on the default adapter (lavapipe in CI) renders one triangle
//! through the shared vertex transform and scene bindings, and the pixels read back.

use glam::{DMat4, DVec3};
use trisort_format::{Camera, FrameState, Geometry, Material, Node, Vertex};
use trisort_gpu::scene_gpu::{vertex_layout, SceneGpu, View};
use trisort_testkit::gpu;

fn vertex(x: f32, y: f32) -> Vertex {
    Vertex {
        position: [x, y, 0.0],
        normal: [0.0, 0.0, 1.0],
        uv: [0.0; 2],
        material: 0,
        node: 0,
        tangent: [0.0; 4],
        uv1: [0.0; 2],
    }
}

/// One red triangle over the left half of the view, and a camera that frames y ∈ [-1, 1].
fn left_half_triangle() -> (Geometry, FrameState) {
    let geometry = Geometry {
        // Covers the left half of the view; the right half stays clear.
        vertices: vec![vertex(-1.0, -1.0), vertex(0.0, -1.0), vertex(-1.0, 1.0)],
        triangles: vec![[0, 1, 2]],
        materials: vec![Material {
            base_color: [1.0, 0.0, 0.0, 1.0],
            ..Default::default()
        }],
        textures: vec![],
        nodes: vec![Node {
            name: "n".into(),
            parent: None,
            rest: DMat4::IDENTITY.to_cols_array(),
        }],
        variants: vec![],
    };
    // Orthographic-like framing: camera 2 units back, fov chosen so y ∈ [-1, 1] fills the view.
    let fov = 2.0 * (0.5f64).atan();
    let view = DMat4::look_at_rh(DVec3::new(0.0, 0.0, 2.0), DVec3::ZERO, DVec3::Y);
    let frame = FrameState {
        camera: Camera {
            view: view.to_cols_array(),
            yfov: fov,
            znear: 0.1,
            zfar: Some(10.0),
        },
        poses: vec![],
    };
    (geometry, frame)
}

/// The smoke pipeline: the plain vertex stage and `fs_smoke`, over `scene`'s group 0, into
/// `format` without depth.
fn smoke_pipeline(
    device: &wgpu::Device,
    scene: &SceneGpu,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    let source = trisort_gpu::smoke_shader();
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("smoke"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[Some(&scene.layout)],
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("smoke"),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_plain"),
            compilation_options: Default::default(),
            buffers: &[Some(vertex_layout())],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_smoke"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

#[test]
fn one_triangle_renders_and_reads_back() {
    let Some(gpu) = gpu() else { return };
    eprintln!("adapter: {}", gpu.describe());
    let (geometry, frame) = left_half_triangle();
    let size = 16;
    let v = View {
        width: size,
        height: size,
        samples: 1,
        glass_opacity: 0.0,
    };
    let scene = SceneGpu::new(&gpu.device, &gpu.queue, &geometry, &[frame], v);
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let pipeline = smoke_pipeline(&gpu.device, &scene, format);
    let target = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("target"),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let tv = target.create_view(&Default::default());
    let index = wgpu::util::DeviceExt::create_buffer_init(
        &gpu.device,
        &wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(&[0u32, 1, 2]),
            usage: wgpu::BufferUsages::INDEX,
        },
    );
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &tv,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &scene.bind_group, &scene.offsets(0));
        pass.set_vertex_buffer(0, scene.vertices.slice(..));
        pass.set_index_buffer(index.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..3, 0, 0..1);
    }
    gpu.queue.submit([enc.finish()]);
    let px = gpu.read_texture_4bpp(&target);
    let at = |x: u32, y: u32| &px[((y * size + x) * 4) as usize..][..4];
    assert_eq!(at(1, 8), &[255, 0, 0, 255], "inside the triangle");
    assert_eq!(at(14, 8), &[0, 0, 0, 255], "outside the triangle");
    let red = px.chunks(4).filter(|p| p[0] == 255).count();
    assert!(
        (56..=72).contains(&red),
        "the triangle covers a quarter of the view (64 of 256 pixels), got {red}"
    );
}
