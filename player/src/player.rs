//! [`Player`]: uploads a baked file once and draws a frame with one multi-draw-indirect call.

use std::ops::Range;
use std::path::Path;

use trisort_format::{Baked, Clip, DrawIndexedIndirectArgs, FileKind, FrameWindow, Material};
use trisort_gpu::scene_gpu::budget::sized_buffer;
use trisort_gpu::scene_gpu::{
    ArrayUpload, Bindings, GpuBytes, GpuKind, SceneGpu, SceneOptions, ScenePipeline, View,
};

use crate::budget::GpuBudget;

use crate::commands::{frame_commands, index_buffer, Order};
use crate::config::{playback_warnings, DrawPath, PlayerConfig};
use crate::draw_calls::DrawCalls;
use crate::error::PlayerError;
use trisort_format::Mode;

/// Size in bytes of one `DrawIndexedIndirectArgs`.
const ARGS_SIZE: u64 = std::mem::size_of::<DrawIndexedIndirectArgs>() as u64;

/// Reads a baked file and checks its structure, so that every draw lies inside its index
/// buffer. Errors name the file.
pub fn open_baked(path: &Path) -> Result<Baked, PlayerError> {
    let bytes = std::fs::read(path).map_err(|source| trisort_format::FormatError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    baked_from_bytes(&bytes, path)
}

/// [`open_baked`] for a file already in memory (a browser's fetch or dropped file); `name`
/// names it in errors.
pub fn baked_from_bytes(bytes: &[u8], name: &Path) -> Result<Baked, PlayerError> {
    let baked: Baked = trisort_format::container::decode(FileKind::Baked, bytes, name)?;
    baked
        .check_structure()
        .map_err(|reason| PlayerError::Structure {
            path: Some(name.to_path_buf()),
            reason,
        })?;
    Ok(baked)
}

/// A baked file on the GPU, ready to draw any of its frames into a caller's render pass.
///
/// Everything is uploaded once by [`Player::new`]: the scene (vertices, materials, textures,
/// per-frame uniforms and node matrices, see [`SceneGpu`]), the index buffer in the mode's
/// order, and every frame's `DrawIndexedIndirectArgs` back to back in one indirect buffer.
pub struct Player {
    scene: SceneGpu,
    /// [`Player::gpu_budget`].
    budget: GpuBudget,
    /// [`Player::gpu_bytes_allocated`].
    allocated: GpuBytes,
    bindings: Bindings,
    pipeline: wgpu::RenderPipeline,
    index_buffer: wgpu::Buffer,
    index_format: wgpu::IndexFormat,
    index_count: u32,
    indirect: wgpu::Buffer,
    commands: Vec<DrawIndexedIndirectArgs>,
    windows: Vec<FrameWindow>,
    config: PlayerConfig,
    warnings: Vec<String>,
    /// The default material table, and each variant's by name (or why it cannot be played),
    /// worked out once from the file's geometry.
    materials: Vec<Material>,
    variants: Vec<(String, Result<Vec<Material>, trisort_format::VariantError>)>,
    /// The file's clips (at least one, covering the frames in order) and the index of the
    /// one selected ([`Player::set_clip`]).
    clips: Vec<Clip>,
    clip: usize,
}

impl Player {
    /// Uploads `baked` for playing with `config`.
    ///
    /// Checks the file's structure first (every draw inside the index buffer, every window
    /// inside the draw list), so the indirect commands are valid whether or not wgpu validates
    /// indirect calls. Errors on an inconsistent file, on `depth` mode without a depth format,
    /// and on anything wgpu refuses (caught in an error scope). [`Player::warnings`] lists what
    /// makes this playback inexact.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        baked: &Baked,
        config: PlayerConfig,
    ) -> Result<Player, PlayerError> {
        Player::build(device, queue, baked, config, false)
    }

    /// [`Player::new`] with 32-bit indices even where 16 bits would do (to compare both paths).
    pub fn new_u32(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        baked: &Baked,
        config: PlayerConfig,
    ) -> Result<Player, PlayerError> {
        Player::build(device, queue, baked, config, true)
    }

    fn build(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        baked: &Baked,
        config: PlayerConfig,
        force_u32: bool,
    ) -> Result<Player, PlayerError> {
        baked
            .check_structure()
            .map_err(|reason| PlayerError::Structure { path: None, reason })?;
        if config.mode == Mode::Depth && config.depth_format.is_none() {
            return Err(PlayerError::DepthFormatMissing);
        }
        let warnings = playback_warnings(baked, &config);
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);

        let view = View {
            width: config.size.0.max(1),
            height: config.size.1.max(1),
            samples: config.sample_count,
            glass_opacity: config.glass_opacity_for(baked),
        };
        let bindings = Bindings::for_limits(&device.limits());
        bindings
            .check_fits(&device.limits(), &baked.geometry, baked.frame_states.len())
            .map_err(PlayerError::DeviceTooSmall)?;
        let scene = SceneGpu::with_options(
            device,
            queue,
            &baked.geometry,
            &baked.frame_states,
            view,
            SceneOptions {
                bindings,
                lighting: trisort_gpu::Lighting {
                    shading: config.shading,
                    tone_map: config.tone_map,
                    environment: &baked.environment,
                },
                decode_textures: config.decode_textures,
            },
        );
        let order = if config.mode.back_to_front() {
            Order::BackToFront
        } else {
            Order::FrontToBack
        };
        // The scene's budget plus the index and indirect buffers: every buffer below is sized
        // from it, and counted as it is created.
        let budget = GpuBudget::from_scene(scene.budget(), baked, force_u32);
        let mut allocated = scene.allocated().clone();
        let indices = index_buffer(baked, order, force_u32);
        let index_count = indices.len() as u32;
        let index_buffer = sized_buffer(
            device,
            "trisort sorted indices",
            budget.bytes.buffer(GpuKind::Indices),
            indices.bytes(),
            // COPY_SRC: so tests and tools can read back what is drawn.
            wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_SRC,
        );
        allocated.count_buffer(GpuKind::Indices, &index_buffer);
        let (commands, windows) = frame_commands(baked, order);
        let indirect = sized_buffer(
            device,
            "trisort frame windows",
            budget.bytes.buffer(GpuKind::Indirect),
            bytemuck::cast_slice(&commands),
            // WebGL2 has no indirect buffers: the direct path draws from the CPU copy, and
            // keeps this one only for tools that read it back.
            match config.draw_path {
                DrawPath::MultiDrawIndirect => {
                    wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_SRC
                }
                DrawPath::Direct => wgpu::BufferUsages::COPY_SRC,
            },
        );
        allocated.count_buffer(GpuKind::Indirect, &indirect);
        let pipeline = create_pipeline(device, &scene.layout, &config, bindings);

        if let Some(Some(e)) = trisort_gpu::poll_ready(scope.pop()) {
            return Err(PlayerError::Wgpu(e.to_string()));
        }
        Ok(Player {
            scene,
            budget,
            allocated,
            bindings,
            pipeline,
            index_format: indices.format(),
            index_buffer,
            index_count,
            indirect,
            commands,
            windows,
            config,
            warnings,
            materials: baked.geometry.materials.clone(),
            variants: (baked.geometry.variants.iter())
                .map(|v| {
                    let table = baked.geometry.variant_materials(Some(&v.name));
                    (v.name.clone(), table)
                })
                .collect(),
            clips: baked.clips.clone(),
            clip: 0,
        })
    }

    /// Draws the file's materials as material variant `name` has them (`None`: the default
    /// materials), by rewriting the material table: colours, emissive and base-colour texture
    /// indices change, the sorted order and every buffer stay. Takes effect for commands
    /// submitted after it.
    ///
    /// Errors, leaving the table as it was: [`trisort_format::VariantError::Unknown`] (listing
    /// the file's variants) when the file has no variant of that name (the first of that name
    /// counts), and [`trisort_format::VariantError::ChangesVisibility`] when the variant
    /// changes what decides coverage or opacity (alpha mode, alpha, cutoff, transmission,
    /// double-sidedness; see [`trisort_format::Geometry::variant_materials`]): the baked order
    /// would not be exact.
    pub fn set_variant(&self, queue: &wgpu::Queue, name: Option<&str>) -> Result<(), PlayerError> {
        let table = match name {
            None => &self.materials,
            Some(name) => match self.variants.iter().find(|(n, _)| n == name) {
                Some((_, Ok(table))) => table,
                Some((_, Err(e))) => return Err(e.clone().into()),
                None => {
                    return Err(trisort_format::VariantError::Unknown {
                        name: name.to_string(),
                        available: self.variant_names(),
                    }
                    .into())
                }
            },
        };
        self.scene.set_materials(queue, table);
        Ok(())
    }

    /// The names of the file's material variants, in file order.
    pub fn variant_names(&self) -> Vec<String> {
        self.variants.iter().map(|(n, _)| n.clone()).collect()
    }

    /// The file's clips (its camera paths), in frame order: at least one, together covering
    /// every frame ([`Baked::clips`]).
    pub fn clips(&self) -> &[Clip] {
        &self.clips
    }

    /// The selected clip: the first until [`Player::set_clip`] selects another.
    pub fn clip(&self) -> &Clip {
        &self.clips[self.clip]
    }

    /// The index of the selected clip in [`Player::clips`].
    pub fn clip_index(&self) -> usize {
        self.clip
    }

    /// The file's frames the selected clip spans: what a host plays, in order, to play the
    /// clip. Frame indices stay the file's: pass them to [`Player::draw`] as they are (frame
    /// `clip_frames().start` is the clip's frame 0).
    pub fn clip_frames(&self) -> Range<u32> {
        self.clip().frames()
    }

    /// Selects the clip named `name` (see [`Player::clip_frames`]). Every frame of the file
    /// stays drawable; the selection only says which frames the clip's playback iterates.
    ///
    /// Errors, leaving the selection as it was, with [`PlayerError::UnknownClip`] (listing
    /// the file's clips) when the file has no clip of that name.
    pub fn set_clip(&mut self, name: &str) -> Result<(), PlayerError> {
        self.clip = clip_index(&self.clips, name)?;
        Ok(())
    }

    /// Draws frame `frame` into `pass`: binds the pipeline, the frame's uniforms and node
    /// matrices (dynamic offsets), the vertex and index buffers, and issues exactly one
    /// `multi_draw_indexed_indirect` over the frame's window, or, on the
    /// [`DrawPath::Direct`] path, one `draw_indexed` per range of the window. A frame whose
    /// window is empty issues no draw.
    ///
    /// The pass's attachments must match the [`PlayerConfig`] (formats, sample count); in
    /// `saturate` mode its colour must have been cleared to alpha 0.
    pub fn draw(&self, pass: &mut impl DrawCalls, frame: u32) -> Result<(), PlayerError> {
        let Some(&window) = self.windows.get(frame as usize) else {
            return Err(PlayerError::FrameOutOfRange {
                frame,
                frames: self.windows.len() as u32,
            });
        };
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
        pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), self.index_format);
        match self.config.draw_path {
            // An empty window draws nothing. It issues no call: wgpu 30.0.1 with indirect
            // validation on draws the first command even when `count` is 0 (wgpu-core
            // `multi_draw_indirect` adds the command at `offset` before looping to `count`).
            _ if window.count == 0 => {}
            DrawPath::MultiDrawIndirect => pass.multi_draw_indexed_indirect(
                &self.indirect,
                window.first as u64 * ARGS_SIZE,
                window.count,
            ),
            DrawPath::Direct => {
                for d in self.frame_commands(frame) {
                    pass.draw_indexed(
                        d.first_index..d.first_index + d.index_count,
                        d.base_vertex,
                        d.first_instance..d.first_instance + d.instance_count,
                    );
                }
            }
        }
        Ok(())
    }

    /// Number of frames.
    pub fn frame_count(&self) -> u32 {
        self.windows.len() as u32
    }

    /// Frame `frame`'s draws in the order they are played (a CPU copy of its part of
    /// [`Player::indirect_buffer`]).
    pub fn frame_commands(&self, frame: u32) -> &[DrawIndexedIndirectArgs] {
        let w = self.windows[frame as usize];
        &self.commands[w.first as usize..(w.first + w.count) as usize]
    }

    /// Triangles drawn in frame `frame`.
    pub fn frame_triangles(&self, frame: u32) -> u64 {
        self.frame_commands(frame)
            .iter()
            .map(|d| d.index_count as u64 / 3)
            .sum()
    }

    /// Byte offset of frame `frame`'s first command in [`Player::indirect_buffer`].
    pub fn frame_offset(&self, frame: u32) -> u64 {
        self.windows[frame as usize].first as u64 * ARGS_SIZE
    }

    /// The indirect buffer: every frame's commands back to back (`INDIRECT` usage only on the
    /// [`DrawPath::MultiDrawIndirect`] path; the direct path draws from a CPU copy).
    pub fn indirect_buffer(&self) -> &wgpu::Buffer {
        &self.indirect
    }

    /// The index buffer in the mode's order.
    pub fn index_buffer(&self) -> &wgpu::Buffer {
        &self.index_buffer
    }

    /// Index format of the index buffer (u16 where every vertex index fits).
    pub fn index_format(&self) -> wgpu::IndexFormat {
        self.index_format
    }

    /// Number of indices in the index buffer (3 per copy).
    pub fn index_count(&self) -> u32 {
        self.index_count
    }

    /// How node matrices and materials are bound: [`Bindings::Storage`], or the data textures
    /// of [`Bindings::Textures`] where the device's limits have no vertex storage (WebGL2).
    pub fn bindings(&self) -> Bindings {
        self.bindings
    }

    /// GPU bytes of the scene's textures (both material arrays with their mips) and the
    /// prefiltered environment ([`SceneGpu::texture_bytes`]).
    pub fn texture_bytes(&self) -> u64 {
        self.scene.texture_bytes()
    }

    /// How the sRGB and the linear material texture array were uploaded: in their members'
    /// block format ([`ArrayUpload::Blocks`]) where every member is stored as blocks of one
    /// family and the device samples it, else as RGBA8 (decoded from the file's blocks where
    /// it has them: always with [`PlayerConfig::decode_textures`]). `play --json` prints their
    /// [`ArrayUpload::name`]s as `texture_upload`.
    pub fn texture_uploads(&self) -> &[ArrayUpload; 2] {
        &self.budget.texture_uploads
    }

    /// The GPU memory this player was sized from: [`GpuBudget::from_scene`] for this device
    /// and tier, the figure `inspect` reports for a device with WebGPU's default limits.
    pub fn gpu_budget(&self) -> &GpuBudget {
        &self.budget
    }

    /// Bytes of every buffer and texture the player created (its scene's and its own), by
    /// kind, counted from the wgpu objects where they were created.
    pub fn gpu_bytes_allocated(&self) -> &GpuBytes {
        &self.allocated
    }

    /// Shifts the projection of every frame by `offset` pixels (x right, y down) at the
    /// configured size; `[0.0, 0.0]` restores the recorded projection. A test aid standing for
    /// another GPU's vertex snapping (`play --subpixel-offset`): frames drawn after it move by
    /// a fraction of a pixel, which the sorted order was not recorded for
    /// ([`trisort_gpu::scene_gpu::SceneGpu::set_subpixel_offset`]).
    pub fn set_subpixel_offset(&self, queue: &wgpu::Queue, offset: [f64; 2]) {
        self.scene.set_subpixel_offset(queue, offset);
    }

    /// The configuration it was created with.
    pub fn config(&self) -> &PlayerConfig {
        &self.config
    }

    /// What makes this playback inexact (see [`playback_warnings`]); empty at the recorded
    /// sample pattern on the recording device.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }
}

