//! The renderers `trisort bench` compares, behind one [`Method`] trait.
//!
//! | method | what it draws per frame | modes |
//! |---|---|---|
//! | `default` | every triangle with the depth test: opaque first, then transparent unsorted (`blend`); a z-buffer of all triangles (`depth`) | blend, depth |
//! | `source` | the frame's own visible set V_f, sorted, one draw (the lower bound) | all |
//! | `merged` | the baked sliding window: one multi-draw-indirect | all |
//! | `oit` | every triangle into per-sample linked lists, sorted and composited per sample (paper 001) | blend |
//! | `peeling` | every triangle once per layer, exact per-sample depth peeling on the GPU | blend, depth |
//! | `presorted` | paper 000's presorted lists: the opaque triangles, then the camera's partition in one draw | all |
//! | `occlusion-query` | paper 004: the transparent objects ordered by occlusion queries each frame, drawn back to front after the opaque ones | blend |
//!
//! Every method renders into its own `Rgba16Float` target at the bench's size and sample count,
//! resolved to one sample and quantized to 8-bit sRGB like the player's frames, so their
//! images compare directly with the exact reference.

use trisort_format::{
    Baked, DrawIndexedIndirectArgs, FrameState, FrameWindow, Geometry, Recording,
};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Gpu;
use trisort_gpu::{clear_colour, FrameTarget, TargetConfig, COLOR_FORMAT, DEPTH_FORMAT};
use trisort_player::commands::{index_buffer, Order};
use trisort_player::config::{DrawPath, PlayerConfig};
use trisort_player::{Mode, Player};
use trisort_reference::exact::whole_scene_baked;
use trisort_reference::DefaultRenderer;

use crate::BenchError;

/// A renderer the bench times and compares.
pub trait Method {
    /// Method name (`default`, `source`, `merged`, `oit`, `peeling`, `presorted`,
    /// `occlusion-query`).
    fn name(&self) -> &str;
    /// Compositing mode it renders.
    fn mode(&self) -> Mode;
    /// The GPU it runs on.
    fn gpu(&self) -> &Gpu;
    /// Extra facts about the configuration (e.g. wgpu's indirect validation, OIT's budget).
    fn variant(&self) -> String {
        String::new()
    }
    /// Work to do before frame `frame` is timed (e.g. finding its peel depth); not timed.
    fn prepare(&self, _frame: u32) -> Result<(), BenchError> {
        Ok(())
    }
    /// Triangles submitted for frame `frame` (after [`Method::prepare`]).
    fn triangles(&self, frame: u32) -> u64;
    /// Draw commands issued for frame `frame` (after [`Method::prepare`]).
    fn draws(&self, frame: u32) -> u32;
    /// Pipeline-statistics query slots [`Method::encode`] uses for frame `frame`: one per
    /// render pass with scene geometry.
    fn stat_slots(&self, frame: u32) -> u32;
    /// Records every GPU command of frame `frame` into `enc`, ending with the resolved frame in
    /// the method's own target; with `stats`, scene-geometry pass k is bracketed by a
    /// pipeline-statistics query at slot k. No readback, no CPU wait.
    fn encode(&self, enc: &mut wgpu::CommandEncoder, frame: u32, stats: Option<&wgpu::QuerySet>);
    /// Renders frame `frame` and reads it back as 8-bit sRGB RGBA.
    fn image(&self, frame: u32) -> Result<Vec<u8>, BenchError>;
    /// The triangle streams the method rasterizes for frame `frame`, in submission order, for
    /// the harness's fragment count (see [`crate::harness::FragmentCounter`]).
    fn streams(&self, frame: u32) -> Vec<Stream>;
    /// What a method that sorts with occlusion queries spent on them (`occlusion-query`).
    fn query_stats(&self) -> Option<crate::vis_sort::QueryStats> {
        None
    }
}

