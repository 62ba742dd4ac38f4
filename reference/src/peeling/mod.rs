//! Classic exact depth peeling run entirely on the GPU: the run-time rival that `trisort bench`
//! times against the merged player.
//!
//! [`ExactReference`](crate::ExactReference) peels with the recorder's peeler and reads every
//! layer back to build per-layer index lists; [`PeelingRenderer`] records a frame as a fixed
//! sequence of GPU passes with no readback and no CPU sync inside it. It produces the exact
//! reference's image bit for bit (`blend` and `depth`), because it keeps the reference's keys,
//! shading, compositing order and blend:
//!
//! - **Keys.** Fragments are ordered per sample by the recorder's (depth, triangle id) key: the
//!   depth is `position.z`, written explicitly, the lower id in front on a tie. Every pass
//!   draws every triangle in one draw in ascending id order (`primitive_index` = id).
//! - **Order.** The reference composites a sample's fragments back to front with the player's
//!   straight-alpha *over* blend into `Rgba16Float`. Rounding to f16 after every blend makes
//!   that order part of the result, so this renderer peels **back to front** (reverse depth
//!   peeling): pass `j` keeps, per sample, the farthest key in front of pass `j − 1`'s (depth
//!   test `GreaterEqual`, so the higher id wins a tie) and is composited over the accumulation
//!   at once. A frame of `L` layers takes `L` peel passes and `L` compositing passes.
//! - **Shading.** The peel pass writes only ids and depth (it shades per sample: it reads the
//!   previous key at `sample_index`). Each layer is then composited by drawing every triangle
//!   again through `vs_player` and the player's `player_colour`, evaluated once per pixel, each
//!   triangle writing only the samples where it is the layer's fragment (`sample_mask`): the
//!   reference's own compositing pass, with the layer's ids read from the peel's texture.
//! - **Truncation.** When a frame needs more layers than it is given, the front `layers` layers
//!   are kept (as the reference keeps them): `layers` front-to-back passes (ids and depth only)
//!   first find, per sample, the key of its last kept fragment; the back-to-front peel then
//!   starts at that key. Only frames [`PeelingRenderer::layers`] found truncated pay for it.
//! - **`depth`.** One front-to-back pass (`Less`: the nearest fragment, the lowest id on a tie)
//!   composited over the background: the reference's first layer.
//!
//! The layer count of a frame is found once, outside the timed path, by front-to-back peeling
//! with an occlusion query per pass until a pass writes no sample ([`PeelingRenderer::layers`]).
//!
//! Cost per layer: two full-scene geometry passes (peel, then composite) and no full-screen
//! pass. Targets: ids `R32Uint` and depth `Depth32Float` (two of each, ping-ponged) and the
//! `Rgba16Float` accumulation at the frame's sample count, resolved by the last compositing
//! pass.

mod setup;

use std::sync::Mutex;

use trisort_gpu::scene_gpu::{begin_peel_pass, SceneGpu};
use trisort_gpu::Gpu;
use trisort_gpu::{clear_colour, FrameTarget};
use trisort_player::Mode;

use crate::ReferenceError;

/// Format of the peel passes' id target (triangle id + 1, 0 = no fragment).
const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// Which fragments a peel pass keeps (the `mode` uniform of `fs_peeling`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Keep {
    /// Every fragment (the first pass).
    All = 0,
    /// Keys behind the previous pass's (front to back).
    Behind = 1,
    /// Keys in front of the previous pass's (back to front).
    InFront = 2,
    /// Keys at or in front of the previous pass's (back to front under a limit).
    AtOrInFront = 3,
}

/// Peel direction: which pipeline and clear depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Direction {
    /// Nearest first: depth test `Less`, cleared to 1.
    FrontToBack,
    /// Farthest first: depth test `GreaterEqual`, cleared to 0.
    BackToFront,
}

/// Which layer one peel pass takes: its direction, which fragments it keeps relative to the
/// previous pass's key, and the target (0 or 1) it writes (it reads the other).
#[derive(Clone, Copy, Debug)]
struct PeelLayer {
    direction: Direction,
    keep: Keep,
    write: usize,
}

