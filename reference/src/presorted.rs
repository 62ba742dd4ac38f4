//! The depth-presorted renderer (paper 000): plays a [`Presorted`] file from any camera outside
//! its polyhedron, for `play`, `verify` and `bench`.
//!
//! Per frame, the CPU picks the camera's partition (trivial) and the GPU selects the copies
//! whose half-space tests the camera passes ([`TestStage`]): in the fragment stage by default
//! (`fs_presorted_*` in `shaders/reference/presorted.wgsl`, the variant paper 000 favours for
//! models of more than a few thousand triangles), or in the vertex stage (`vs_presorted`, the
//! list drawn from three vertices a copy; BENCHMARKS § Free viewpoints compares them). Passes, into the player's `Rgba16Float` MSAA target with a
//! depth buffer, resolved and quantized once like the player's frames:
//!
//! - `blend`: the opaque triangles (ascending ids, depth test and writes), then the partition's
//!   segment in one draw, back to front (depth test, no writes), straight-alpha `over`.
//! - `depth`: the segment front to back, then the opaque triangles, both with depth test and
//!   writes: each sample shows its nearest fragment over the background.
//! - `saturate`: the opaque triangles' depth alone, then the segment front to back (depth test,
//!   no writes), then the opaque colours (`LessEqual`), premultiplied and composited under.

use trisort_format::{FrameState, Mode, Presorted};
use trisort_gpu::pipeline::{storage_entry, uniform_entry};
use trisort_gpu::scene_gpu::{Lighting, SceneGpu, ScenePipeline, View};
use trisort_gpu::Gpu;
use trisort_gpu::{clear_colour, halves, quantize_rgba16f, BACKGROUND, COLOR_FORMAT};
use trisort_player::blend_state;
use wgpu::util::DeviceExt;

use crate::target::{lit_scene, Target, DEPTH_FORMAT};
use crate::ReferenceError;

/// The camera of every frame checked against a presorted file: outside the polyhedron, within
/// its reach, no node moved from its rest pose (the lists are for the static scene). Returns
/// each frame's partition, or an error naming the first frame that cannot be drawn.
pub fn partitions_of(
    file: &Presorted,
    frames: &[FrameState],
) -> Result<Vec<usize>, ReferenceError> {
    frames
        .iter()
        .enumerate()
        .map(|(f, s)| {
            if let Some(p) = s.poses.first() {
                return Err(ReferenceError::Invalid(format!(
                    "frame {f}: the path moves node {} from its rest pose; a presorted file \
                     holds the scene at rest",
                    p.node
                )));
            }
            let eye = s.camera.eye();
            file.polyhedron.partition_of(eye.to_array()).map_err(|e| {
                ReferenceError::Invalid(format!(
                    "frame {f}: {e} (camera at {:.3}, {:.3}, {:.3}; presorted files play from \
                     outside their bounding polyhedron, within {:.3} of its centre per axis)",
                    eye.x, eye.y, eye.z, file.polyhedron.reach
                ))
            })
        })
        .collect()
}

/// Where the half-space test selects a partition's copies (paper 000 measures both).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestStage {
    /// Per fragment: the list in one indexed draw, a fragment's copy by `primitive_index`
    /// (the default: paper 000 finds it faster above a few thousand triangles).
    Fragment,
    /// Per vertex: the list drawn from three vertices a copy, a failing copy clipped away.
    Vertex,
}

/// Renders a presorted file's frames.
pub struct PresortedRenderer<'g> {
    gpu: &'g Gpu,
    mode: Mode,
    scene: SceneGpu,
    /// Per frame: partition and camera relative to the centre.
    frames: Vec<(usize, [f32; 3])>,
    /// Per partition: (first copy, copies) in this renderer's drawing order.
    segments: Vec<(u32, u32)>,
    opaque: (wgpu::Buffer, u32),
    sorted: wgpu::Buffer,
    /// Bytes between frames' uniform slots.
    stride: u32,
    /// Every frame's camera and segment.
    params: wgpu::Buffer,
    /// The file's polyhedron (a free camera's partition).
    polyhedron: trisort_format::Polyhedron,
    bind_group: wgpu::BindGroup,
    /// (pipeline, what it draws: false opaque, true the segment), in order.
    passes: Vec<(wgpu::RenderPipeline, bool)>,
    /// The vertex-stage variant's list: three vertices a copy, in drawing order.
    expanded: Option<wgpu::Buffer>,
    target: Target,
}