/// The index of the clip named `name` among `clips`, or [`PlayerError::UnknownClip`] listing
/// their names (for hosts that pick a clip before building a [`Player`]).
pub fn clip_index(clips: &[Clip], name: &str) -> Result<usize, PlayerError> {
    clips
        .iter()
        .position(|c| c.name == name)
        .ok_or_else(|| PlayerError::UnknownClip {
            name: name.to_string(),
            clips: clips.iter().map(|c| c.name.clone()).collect(),
        })
}

/// The fragment entry point of [`trisort_gpu::PLAYER`] a mode uses: straight alpha for
/// `blend` and `depth`, premultiplied for `saturate`. With [`blend_state`], what a reference
/// renderer needs to composite exactly as the player does.
pub fn fragment_entry_point(mode: Mode) -> &'static str {
    match mode {
        Mode::Blend | Mode::Depth => "fs_player_straight",
        Mode::Saturate => "fs_player_premultiplied",
    }
}

/// The blend state of a mode (see the crate documentation for the equations).
pub fn blend_state(mode: Mode) -> wgpu::BlendState {
    use wgpu::{BlendComponent, BlendFactor, BlendOperation};
    match mode {
        // Straight alpha, over: colour s.a·s + (1 − s.a)·d, alpha s.a + (1 − s.a)·d.a.
        Mode::Blend | Mode::Depth => wgpu::BlendState {
            color: BlendComponent {
                src_factor: BlendFactor::SrcAlpha,
                dst_factor: BlendFactor::OneMinusSrcAlpha,
                operation: BlendOperation::Add,
            },
            alpha: BlendComponent {
                src_factor: BlendFactor::One,
                dst_factor: BlendFactor::OneMinusSrcAlpha,
                operation: BlendOperation::Add,
            },
        },
        // Premultiplied source, under: (1 − d.a)·s + d for colour and alpha alike.
        Mode::Saturate => {
            let under = BlendComponent {
                src_factor: BlendFactor::OneMinusDstAlpha,
                dst_factor: BlendFactor::One,
                operation: BlendOperation::Add,
            };
            wgpu::BlendState {
                color: under,
                alpha: under,
            }
        }
    }
}

fn create_pipeline(
    device: &wgpu::Device,
    scene_layout: &wgpu::BindGroupLayout,
    config: &PlayerConfig,
    bindings: Bindings,
) -> wgpu::RenderPipeline {
    let source = trisort_gpu::compose_with(bindings, &[], trisort_gpu::PLAYER);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("trisort player"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    // The player's pipeline state (every reference renderer shares it through ScenePipeline):
    // counter-clockwise fronts, no hardware culling (single-sided materials discard on
    // `front_facing`), the mode's blend, depth only in depth mode.
    let depth = config.depth_format.map(|format| {
        if config.mode == Mode::Depth {
            (format, wgpu::CompareFunction::Less, true)
        } else {
            (format, wgpu::CompareFunction::Always, false)
        }
    });
    ScenePipeline {
        label: "trisort player",
        layouts: &[scene_layout],
        module: &module,
        vertex: "vs_player",
        fragment: fragment_entry_point(config.mode),
        target: wgpu::ColorTargetState {
            format: config.color_format,
            blend: Some(blend_state(config.mode)),
            write_mask: wgpu::ColorWrites::ALL,
        },
        depth,
        samples: config.sample_count,
    }
    .build_shaded(device, config.shading)
}
