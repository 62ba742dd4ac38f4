//! The exact reference: what each frame should look like, against which a baked file's frames
//! are measured.
//!
//! `blend` and `saturate`: the *full* scene (every triangle, not only G) is peeled per sample
//! to completion with the recorder's own [`Peeler`] (same shader, same (depth, id) keys, same
//! per-sample targets). The layers are then composited in the mode's order (`blend`: back to
//! front; `saturate`: front to back, under) through the player's vertex shader, its
//! `player_colour`, its blend state and its `Rgba16Float` target, one render pass with one draw
//! per layer: each triangle of a layer writes only the samples where the peel found it in that
//! layer (`@builtin(sample_mask)`, see `shaders/reference/reference.wgsl`); shading stays per
//! pixel as in the player. The pass resolves MSAA like the headless player and the result is
//! quantized once with [`quantize_rgba16f`].
//!
//! Each sample's fragments are taken in the tie rule's order (`trisort_recorder::tie_rule`),
//! which the recorder followed: the peel's (depth, id) order, with pairs of triangles that lie
//! in one plane, or that one's plane separates, put as the rule says whatever their depths.
//!
//! `depth`: the player's depth mode draws front to back with the depth test (`Less`, depth
//! writes) and *over*, so a sample shows, composited in that order, every fragment nearer than
//! all those drawn before it. The reference lets through the same fragments of the rule's
//! order. For opaque scenes that is the nearest fragment (on an exact tie, the one the rule
//! puts first: the lower id unless the rule says otherwise), the plain z-buffer of all
//! triangles in ascending id order with `Less` ([`whole_scene_baked`] played in depth mode)
//! except at exact ties the rule breaks otherwise; with transparency the z-buffer in id order
//! blends a near transparent fragment over whatever farther fragment happened to have a lower
//! id, which no sorted front-to-back player draws, so it cannot be the reference there.
//!
//! The player draws only the triangles visible before saturation; the reference composites
//! every layer. What lies behind a saturated sample contributes at most the residual
//! transmittance (1 − threshold, 0.002 by default) to it.

use std::collections::HashSet;

use trisort_format::{
    Baked, DrawIndexedIndirectArgs, Environment, FrameState, FrameWindow, Geometry, RecordSettings,
    Recording,
};
use trisort_gpu::pipeline::{storage_entry, uniform_entry};
use trisort_gpu::scene_gpu::{Lighting, SceneGpu, ScenePipeline, View};
use trisort_gpu::Gpu;
use trisort_gpu::{clear_colour, halves, quantize_rgba16f, BACKGROUND, COLOR_FORMAT};
use trisort_player::{blend_state, Mode};
use trisort_recorder::tie_rule::{TieRule, Window};
use trisort_recorder::Peeler;
use wgpu::util::DeviceExt;

use crate::target::{check_pattern, lit_scene, Target};
use crate::ReferenceError;

/// The pattern and mode a reference frame is rendered at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceConfig {
    /// Image size (width, height).
    pub size: (u32, u32),
    /// MSAA samples (1 or 4).
    pub samples: u32,
    /// Compositing mode.
    pub mode: Mode,
    /// Opacity of transmissive glass.
    pub glass_opacity: f32,
    /// Safety bound on peel layers; a frame that hits it is reported truncated.
    pub max_layers: u32,
}

impl ReferenceConfig {
    /// A baked file's recorded pattern (size, samples, glass opacity) in `mode`, with a layer
    /// bound of 4096.
    pub fn recorded(baked: &Baked, mode: Mode) -> ReferenceConfig {
        ReferenceConfig {
            size: (baked.settings.width, baked.settings.height),
            samples: baked.settings.samples.max(1),
            mode,
            glass_opacity: baked.settings.glass_opacity,
            max_layers: 4096,
        }
    }

    fn view(&self) -> View {
        View {
            width: self.size.0,
            height: self.size.1,
            samples: self.samples,
            glass_opacity: self.glass_opacity,
        }
    }
}