impl<'g> PresortedRenderer<'g> {
    /// Uploads `file` for the camera path `frames` at `view` in `mode`, lit as `lighting` says,
    /// testing in the fragment stage. Errors naming the frame where a camera is inside the
    /// polyhedron or beyond its reach, or a frame moves a node; or where the device lacks
    /// `PRIMITIVE_INDEX`.
    pub fn new(
        gpu: &'g Gpu,
        file: &Presorted,
        frames: &[FrameState],
        view: View,
        lighting: Lighting<'_>,
        mode: Mode,
    ) -> Result<PresortedRenderer<'g>, ReferenceError> {
        Self::with_stage(gpu, file, frames, view, lighting, mode, TestStage::Fragment)
    }

    /// [`PresortedRenderer::new`] with the half-space test in `stage`.
    pub fn with_stage(
        gpu: &'g Gpu,
        file: &Presorted,
        frames: &[FrameState],
        view: View,
        lighting: Lighting<'_>,
        mode: Mode,
        stage: TestStage,
    ) -> Result<PresortedRenderer<'g>, ReferenceError> {
        check_device(gpu)?;
        let partitions = partitions_of(file, frames)?;
        let frame_eyes: Vec<(usize, [f32; 3])> = partitions
            .iter()
            .zip(frames)
            .map(|(&k, s)| (k, relative_eye(file.polyhedron.centre, s)))
            .collect();
        let device = &gpu.device;
        let target = Target::new(
            gpu,
            (view.width, view.height),
            view.samples,
            COLOR_FORMAT,
            true,
        )?;
        let shading = lighting.shading;
        let scene = lit_scene(gpu, &file.geometry, frames, view, lighting);
        // Back to front in blend, front to back otherwise.
        let order = DrawingOrder::of(file, mode != Mode::Blend);
        let buffer = |label: &str, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let sorted = buffer(
            "presorted copies",
            bytemuck::cast_slice(&order.index),
            wgpu::BufferUsages::INDEX,
        );
        let mut tests: Vec<u32> = file.tests.iter().map(|t| t.packed()).collect();
        tests.push(0);
        let mut planes = file.planes.clone();
        planes.push([0.0; 4]);
        // Every frame's camera and segment, one uniform slot each (a dynamic offset picks the
        // frame, so frames can be encoded back to back without a write between them).
        let stride = device.limits().min_uniform_buffer_offset_alignment.max(32) as usize;
        let mut slots = vec![0u8; stride * frames.len().max(1)];
        for (f, (k, eye)) in frame_eyes.iter().enumerate() {
            slots[f * stride..f * stride + 32].copy_from_slice(&slot(*eye, order.segments[*k].0));
        }
        let params = buffer(
            "presorted params",
            &slots,
            // COPY_DST: a free camera rewrites its slot (`set_camera`).
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        // Read by the stage that tests: the vertex or the fragment stage.
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("presorted"),
            entries: &[
                uniform_entry(0, stages, true, Some(32)),
                storage_entry(1, stages, true),
                storage_entry(2, stages, true),
                storage_entry(3, stages, true),
            ],
        });
        let copy_tests = buffer(
            "presorted copy tests",
            bytemuck::cast_slice(&order.copy_tests),
            storage,
        );
        let tests = buffer("presorted tests", bytemuck::cast_slice(&tests), storage);
        let planes = buffer("presorted planes", bytemuck::cast_slice(&planes), storage);
        let bind_group = trisort_gpu::pipeline::bind_group(
            device,
            "presorted",
            &layout,
            &[
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &params,
                    offset: 0,
                    size: wgpu::BufferSize::new(32),
                }),
                copy_tests.as_entire_binding(),
                tests.as_entire_binding(),
                planes.as_entire_binding(),
            ],
        );
        let passes = passes(
            device,
            &[&scene.layout, &layout],
            mode,
            view.samples,
            shading,
            stage,
        );
        let expanded = (stage == TestStage::Vertex).then(|| order.vertices(device, file));
        let mut opaque: Vec<u32> = file
            .opaque
            .iter()
            .flat_map(|&t| file.geometry.triangles[t as usize])
            .collect();
        let opaque_count = opaque.len() as u32;
        opaque.extend_from_slice(&[0, 0, 0]);
        let opaque = (
            buffer(
                "presorted opaque",
                bytemuck::cast_slice(&opaque),
                wgpu::BufferUsages::INDEX,
            ),
            opaque_count,
        );
        Ok(PresortedRenderer {
            gpu,
            mode,
            scene,
            frames: frame_eyes,
            segments: order.segments,
            opaque,
            sorted,
            stride: stride as u32,
            params,
            polyhedron: file.polyhedron.clone(),
            bind_group,
            passes,
            expanded,
            target,
        })
    }

    /// Moves frame slot `frame` to the camera of `state` (a free camera: the window's orbit),
    /// `geometry` being the file's scene. Errors, leaving the slot as it was, where the camera
    /// is inside the polyhedron or beyond its reach or `state` moves a node.
    pub fn set_camera(
        &mut self,
        geometry: &trisort_format::Geometry,
        frame: u32,
        state: &FrameState,
    ) -> Result<usize, ReferenceError> {
        if frame as usize >= self.frames.len() {
            return Err(ReferenceError::Invalid(format!(
                "frame {frame} is beyond the path"
            )));
        }
        if !state.poses.is_empty() {
            return Err(ReferenceError::Invalid(
                "a presorted file holds the scene at rest: no node may move".into(),
            ));
        }
        let e = state.camera.eye();
        let k = self
            .polyhedron
            .partition_of(e.to_array())
            .map_err(|why| ReferenceError::Invalid(why.to_string()))?;
        let eye = relative_eye(self.polyhedron.centre, state);
        if !self
            .scene
            .set_frame(&self.gpu.queue, geometry, frame, state)
        {
            return Err(ReferenceError::Unsupported(
                "the scene's frames cannot be rewritten on this binding tier".into(),
            ));
        }
        self.gpu.queue.write_buffer(
            &self.params,
            frame as u64 * self.stride as u64,
            &slot(eye, self.segments[k].0),
        );
        self.frames[frame as usize] = (k, eye);
        Ok(k)
    }

    /// Frame `frame`'s partition.
    pub fn partition(&self, frame: u32) -> Option<usize> {
        self.frames.get(frame as usize).map(|f| f.0)
    }

    /// Triangles submitted for frame `frame` (the opaque ones and the partition's copies; the
    /// copies that fail their tests are discarded per fragment).
    pub fn triangles(&self, frame: u32) -> u32 {
        // (Frames beyond the path count the opaque triangles alone.)
        let Some(&(k, _)) = self.frames.get(frame as usize) else {
            return self.opaque.1 / 3;
        };
        self.opaque.1 / 3 + self.segments[k].1
    }

    /// Draw calls of a frame (the opaque pass or passes, the list).
    pub fn draws(&self) -> u32 {
        self.passes.len() as u32
    }

    /// Records frame `frame` into `pass` (attachments as the view: `Rgba16Float` colour and
    /// `Depth32Float` depth at its sample count).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, frame: u32) {
        let (k, _) = self.frames[frame as usize];
        let (first, count) = self.segments[k];
        pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
        pass.set_bind_group(1, &self.bind_group, &[frame * self.stride]);
        for (pipeline, list) in &self.passes {
            pass.set_pipeline(pipeline);
            if *list {
                if count == 0 {
                    continue;
                }
                if let Some(expanded) = &self.expanded {
                    pass.set_vertex_buffer(0, expanded.slice(..));
                    pass.draw(first * 3..(first + count) * 3, 0..1);
                    continue;
                }
                pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
                pass.set_index_buffer(self.sorted.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(first * 3..(first + count) * 3, 0, 0..1);
            } else {
                if self.opaque.1 == 0 {
                    continue;
                }
                pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
                pass.set_index_buffer(self.opaque.0.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..self.opaque.1, 0, 0..1);
            }
        }
    }

    /// Renders frame `frame` over the player's background as 8-bit sRGB RGBA (quantized once,
    /// like the player's frames).
    pub fn render(&self, frame: u32) -> Result<Vec<u8>, ReferenceError> {
        if frame as usize >= self.frames.len() {
            return Err(ReferenceError::Invalid(format!(
                "frame {frame} is beyond the path"
            )));
        }
        let bytes = self
            .target
            .render(self.gpu, clear_colour(self.mode), |pass| {
                self.draw(pass, frame);
                Ok(())
            })?;
        let under = (self.mode == Mode::Saturate).then_some(BACKGROUND);
        Ok(quantize_rgba16f(&halves(&bytes), under))
    }
}