/// One draw of a method's frame as the fragment counter replays it.
#[derive(Clone, Debug, PartialEq)]
pub struct Stream {
    /// Vertex indices (three per triangle) in submission order.
    pub indices: Vec<u32>,
    /// Depth state: `None` no test; `Some(write)` test `Less`, writing depth when `write`.
    pub depth: Option<bool>,
    /// Times the stream is drawn per frame (peeling: once per layer).
    pub repeat: u32,
    /// Whether its fragments are shaded once per sample (per-sample shading).
    pub per_sample: bool,
}

/// Why a presorted file cannot stand for the bench's scene (`None`: it can): the `presorted`
/// methods draw the file's scene and the reference renders the bench's, so the two must be
/// the same triangle for triangle (the same scene split at the same pose).
pub fn presorted_mismatch(file: &trisort_format::Presorted, geometry: &Geometry) -> Option<String> {
    (file.geometry.triangles != geometry.triangles || file.geometry.vertices != geometry.vertices)
        .then(|| {
            format!(
                "the file's scene ({} triangles, {} vertices) is not the bench's ({} and {}): \
                 presort the same scene (a path whose first frame moves a node splits it at \
                 another pose)",
                file.geometry.triangles.len(),
                file.geometry.vertices.len(),
                geometry.triangles.len(),
                geometry.vertices.len()
            )
        })
}

/// Size, sample count and glass opacity the bench renders at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchView {
    /// Width and height in pixels.
    pub size: (u32, u32),
    /// MSAA samples (1 or 4).
    pub samples: u32,
    /// Opacity of transmissive glass.
    pub glass_opacity: f32,
}

impl BenchView {
    pub(crate) fn view(&self) -> View {
        View {
            width: self.size.0,
            height: self.size.1,
            samples: self.samples,
            glass_opacity: self.glass_opacity,
        }
    }
}

pub(crate) fn stats_begin(
    pass: &mut wgpu::RenderPass<'_>,
    stats: Option<&wgpu::QuerySet>,
    slot: u32,
) {
    if let Some(set) = stats {
        pass.begin_pipeline_statistics_query(set, slot);
    }
}

pub(crate) fn stats_end(pass: &mut wgpu::RenderPass<'_>, stats: Option<&wgpu::QuerySet>) {
    if stats.is_some() {
        pass.end_pipeline_statistics_query();
    }
}

/// A baked file played by the [`Player`]: `merged` (the bake itself), `source` (see
/// [`source_baked`]) and the depth-mode `default` (see [`whole_scene_baked`]).
pub struct PlayerMethod<'g> {
    name: String,
    variant: String,
    gpu: &'g Gpu,
    player: Player,
    target: FrameTarget,
    mode: Mode,
    /// CPU copy of the index buffer in play order (for the fragment counter).
    indices: Vec<u32>,
}

impl<'g> PlayerMethod<'g> {
    /// Plays `baked` in `mode` at `view` on `gpu`.
    pub fn new(
        name: &str,
        variant: String,
        gpu: &'g Gpu,
        baked: &Baked,
        mode: Mode,
        view: BenchView,
    ) -> Result<PlayerMethod<'g>, BenchError> {
        let depth = mode == Mode::Depth;
        let target = FrameTarget::new(
            &gpu.adapter,
            &gpu.device,
            TargetConfig::readback(view.size, view.samples, mode),
        )?;
        let config = PlayerConfig {
            color_format: COLOR_FORMAT,
            depth_format: depth.then_some(DEPTH_FORMAT),
            sample_count: view.samples,
            size: view.size,
            mode,
            glass_opacity: Some(view.glass_opacity),
            draw_path: DrawPath::for_device(&gpu.adapter, &gpu.device),
            device: None,
            shading: trisort_gpu::Shading::Pbr,
            tone_map: trisort_gpu::ToneMap::Neutral,
            decode_textures: false,
        };
        let player = Player::new(&gpu.device, &gpu.queue, baked, config)?;
        let order = if mode.back_to_front() {
            Order::BackToFront
        } else {
            Order::FrontToBack
        };
        let ib = index_buffer(baked, order, true);
        let indices = (0..ib.len()).map(|k| ib.get(k)).collect();
        Ok(PlayerMethod {
            name: name.to_string(),
            variant,
            gpu,
            player,
            target,
            mode,
            indices,
        })
    }
}