/// The edges whose samples the image check may excuse, by scene id: a sample is *unordered*
/// when two consecutive fragments of the peel of G there, a then b, form one of them.
///
/// [`UnorderedEdges::of_recordings`] derives them from the recordings alone: the edges of E_f that
/// lie on a cycle (both ends in one strongly connected component, [`trisort_verify::cycle_edges`]),
/// the only ones any bake may leave unordered (rule 3 of [`trisort_verify::check_graph`]).
/// Verification uses nothing else; without a recording no sample is excused.
/// [`UnorderedEdges::of_baked`] takes the edges a baked file says its merger removed, for
/// measurements that describe that bake (`bench`), never to verify it.
pub struct UnorderedEdges {
    /// Per scene triangle: whether it is in G (the peel of G skips the others).
    in_g: Vec<bool>,
    /// Per frame: the edges (scene ids).
    per_frame: Vec<HashSet<(u32, u32)>>,
    /// Per frame: their total weight in samples.
    recorded: Vec<u64>,
    /// Per frame: the triangles the player draws there (scene ids, ascending), the only ones
    /// the tie rule may move up (`TieRule::moving_only`): the recording's V_f, or the
    /// triangles of the baked frame's draws.
    drawn: Vec<Vec<u32>>,
}

impl UnorderedEdges {
    /// Per frame of `recordings` (frame ranges of one path, any order), the edges of E_f on a
    /// cycle of E_f; with `depth_mode` (a depth-only bake checked in depth mode), of the edges
    /// depth mode needs ([`Recording::depth_mode_edges`]), all that such a bake keeps. Errors
    /// when a recording names scene ids beyond the scene's `scene_triangles`.
    pub fn of_recordings(
        recordings: &[Recording],
        depth_mode: bool,
        scene_triangles: usize,
    ) -> Result<UnorderedEdges, ReferenceError> {
        let mut edges = UnorderedEdges::empty(scene_triangles);
        for r in recordings {
            edges.add_g(&r.unique_visible, "a recording")?;
            for fr in &r.frames {
                let depth_edges;
                let source = if depth_mode {
                    depth_edges = r.depth_mode_edges(fr);
                    &depth_edges
                } else {
                    &fr.edges
                };
                edges.set_drawn(fr.frame as usize, fr.visible.clone());
                edges.set_frame(
                    fr.frame as usize,
                    trisort_verify::cycle_edges(source)
                        .iter()
                        .map(|e| (e.from, e.to, e.weight)),
                );
            }
        }
        Ok(edges)
    }

    /// The edges `baked` says its merger removed, for a scene of `scene_triangles` triangles.
    /// Errors when the file names scene ids the scene lacks.
    pub fn of_baked(
        baked: &Baked,
        scene_triangles: usize,
    ) -> Result<UnorderedEdges, ReferenceError> {
        let mut edges = UnorderedEdges::empty(scene_triangles);
        edges.add_g(&baked.scene_ids, "the baked file")?;
        let scene = |t: u32| baked.scene_ids.get(t as usize).copied().unwrap_or(u32::MAX);
        let drawn = DrawnSets::new(baked);
        for (f, removed) in baked.removed_edges.iter().enumerate() {
            edges.set_drawn(f, drawn.of_frame(f).collect());
            edges.set_frame(
                f,
                removed
                    .iter()
                    .map(|e| (scene(e.from), scene(e.to), e.weight)),
            );
        }
        Ok(edges)
    }

    /// `pairs` (scene ids, either order) in each of `frames` frames, over a scene of
    /// `scene_triangles` triangles, every one of them in G and none moved by the tie rule: for
    /// a renderer that orders by geometry where the rasterizer's depths may not, e.g. two
    /// triangles that meet at an edge or a corner, whose depths there differ by rounding
    /// alone. The caller derives the pairs from the scene, not from the file it checks.
    pub fn of_pairs(
        scene_triangles: usize,
        frames: usize,
        pairs: &[(u32, u32)],
    ) -> Result<UnorderedEdges, ReferenceError> {
        let mut edges = UnorderedEdges::empty(scene_triangles);
        let all: Vec<u32> = (0..scene_triangles as u32).collect();
        edges.add_g(&all, "the scene")?;
        if let Some(&(a, b)) = pairs
            .iter()
            .find(|(a, b)| a.max(b) >= &(scene_triangles as u32))
        {
            return Err(ReferenceError::Invalid(format!(
                "pair ({a}, {b}) names a triangle beyond the scene's {scene_triangles}"
            )));
        }
        for f in 0..frames {
            edges.set_drawn(f, Vec::new());
            edges.set_frame(f, pairs.iter().flat_map(|&(a, b)| [(a, b, 0), (b, a, 0)]));
        }
        Ok(edges)
    }