/// The camera of `state` relative to the polyhedron's centre `c`, as the shader tests it.
fn relative_eye(c: [f64; 3], state: &FrameState) -> [f32; 3] {
    let e = state.camera.eye();
    [0, 1, 2].map(|a| (e[a] - c[a]) as f32)
}

/// One frame's uniform slot (`PresortParams`): the camera relative to the centre and the
/// drawn segment's first copy.
fn slot(eye: [f32; 3], first: u32) -> [u8; 32] {
    let mut bytes = [0u8; 32];
    bytes[..12].copy_from_slice(bytemuck::cast_slice(&eye));
    bytes[16..20].copy_from_slice(&first.to_le_bytes());
    bytes
}

/// The copies in the order a renderer draws them, segment by segment.
struct DrawingOrder {
    /// Vertex indices, three a copy (and one degenerate triangle: no empty buffers).
    index: Vec<u32>,
    /// Per copy: its first test and test count (and one entry more).
    copy_tests: Vec<[u32; 2]>,
    /// Per partition: (first copy, copies) in this order.
    segments: Vec<(u32, u32)>,
}

impl DrawingOrder {
    /// The vertex stage's list: three vertices a copy, in this order.
    fn vertices(&self, device: &wgpu::Device, file: &Presorted) -> wgpu::Buffer {
        let vertices: Vec<trisort_format::Vertex> = self
            .index
            .iter()
            .map(|&v| file.geometry.vertices[v as usize])
            .collect();
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("presorted copies' vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        })
    }

    /// `file`'s copies, each segment back to front, or front to back when `reverse`.
    fn of(file: &Presorted, reverse: bool) -> DrawingOrder {
        let mut order: Vec<u32> = Vec::with_capacity(file.copies.len());
        let mut segments = Vec::with_capacity(file.segments.len());
        for s in &file.segments {
            segments.push((order.len() as u32, s.count));
            let run = s.first..s.first + s.count;
            if reverse {
                order.extend(run.rev());
            } else {
                order.extend(run);
            }
        }
        let mut index: Vec<u32> = Vec::with_capacity(order.len() * 3 + 3);
        let mut copy_tests: Vec<[u32; 2]> = Vec::with_capacity(order.len() + 1);
        for &k in &order {
            let copy = &file.copies[k as usize];
            index.extend_from_slice(&file.geometry.triangles[copy.triangle as usize]);
            copy_tests.push([copy.first_test, copy.tests]);
        }
        index.extend_from_slice(&[0, 0, 0]);
        copy_tests.push([0, 0]);
        DrawingOrder {
            index,
            copy_tests,
            segments,
        }
    }
}

/// The passes of `mode`, each a pipeline and whether it draws the list (else the opaque
/// triangles), in order (see the module documentation).
fn passes(
    device: &wgpu::Device,
    layouts: &[&wgpu::BindGroupLayout],
    mode: Mode,
    samples: u32,
    shading: trisort_gpu::Shading,
    stage: TestStage,
) -> Vec<(wgpu::RenderPipeline, bool)> {
    use wgpu::CompareFunction::{Less, LessEqual};
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("presorted"),
        source: wgpu::ShaderSource::Wgsl(trisort_gpu::presorted_shader().into()),
    });
    let (player_fs, presorted_fs) = match mode {
        Mode::Saturate => ("fs_player_premultiplied", "fs_presorted_premultiplied"),
        Mode::Blend | Mode::Depth => ("fs_player_straight", "fs_presorted_straight"),
    };
    let pipeline = |list: bool, depth: (wgpu::CompareFunction, bool), colour: bool| {
        let p = ScenePipeline {
            label: if list {
                "presorted list"
            } else {
                "presorted opaque"
            },
            layouts,
            module: &module,
            vertex: if list && stage == TestStage::Vertex {
                "vs_presorted"
            } else {
                "vs_player"
            },
            fragment: if list && stage == TestStage::Fragment {
                presorted_fs
            } else {
                player_fs
            },
            target: wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                blend: Some(blend_state(mode)),
                write_mask: if colour {
                    wgpu::ColorWrites::ALL
                } else {
                    wgpu::ColorWrites::empty()
                },
            },
            depth: Some((DEPTH_FORMAT, depth.0, depth.1)),
            samples,
        }
        .build_shaded(device, shading);
        (p, list)
    };
    match mode {
        Mode::Blend => vec![
            pipeline(false, (Less, true), true),
            pipeline(true, (Less, false), true),
        ],
        Mode::Depth => vec![
            pipeline(true, (Less, true), true),
            pipeline(false, (Less, true), true),
        ],
        // The opaque depth alone, the list under nothing, the opaque colours under the list.
        Mode::Saturate => vec![
            pipeline(false, (Less, true), false),
            pipeline(true, (Less, false), true),
            pipeline(false, (LessEqual, false), true),
        ],
    }
}

/// Errors where the device lacks `PRIMITIVE_INDEX` (the test finds a fragment's copy by it).
fn check_device(gpu: &Gpu) -> Result<(), ReferenceError> {
    if gpu
        .device
        .features()
        .contains(wgpu::Features::PRIMITIVE_INDEX)
    {
        return Ok(());
    }
    Err(ReferenceError::Unsupported(format!(
        "{}: the presorted renderer selects copies by primitive index",
        gpu.describe()
    )))
}