impl Method for PlayerMethod<'_> {
    fn name(&self) -> &str {
        &self.name
    }
    fn mode(&self) -> Mode {
        self.mode
    }
    fn gpu(&self) -> &Gpu {
        self.gpu
    }
    fn variant(&self) -> String {
        self.variant.clone()
    }
    fn triangles(&self, frame: u32) -> u64 {
        self.player
            .frame_commands(frame)
            .iter()
            .map(|d| d.index_count as u64 / 3)
            .sum()
    }
    fn draws(&self, frame: u32) -> u32 {
        self.player.frame_commands(frame).len() as u32
    }
    fn stat_slots(&self, _frame: u32) -> u32 {
        1
    }
    fn encode(&self, enc: &mut wgpu::CommandEncoder, frame: u32, stats: Option<&wgpu::QuerySet>) {
        let mut pass = self.target.begin_pass(enc, clear_colour(self.mode), None);
        stats_begin(&mut pass, stats, 0);
        // Frames are checked against the window count when the methods are built.
        let _ = self.player.draw(&mut pass, frame);
        stats_end(&mut pass, stats);
    }
    fn image(&self, frame: u32) -> Result<Vec<u8>, BenchError> {
        Ok(self
            .target
            .read_rgba8(self.gpu, self.mode, |enc| self.encode(enc, frame, None))?)
    }
    fn streams(&self, frame: u32) -> Vec<Stream> {
        let mut indices = Vec::new();
        for d in self.player.frame_commands(frame) {
            let a = d.first_index as usize;
            indices.extend_from_slice(&self.indices[a..a + d.index_count as usize]);
        }
        vec![Stream {
            indices,
            depth: (self.mode == Mode::Depth).then_some(true),
            repeat: 1,
            per_sample: false,
        }]
    }
}

/// The `source` method's baked file: each frame's own visible set V_f, each triangle once, in
/// the merged order restricted to V_f (a topological order of the frame's graph, since the
/// merged order satisfies every edge the bake kept), drawn with one draw per frame.
///
/// `recording` must be the one `baked` was merged from (same G, every frame).
pub fn source_baked(baked: &Baked, recording: &Recording) -> Result<Baked, BenchError> {
    if recording.frames.len() != baked.frames.len() || recording.unique_visible != baked.scene_ids {
        return Err(BenchError::Invalid(format!(
            "the recording ({} frames, |G| = {}) is not the one the baked file ({} frames, |G| = {}) was merged from",
            recording.frames.len(),
            recording.unique_visible.len(),
            baked.frames.len(),
            baked.scene_ids.len()
        )));
    }
    let mut copies = Vec::new();
    let mut draws = Vec::new();
    let mut frames = Vec::new();
    let mut taken = vec![u32::MAX; baked.scene_ids.len()];
    for (f, (window, record)) in baked.frames.iter().zip(&recording.frames).enumerate() {
        let first = copies.len() as u32;
        let mut visible = vec![false; baked.scene_ids.len()];
        for &s in &record.visible {
            if let Ok(k) = baked.scene_ids.binary_search(&s) {
                visible[k] = true;
            }
        }
        let window_draws =
            &baked.draws[window.first as usize..(window.first + window.count) as usize];
        for d in window_draws {
            let a = d.first_index / 3;
            for c in a..a + d.index_count / 3 {
                let t = baked.copies[c as usize];
                if visible[t as usize] && taken[t as usize] != f as u32 {
                    taken[t as usize] = f as u32;
                    copies.push(t);
                }
            }
        }
        let n = copies.len() as u32 - first;
        frames.push(FrameWindow {
            first: draws.len() as u32,
            count: 1,
        });
        draws.push(DrawIndexedIndirectArgs {
            index_count: 3 * n,
            instance_count: 1,
            first_index: 3 * first,
            base_vertex: 0,
            first_instance: 0,
        });
    }
    Ok(Baked {
        copies,
        draws,
        frames,
        ..baked.clone()
    })
}