    fn empty(scene_triangles: usize) -> UnorderedEdges {
        UnorderedEdges {
            in_g: vec![false; scene_triangles],
            per_frame: Vec::new(),
            recorded: Vec::new(),
            drawn: Vec::new(),
        }
    }

    /// Frame `f`'s drawn triangles (scene ids, any order, repeats allowed): kept sorted and
    /// without repeats.
    fn set_drawn(&mut self, f: usize, mut drawn: Vec<u32>) {
        if self.drawn.len() <= f {
            self.drawn.resize_with(f + 1, Vec::new);
        }
        drawn.sort_unstable();
        drawn.dedup();
        self.drawn[f] = drawn;
    }

    /// Marks the members of `g` (scene ids, from `what`) as triangles of G.
    fn add_g(&mut self, g: &[u32], what: &str) -> Result<(), ReferenceError> {
        let n = self.in_g.len();
        for &s in g {
            *self.in_g.get_mut(s as usize).ok_or_else(|| {
                ReferenceError::Invalid(format!(
                    "{what} names scene triangle {s}; the scene has {n}"
                ))
            })? = true;
        }
        Ok(())
    }

    /// Frame `f`'s edges `(from, to, weight)` in scene ids.
    fn set_frame(&mut self, f: usize, edges: impl Iterator<Item = (u32, u32, u32)>) {
        if self.per_frame.len() <= f {
            self.per_frame.resize_with(f + 1, HashSet::new);
            self.recorded.resize(f + 1, 0);
        }
        let (mut set, mut weight) = (HashSet::new(), 0u64);
        for (a, b, w) in edges {
            set.insert((a, b));
            weight += w as u64;
        }
        self.per_frame[f] = set;
        self.recorded[f] = weight;
    }

    /// The edges' total weight in frame `f`: the unordered samples the recording (or the
    /// file, for [`UnorderedEdges::of_baked`]) counts there.
    pub fn recorded_weight(&self, f: u32) -> u64 {
        self.recorded.get(f as usize).copied().unwrap_or(0)
    }
}

/// One frame of the exact reference.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceFrame {
    /// Frame index.
    pub frame: u32,
    /// `width × height` pixels, RGBA8, sRGB-encoded, alpha 255 (as [`quantize_rgba16f`]).
    pub rgba8: Vec<u8>,
    /// Per pixel: whether it has an unordered sample (all false without [`UnorderedEdges`]).
    pub unordered: Vec<bool>,
    /// Number of samples whose consecutive fragments form one of the [`UnorderedEdges`], as
    /// the peel finds them.
    pub unordered_samples: u64,
    /// Peel layers peeled (`blend` and `saturate` to the end; `depth` until every sample's
    /// nearest fragment has come out of the tie rule's window, or to the end where the frame
    /// has unordered edges to find).
    pub layers: u32,
    /// Whether the peel stopped at `max_layers` with fragments left.
    pub truncated: bool,
    /// Per sample (`pixel · samples + s`): the scene id + 1 of the first fragment composited
    /// (the nearest in the tie rule's order; in `depth`, the first the depth test passes)
    /// that is not of a triangle whose every fragment has alpha 0; 0 where the sample has
    /// none. What a verifier tells holes by.
    pub front: Vec<u32>,
}

/// The triangles each frame of a baked file draws, by scene id: the scene id of every copy,
/// and per frame its draws' copy ranges (compact however long the path).
pub(crate) struct DrawnSets {
    /// Scene id of each copy (`u32::MAX` for a G-local id outside `scene_ids`).
    copies: Vec<u32>,
    /// Per frame: half-open copy ranges.
    frames: Vec<Vec<(u32, u32)>>,
}