/// One frame of the peeling renderer, read back.
#[derive(Clone, Debug, PartialEq)]
pub struct PeeledFrame {
    /// `width × height` pixels, RGBA8, sRGB-encoded, alpha 255: the resolved `Rgba16Float`
    /// frame through [`trisort_gpu::quantize_rgba16f`], like the player's and the exact reference's frames.
    pub rgba8: Vec<u8>,
    /// Layers peeled and composited (`depth`: 1, or 0 where nothing is drawn).
    pub layers: u32,
    /// Whether the frame needs more than `max_layers` layers (the front `max_layers` are
    /// composited).
    pub truncated: bool,
}

/// GPU-only exact depth peeling of one scene at one size, sample count and mode.
pub struct PeelingRenderer<'g> {
    gpu: &'g Gpu,
    samples: u32,
    mode: Mode,
    max_layers: u32,
    triangles: u32,
    scene: SceneGpu,
    index: wgpu::Buffer,
    front: wgpu::RenderPipeline,
    back: wgpu::RenderPipeline,
    composite: wgpu::RenderPipeline,
    /// Per keep mode, at `params_stride`: the `Peeling` uniform.
    params_stride: u64,
    /// `peel_groups[p]`: the peel bind group reading target `p` as the previous key.
    peel_groups: [wgpu::BindGroup; 2],
    /// `composite_groups[p]`: the compositing bind group reading target `p`'s ids.
    composite_groups: [wgpu::BindGroup; 2],
    ids: [wgpu::TextureView; 2],
    depth: [wgpu::TextureView; 2],
    /// The accumulation (multisampled at `samples`, resolved by the last compositing pass)
    /// and its readback.
    target: FrameTarget,
    occlusion: wgpu::QuerySet,
    occlusion_resolve: wgpu::Buffer,
    occlusion_staging: wgpu::Buffer,
    /// Per frame: (layers, truncated) once counted.
    counted: Mutex<Vec<Option<(u32, bool)>>>,
}

/// Size, mode and budget of a [`PeelingRenderer`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeelingConfig {
    /// Image size (width, height).
    pub size: (u32, u32),
    /// MSAA samples (1 or 4).
    pub samples: u32,
    /// `Blend` or `Depth` (`Saturate` has no peeling renderer).
    pub mode: Mode,
    /// Most layers peeled a frame; a frame that needs more is marked truncated.
    pub max_layers: u32,
    /// Opacity transmissive glass is drawn at (a baked file's recorded opacity, or the one it
    /// is played at).
    pub glass_opacity: f32,
}

impl PeelingConfig {
    /// `mode` at `size` and `samples` with at most `max_layers` layers, transmissive glass at
    /// the recorder's default opacity.
    pub fn new(size: (u32, u32), samples: u32, mode: Mode, max_layers: u32) -> PeelingConfig {
        PeelingConfig {
            size,
            samples,
            mode,
            max_layers,
            glass_opacity: trisort_format::RecordSettings::default().glass_opacity,
        }
    }
}

impl<'g> PeelingRenderer<'g> {
    /// Triangles submitted per peel pass: every triangle of the scene. Each compositing pass
    /// submits them again, so a frame of `L` layers submits `2 · L` times this (and `L` more
    /// when truncated).
    pub fn triangles(&self) -> u64 {
        self.triangles as u64
    }

    /// The resolved single-sample `Rgba16Float` frame [`PeelingRenderer::encode`] leaves.
    pub fn target(&self) -> &wgpu::Texture {
        self.target.resolved()
    }

    /// The number of layers frame `frame` needs: peels front to back with an occlusion query
    /// per pass, reading each back, until a pass writes no sample; capped at `max_layers`
    /// (`depth` mode: 1, or 0 where nothing is drawn). Counted once per frame, then cached.
    /// Errors for a frame beyond the path or a wgpu validation error.
    pub fn layers(&self, frame: u32) -> Result<u32, ReferenceError> {
        Ok(self.count(frame)?.0)
    }