/// The `default` method in `blend` mode: [`DefaultRenderer`] (every triangle with the depth
/// test, opaque first, transparent unsorted).
pub struct DefaultMethod<'g> {
    gpu: &'g Gpu,
    renderer: DefaultRenderer<'g>,
    target: FrameTarget,
    streams: [Vec<u32>; 2],
}

impl<'g> DefaultMethod<'g> {
    /// Uploads the whole scene, lit by `environment` (the bake's).
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        environment: &trisort_format::Environment,
        view: BenchView,
    ) -> Result<DefaultMethod<'g>, BenchError> {
        let renderer = DefaultRenderer::new(
            gpu,
            geometry,
            frames,
            view.view(),
            trisort_gpu::Lighting::pbr(environment),
        )?;
        let target = FrameTarget::new(
            &gpu.adapter,
            &gpu.device,
            TargetConfig {
                depth: true,
                ..TargetConfig::readback(view.size, view.samples, Mode::Blend)
            },
        )?;
        let mut streams = [Vec::new(), Vec::new()];
        for (t, tri) in geometry.triangles.iter().enumerate() {
            streams[trisort_reference::default_pipeline::is_transparent(geometry, t) as usize]
                .extend_from_slice(tri);
        }
        Ok(DefaultMethod {
            gpu,
            renderer,
            target,
            streams,
        })
    }
}

impl Method for DefaultMethod<'_> {
    fn name(&self) -> &str {
        "default"
    }
    fn mode(&self) -> Mode {
        Mode::Blend
    }
    fn gpu(&self) -> &Gpu {
        self.gpu
    }
    fn variant(&self) -> String {
        "opaque then transparent unsorted, depth test".into()
    }
    fn triangles(&self, _frame: u32) -> u64 {
        let (o, t) = self.renderer.triangles();
        o as u64 + t as u64
    }
    fn draws(&self, _frame: u32) -> u32 {
        let (o, t) = self.renderer.triangles();
        (o > 0) as u32 + (t > 0) as u32
    }
    fn stat_slots(&self, _frame: u32) -> u32 {
        1
    }
    fn encode(&self, enc: &mut wgpu::CommandEncoder, frame: u32, stats: Option<&wgpu::QuerySet>) {
        let mut pass = self.target.begin_pass(enc, clear_colour(Mode::Blend), None);
        stats_begin(&mut pass, stats, 0);
        self.renderer.draw(&mut pass, frame);
        stats_end(&mut pass, stats);
    }
    fn image(&self, frame: u32) -> Result<Vec<u8>, BenchError> {
        Ok(self
            .target
            .read_rgba8(self.gpu, Mode::Blend, |enc| self.encode(enc, frame, None))?)
    }
    fn streams(&self, _frame: u32) -> Vec<Stream> {
        vec![
            Stream {
                indices: self.streams[0].clone(),
                depth: Some(true),
                repeat: 1,
                per_sample: false,
            },
            Stream {
                indices: self.streams[1].clone(),
                depth: Some(false),
                repeat: 1,
                per_sample: false,
            },
        ]
    }
}

/// The depth-mode `default`: every triangle in id order through the player with the depth test
/// (a plain z-buffer).
pub fn default_depth<'g>(
    gpu: &'g Gpu,
    geometry: &Geometry,
    frames: &[FrameState],
    settings: trisort_format::RecordSettings,
    environment: &trisort_format::Environment,
    view: BenchView,
) -> Result<PlayerMethod<'g>, BenchError> {
    let baked = whole_scene_baked(geometry, frames, settings, environment);
    PlayerMethod::new(
        "default",
        "all triangles, depth test".into(),
        gpu,
        &baked,
        Mode::Depth,
        view,
    )
}