impl DrawnSets {
    pub(crate) fn new(baked: &Baked) -> DrawnSets {
        let scene = |t: u32| baked.scene_ids.get(t as usize).copied().unwrap_or(u32::MAX);
        DrawnSets {
            copies: baked.copies.iter().map(|&t| scene(t)).collect(),
            frames: (0..baked.frames.len())
                .map(|f| {
                    baked
                        .frame_draws(f)
                        .iter()
                        .map(|d| (d.first_index / 3, (d.first_index + d.index_count) / 3))
                        .collect()
                })
                .collect(),
        }
    }

    /// The scene ids frame `f` draws, in draw order (with repeats where it draws a triangle
    /// twice).
    pub(crate) fn of_frame(&self, f: usize) -> impl Iterator<Item = u32> + '_ {
        self.frames
            .get(f)
            .map(Vec::as_slice)
            .unwrap_or(&[])
            .iter()
            .flat_map(|&(a, b)| self.copies.get(a as usize..b as usize).unwrap_or(&[]))
            .copied()
    }
}

/// Composite-pass resources of one layer.
struct LayerDraw {
    bind_group: wgpu::BindGroup,
    index: wgpu::Buffer,
    triangles: u32,
}

/// The exact reference renderer for one scene at one pattern and mode.
pub struct ExactReference<'g> {
    gpu: &'g Gpu,
    config: ReferenceConfig,
    /// Every scene triangle (vertex indices), to build each layer's index list.
    triangles: Vec<[u32; 3]>,
    /// The scene's positions, triangles and nodes with the path's frames: the tie rule's
    /// planes ([`TieRule`]).
    shape: Geometry,
    frames: Vec<FrameState>,
    /// Per scene triangle: whether every fragment of it has alpha 0 (glass at opacity 0, a
    /// blend material of alpha 0): it is composited but shows nothing, so it is no sample's
    /// front ([`ReferenceFrame::front`]).
    clear: Vec<bool>,
    peeler: Peeler<'g>,
    scene: SceneGpu,
    pipeline: wgpu::RenderPipeline,
    composite_layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    target: Target,
}

/// A baked file that draws every triangle of `geometry` in ascending id order in every frame
/// (front-to-back playback is the stored order): played by the player in `depth` mode it is
/// the plain z-buffer of all triangles in id order (equal to the `depth` reference on opaque
/// scenes), lit by `environment` (the bake's, so it lights like the bake).
pub fn whole_scene_baked(
    geometry: &Geometry,
    frames: &[FrameState],
    settings: RecordSettings,
    environment: &Environment,
) -> Baked {
    let n = geometry.triangles.len() as u32;
    let frame_count = frames.len() as u32;
    Baked {
        tool_version: trisort_format::TOOL_VERSION.to_string(),
        scene_hash: [0; 32],
        path_hash: [0; 32],
        recording_hashes: vec![],
        settings,
        device: Default::default(),
        merge: Default::default(),
        stats: Default::default(),
        geometry: geometry.clone(),
        scene_ids: (0..n).collect(),
        copies: (0..n).collect(),
        draws: (0..frame_count)
            .map(|_| DrawIndexedIndirectArgs {
                index_count: 3 * n,
                instance_count: 1,
                first_index: 0,
                base_vertex: 0,
                first_instance: 0,
            })
            .collect(),
        frames: (0..frame_count)
            .map(|f| FrameWindow { first: f, count: 1 })
            .collect(),
        frame_states: frames.to_vec(),
        removed_edges: vec![vec![]; frames.len()],
        fps: None,
        environment: environment.clone(),
        clips: vec![trisort_format::Clip::whole(frame_count, None, [0; 32])],
    }
}