    /// Whether frame `frame` needs more than `max_layers` layers (counted as in
    /// [`PeelingRenderer::layers`]; always false in `depth` mode).
    pub fn truncated(&self, frame: u32) -> Result<bool, ReferenceError> {
        Ok(self.count(frame)?.1)
    }

    fn count(&self, frame: u32) -> Result<(u32, bool), ReferenceError> {
        let frames = self.scene.frames();
        if frame >= frames {
            return Err(ReferenceError::Invalid(format!(
                "frame {frame} of a path of {frames} frames"
            )));
        }
        if let Some(c) = self.lock_counted()[frame as usize] {
            return Ok(c);
        }
        let cap = if self.mode == Mode::Depth {
            1
        } else {
            self.max_layers
        };
        let device = &self.gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut layers = 0u32;
        let truncated = loop {
            let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("peeling layer count"),
            });
            let keep = if layers == 0 { Keep::All } else { Keep::Behind };
            self.peel_pass(
                &mut enc,
                frame,
                PeelLayer {
                    direction: Direction::FrontToBack,
                    keep,
                    write: (layers % 2) as usize,
                },
                None,
                true,
            );
            enc.resolve_query_set(&self.occlusion, 0..1, &self.occlusion_resolve, 0);
            enc.copy_buffer_to_buffer(&self.occlusion_resolve, 0, &self.occlusion_staging, 0, 8);
            self.gpu.queue.submit([enc.finish()]);
            let bytes = self.gpu.map_read(&self.occlusion_staging);
            let passed = u64::from_le_bytes(bytes[..8].try_into().expect("8 bytes"));
            if passed == 0 {
                break false;
            }
            if layers == cap {
                // The pass after the last allowed one still wrote samples.
                break self.mode != Mode::Depth;
            }
            layers += 1;
        };
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(ReferenceError::Wgpu(e.to_string()));
        }
        let c = (layers, truncated);
        self.lock_counted()[frame as usize] = Some(c);
        Ok(c)
    }

    fn lock_counted(&self) -> std::sync::MutexGuard<'_, Vec<Option<(u32, bool)>>> {
        self.counted.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Records every GPU command of frame `frame` with `layers` peel passes and their
    /// compositing passes into `enc`, leaving the resolved single-sample `Rgba16Float` frame in
    /// [`PeelingRenderer::target`]. With `stats`, back-to-front peel pass `k` (`depth` mode:
    /// the one front-to-back pass) is bracketed by pipeline-statistics query `k`, so the set
    /// needs `layers` slots; the compositing passes (and a truncated frame's limit passes) are
    /// not counted. No readback, no CPU sync.
    ///
    /// `layers` is normally [`PeelingRenderer::layers`]`(frame)`. Where that call found the
    /// frame truncated or needing more than `layers`, the front `layers` layers are kept
    /// (`layers` more front-to-back passes find where they end); a frame not counted yet is
    /// taken to need no more than `layers`. In `depth` mode any `layers` ≥ 1 draws the one
    /// layer. Panics if `frame` is beyond the path.
    pub fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        frame: u32,
        layers: u32,
        stats: Option<&wgpu::QuerySet>,
    ) {
        assert!(
            frame < self.scene.frames(),
            "frame {frame} of a path of {} frames",
            self.scene.frames()
        );
        let clear = clear_colour(self.mode);
        if layers == 0 {
            drop(self.composite_pass(enc, frame, None, Some(clear), true));
            return;
        }
        if self.mode == Mode::Depth {
            self.peel_pass(
                enc,
                frame,
                PeelLayer {
                    direction: Direction::FrontToBack,
                    keep: Keep::All,
                    write: 0,
                },
                stats.map(|s| (s, 0)),
                false,
            );
            drop(self.composite_pass(enc, frame, Some(0), Some(clear), true));
            return;
        }
        let limited = self
            .lock_counted()
            .get(frame as usize)
            .copied()
            .flatten()
            .is_some_and(|(needed, truncated)| layers < needed || truncated);
        // `next`: the target the next peel pass writes (the other one holds the previous key).
        let mut next = 0usize;
        let mut keep = Keep::All;
        if limited {
            for k in 0..layers {
                let keep = if k == 0 { Keep::All } else { Keep::Behind };
                self.peel_pass(
                    enc,
                    frame,
                    PeelLayer {
                        direction: Direction::FrontToBack,
                        keep,
                        write: next,
                    },
                    None,
                    false,
                );
                next = 1 - next;
            }
            keep = Keep::AtOrInFront;
        }
        for k in 0..layers {
            self.peel_pass(
                enc,
                frame,
                PeelLayer {
                    direction: Direction::BackToFront,
                    keep,
                    write: next,
                },
                stats.map(|s| (s, k)),
                false,
            );
            let (load, resolve) = (if k == 0 { Some(clear) } else { None }, k + 1 == layers);
            drop(self.composite_pass(enc, frame, Some(next), load, resolve));
            next = 1 - next;
            keep = Keep::InFront;
        }
    }

    /// One peel pass of `layer` (writing ids and depth into its target, reading the previous
    /// key from the other), counting into the pipeline statistics query `stats` and, with
    /// `occlusion`, the occlusion query.
    fn peel_pass(
        &self,
        enc: &mut wgpu::CommandEncoder,
        frame: u32,
        layer: PeelLayer,
        stats: Option<(&wgpu::QuerySet, u32)>,
        occlusion: bool,
    ) {
        let PeelLayer {
            direction,
            keep,
            write,
        } = layer;
        let clear_depth = match direction {
            Direction::FrontToBack => 1.0,
            Direction::BackToFront => 0.0,
        };
        let mut pass = begin_peel_pass(
            enc,
            "peeling peel",
            &self.ids[write],
            &self.depth[write],
            clear_depth,
            occlusion.then_some(&self.occlusion),
        );
        pass.set_pipeline(match direction {
            Direction::FrontToBack => &self.front,
            Direction::BackToFront => &self.back,
        });
        pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
        pass.set_bind_group(
            1,
            &self.peel_groups[1 - write],
            &[(keep as u64 * self.params_stride) as u32],
        );
        pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
        pass.set_index_buffer(self.index.slice(..), wgpu::IndexFormat::Uint32);
        if occlusion {
            pass.begin_occlusion_query(0);
        }
        if let Some((set, k)) = stats {
            pass.begin_pipeline_statistics_query(set, k);
        }
        if self.triangles > 0 {
            pass.draw_indexed(0..self.triangles * 3, 0, 0..1);
        }
        if stats.is_some() {
            pass.end_pipeline_statistics_query();
        }
        if occlusion {
            pass.end_occlusion_query();
        }
    }

    /// One compositing pass over the accumulation: the layer in target `layer` (none: only
    /// the clear), cleared first when `clear` is given, resolved when `resolve`.
    fn composite_pass<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        frame: u32,
        layer: Option<usize>,
        clear: Option<wgpu::Color>,
        resolve: bool,
    ) -> wgpu::RenderPass<'e> {
        let mut pass = self.target.begin_pass_with(enc, clear, resolve, None);
        if let Some(p) = layer {
            if self.triangles > 0 {
                pass.set_pipeline(&self.composite);
                pass.set_bind_group(0, &self.scene.bind_group, &self.scene.offsets(frame));
                pass.set_bind_group(1, &self.composite_groups[p], &[]);
                pass.set_vertex_buffer(0, self.scene.vertices.slice(..));
                pass.set_index_buffer(self.index.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..self.triangles * 3, 0, 0..1);
            }
        }
        pass
    }

    /// [`PeelingRenderer::layers`], then [`PeelingRenderer::encode`] with that many layers,
    /// submitted and read back as 8-bit sRGB.
    pub fn render(&self, frame: u32) -> Result<PeeledFrame, ReferenceError> {
        let (layers, truncated) = self.count(frame)?;
        let rgba8 = self.target.read_rgba8(self.gpu, Mode::Blend, |enc| {
            self.encode(enc, frame, layers, None)
        })?;
        Ok(PeeledFrame {
            rgba8,
            layers,
            truncated,
        })
    }

    /// The sample count.
    pub fn samples(&self) -> u32 {
        self.samples
    }
}