impl<'g> ExactReference<'g> {
    /// Uploads the full scene `geometry` with the path's `frames` for rendering at `config`,
    /// lit as `lighting` says (a baked file's environment and the player's shading, so the
    /// reference lights like the player it checks). Errors where the device lacks what the
    /// peeler needs (`PRIMITIVE_INDEX`, multisampled integer targets) or cannot multisample
    /// the targets.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        lighting: Lighting<'_>,
        config: ReferenceConfig,
    ) -> Result<ExactReference<'g>, ReferenceError> {
        check_pattern(config.size, config.samples)?;
        let all: Vec<u32> = (0..geometry.triangles.len() as u32).collect();
        let view = config.view();
        // Depths too: the tie rule keeps exact ties in the peel's order.
        let peeler = Peeler::new(gpu, geometry, &all, frames, view)?.with_readback(false, true);
        let device = &gpu.device;
        let shading = lighting.shading;
        let scene = lit_scene(gpu, geometry, frames, view, lighting);
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let composite_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("reference composite"),
            entries: &[
                uniform_entry(0, fragment, false, Some(16)),
                storage_entry(1, fragment, true),
                storage_entry(2, fragment, true),
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("reference composite"),
            source: wgpu::ShaderSource::Wgsl(trisort_gpu::reference_shader().into()),
        });
        // The fragment outputs of `trisort_player::fragment_entry_point(mode)`, masked.
        let entry = match config.mode {
            Mode::Saturate => "fs_reference_premultiplied",
            Mode::Blend | Mode::Depth => "fs_reference_straight",
        };
        // The player's pipeline state (shared `ScenePipeline`: CCW, no hardware culling, its
        // MSAA count, no depth test in blend and saturate) with the reference's fragment
        // entry point and the player's blend state.
        let pipeline = ScenePipeline {
            label: "reference composite",
            layouts: &[&scene.layout, &composite_layout],
            module: &module,
            vertex: "vs_player",
            fragment: entry,
            target: wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                blend: Some(blend_state(config.mode)),
                write_mask: wgpu::ColorWrites::ALL,
            },
            depth: None,
            samples: config.samples,
        }
        .build_shaded(device, shading);
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("reference composite params"),
            contents: bytemuck::cast_slice(&[config.size.0, config.samples, 0, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let target = Target::new(gpu, config.size, config.samples, COLOR_FORMAT, false)?;
        Ok(ExactReference {
            gpu,
            config,
            triangles: geometry.triangles.clone(),
            shape: Geometry {
                vertices: geometry.vertices.clone(),
                triangles: geometry.triangles.clone(),
                nodes: geometry.nodes.clone(),
                ..Geometry::default()
            },
            frames: frames.to_vec(),
            clear: (0..geometry.triangles.len() as u32)
                .map(|t| {
                    geometry
                        .materials
                        .get(geometry.triangle_material(t) as usize)
                        .is_some_and(|m| m.factor_opacity(config.glass_opacity) <= 0.0)
                })
                .collect(),
            peeler,
            scene,
            pipeline,
            composite_layout,
            params,
            target,
        })
    }

    /// Shifts every frame's projection by `offset` pixels (x right, y down), in the peel and
    /// in the compositing pass alike: the exact reference of a player shifted the same way
    /// ([`trisort_player::Player::set_subpixel_offset`]). `[0.0, 0.0]` restores it.
    pub fn set_subpixel_offset(&self, offset: [f64; 2]) {
        self.peeler.set_subpixel_offset(offset);
        self.scene.set_subpixel_offset(&self.gpu.queue, offset);
    }

    /// The configuration.
    pub fn config(&self) -> &ReferenceConfig {
        &self.config
    }

    /// The tie rule of frame `frame` over the whole scene, moving only the triangles
    /// `unordered` says the frame draws.
    fn tie_rule(
        &self,
        frame: u32,
        unordered: Option<&UnorderedEdges>,
    ) -> Result<TieRule, ReferenceError> {
        let state = self
            .frames
            .get(frame as usize)
            .ok_or_else(|| ReferenceError::Invalid(format!("frame {frame} is beyond the path")))?;
        let all: Vec<u32> = (0..self.triangles.len() as u32).collect();
        // Without a recording (or a file's draws) the rule moves nothing: the rasterizer's order.
        let mut moves = vec![false; all.len()];
        if let Some(d) = unordered.and_then(|r| r.drawn.get(frame as usize)) {
            for &t in d {
                if let Some(m) = moves.get_mut(t as usize) {
                    *m = true;
                }
            }
        }
        Ok(TieRule::new(&self.shape, &all, state).moving_only(moves))
    }

    /// Renders frame `frame`. With `unordered`, also finds the unordered samples of the frame.
    pub fn render(
        &self,
        frame: u32,
        unordered: Option<&UnorderedEdges>,
    ) -> Result<ReferenceFrame, ReferenceError> {
        let (w, h) = self.config.size;
        let pixels = w as usize * h as usize;
        let depth_mode = self.config.mode == Mode::Depth;
        let samples = self.config.samples as usize;
        let slots = self.peeler.slots();
        let mut layer_ids: Vec<Vec<u32>> = Vec::new();
        // Per sample: the scene id + 1 of its last fragment of G (0: none yet).
        let mut last_g = vec![0u32; if unordered.is_some() { slots } else { 0 }];
        let mut unordered_sample = vec![false; pixels];
        let mut unordered_samples = 0u64;
        let no_edges = HashSet::new();
        let edges = unordered.map(|r| r.per_frame.get(frame as usize).unwrap_or(&no_edges));
        // Every mode takes each sample's fragments in the tie rule's
        // order, which the recorder followed (`trisort_recorder::tie_rule`): they go through a
        // window as they come, and the k-th to leave it goes to composited layer k (in `depth`,
        // the k-th that the depth test lets through).
        let rule = self.tie_rule(frame, unordered)?;
        let mut windows = vec![Window::default(); slots];
        let mut placed = vec![0u32; slots];
        // `depth`: the player draws a sample's fragments in that order with the depth test
        // (`Less`, depth writes, cleared to 1): a fragment shows, *over* what came before, where
        // it is nearer than every fragment drawn before it. Per sample, the depth written so far.
        let mut written = vec![1.0f32; if depth_mode { slots } else { 0 }];
        // `depth` needs a sample's fragments only until its nearest one (its first peel layer)
        // has come out of the rule's window: nothing after it passes the depth test. Per
        // sample, that nearest depth (NaN once it came out, or where the sample has none), and
        // how many samples still wait for it; the peel stops when none does.
        let gate =
            std::cell::RefCell::new((vec![f32::NAN; if depth_mode { slots } else { 0 }], 0usize));
        let mut front = vec![0u32; slots];
        let clear = &self.clear;
        let mut settle = |i: usize, (id, depth): (u32, f32), layer_ids: &mut Vec<Vec<u32>>| {
            if let (Some(r), Some(edges)) = (unordered, edges) {
                if r.in_g.get((id - 1) as usize) == Some(&true) {
                    let prev = last_g[i];
                    if prev != 0 && edges.contains(&(prev - 1, id - 1)) {
                        unordered_samples += 1;
                        unordered_sample[i / samples] = true;
                    }
                    last_g[i] = id;
                }
            }
            if depth_mode {
                let (nearest, waiting) = &mut *gate.borrow_mut();
                if depth == nearest[i] {
                    nearest[i] = f32::NAN;
                    *waiting -= 1;
                }
                if depth.partial_cmp(&written[i]) != Some(std::cmp::Ordering::Less) {
                    return;
                }
                written[i] = depth;
            }
            if front[i] == 0 && !clear.get((id - 1) as usize).copied().unwrap_or(false) {
                front[i] = id;
            }
            let k = placed[i] as usize;
            placed[i] += 1;
            if layer_ids.len() <= k {
                layer_ids.push(vec![0; slots]);
            }
            layer_ids[k][i] = id;
        };
        let (layers, truncated) =
            self.peeler
                .peel(frame, self.config.max_layers, |k, layer, _| {
                    if depth_mode && k == 0 {
                        let (nearest, waiting) = &mut *gate.borrow_mut();
                        for (i, &id) in layer.ids.iter().enumerate() {
                            if id != 0 {
                                nearest[i] = layer.depth[i];
                                *waiting += 1;
                            }
                        }
                    }
                    for (i, &id) in layer.ids.iter().enumerate() {
                        if id == 0 {
                            // The sample's list has ended: in depth mode its window can empty
                            // now (the others empty after the peel).
                            if depth_mode && !gate.borrow().0[i].is_nan() {
                                for (p, d) in windows[i].drain() {
                                    settle(i, (p + 1, d), &mut layer_ids);
                                }
                            }
                            continue;
                        }
                        if let Some((p, d)) = rule.push(&mut windows[i], (id - 1, layer.depth[i])) {
                            settle(i, (p + 1, d), &mut layer_ids);
                        }
                    }
                    // Blend and saturate composite every layer; depth peels on only while a
                    // sample waits for its nearest fragment, or to find unordered samples.
                    let finding = edges.is_some_and(|e| !e.is_empty());
                    Ok(!depth_mode || finding || gate.borrow().1 > 0)
                })?;
        for (i, w) in windows.iter_mut().enumerate() {
            for (p, d) in w.drain() {
                settle(i, (p + 1, d), &mut layer_ids);
            }
        }
        let draws = self.layer_draws(&layer_ids)?;
        let order: Vec<&LayerDraw> = match self.config.mode {
            Mode::Blend => draws.iter().rev().collect(),
            Mode::Depth | Mode::Saturate => draws.iter().collect(),
        };
        let (target, scene, pipeline) = (&self.target, &self.scene, &self.pipeline);
        let bytes = target.render(self.gpu, clear_colour(self.config.mode), |pass| {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &scene.bind_group, &scene.offsets(frame));
            pass.set_vertex_buffer(0, scene.vertices.slice(..));
            for d in order {
                pass.set_bind_group(1, &d.bind_group, &[]);
                pass.set_index_buffer(d.index.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..d.triangles * 3, 0, 0..1);
            }
            Ok(())
        })?;
        let under = (self.config.mode == Mode::Saturate).then_some(BACKGROUND);
        Ok(ReferenceFrame {
            frame,
            rgba8: quantize_rgba16f(&halves(&bytes), under),
            unordered: unordered_sample,
            unordered_samples,
            layers,
            truncated,
            front,
        })
    }

    /// Per layer: its ids as a storage buffer, the index list of the triangles it holds
    /// (ascending id) and their ids.
    fn layer_draws(&self, layers: &[Vec<u32>]) -> Result<Vec<LayerDraw>, ReferenceError> {
        let device = &self.gpu.device;
        let (layout, params) = (&self.composite_layout, &self.params);
        let mut seen = vec![u32::MAX; self.triangles.len()];
        let mut out = Vec::with_capacity(layers.len());
        for (k, ids) in layers.iter().enumerate() {
            let mut tris: Vec<u32> = Vec::new();
            for &id in ids {
                if id == 0 {
                    continue;
                }
                let t = (id - 1) as usize;
                let s = seen.get_mut(t).ok_or_else(|| {
                    ReferenceError::Invalid(format!("peel returned triangle {t} beyond the scene"))
                })?;
                if *s != k as u32 {
                    *s = k as u32;
                    tris.push(t as u32);
                }
            }
            tris.sort_unstable();
            let mut index: Vec<u32> = Vec::with_capacity(tris.len() * 3);
            for &t in &tris {
                index.extend_from_slice(&self.triangles[t as usize]);
            }
            if tris.is_empty() {
                tris.push(0);
                index.extend_from_slice(&[0, 0, 0]);
            }
            let buffer = |label, contents: &[u8], usage| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage,
                })
            };
            let ids_buf = buffer(
                "reference layer ids",
                bytemuck::cast_slice(ids),
                wgpu::BufferUsages::STORAGE,
            );
            let draw_ids = buffer(
                "reference layer triangles",
                bytemuck::cast_slice(&tris),
                wgpu::BufferUsages::STORAGE,
            );
            let index_buf = buffer(
                "reference layer indices",
                bytemuck::cast_slice(&index),
                wgpu::BufferUsages::INDEX,
            );
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("reference layer"),
                layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: params.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: ids_buf.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: draw_ids.as_entire_binding(),
                    },
                ],
            });
            out.push(LayerDraw {
                bind_group,
                index: index_buf,
                triangles: (index.len() / 3) as u32,
            });
        }
        Ok(out)
    }
}
