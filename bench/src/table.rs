//! One row of the method comparison per (samples, mode, method): the paper's Table 1 with
//! device-independent counts and the error against the exact reference added.
//!
//! [`run_group`] builds every method that applies to one sample count and mode, renders the
//! exact reference of each measured frame once, compares every method's image with it, counts
//! triangles, draws, pipeline statistics and overdraw, then times all methods interleaved
//! ([`crate::harness::time_methods`]) so the ratios within a group come from one run.

use serde::Serialize;
use trisort_format::{Baked, FrameState, Geometry};
use trisort_gpu::Gpu;
use trisort_player::{config::DrawPath, Mode};
use trisort_reference::{compare, ExactReference, ReferenceConfig, ReferenceError, UnorderedEdges};

use crate::harness::{pipeline_statistics, time_methods, FragmentCounter, Summary, Timing};
use crate::methods::{default_depth, BenchView, DefaultMethod, Method, PlayerMethod};
use crate::BenchError;

/// The methods a group may run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MethodKind {
    /// Every triangle with the depth test (unsorted transparency).
    Default,
    /// Each frame's own sorted visible set, one draw.
    Source,
    /// The baked sliding window, one multi-draw-indirect.
    Merged,
    /// Per-sample linked-list OIT.
    Oit,
    /// Exact GPU depth peeling.
    Peeling,
    /// Depth-presorted lists for free viewpoints (paper 000).
    Presorted,
    /// Objects ordered by occlusion queries every frame (paper 004).
    #[serde(rename = "occlusion-query")]
    OcclusionQuery,
}

impl MethodKind {
    /// All methods, in table order.
    pub const ALL: [MethodKind; 7] = [
        MethodKind::Default,
        MethodKind::Source,
        MethodKind::Merged,
        MethodKind::Oit,
        MethodKind::Peeling,
        MethodKind::Presorted,
        MethodKind::OcclusionQuery,
    ];

    /// The name used on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            MethodKind::Default => "default",
            MethodKind::Source => "source",
            MethodKind::Merged => "merged",
            MethodKind::Oit => "oit",
            MethodKind::Peeling => "peeling",
            MethodKind::Presorted => "presorted",
            MethodKind::OcclusionQuery => "occlusion-query",
        }
    }

    /// Parses a name.
    pub fn parse(s: &str) -> Option<MethodKind> {
        MethodKind::ALL.into_iter().find(|m| m.name() == s)
    }

    /// Whether the method renders `mode` (OIT and occlusion-query: blend only; default and
    /// peeling: no saturate).
    pub fn supports(self, mode: Mode) -> bool {
        match self {
            MethodKind::Source | MethodKind::Merged | MethodKind::Presorted => true,
            MethodKind::Oit | MethodKind::OcclusionQuery => mode == Mode::Blend,
            MethodKind::Default | MethodKind::Peeling => mode != Mode::Saturate,
        }
    }
}

/// What one group measures.
pub struct GroupInput<'a> {
    /// The scene's full geometry.
    pub geometry: &'a Geometry,
    /// Every frame of the path.
    pub frame_states: &'a [FrameState],
    /// The bake played by `merged`, recorded at this group's sample count.
    pub baked: &'a Baked,
    /// The `source` method's bake: [`crate::methods::source_baked`] of `baked` (made once per
    /// bake by the caller, shared by its groups).
    pub source: &'a Baked,
    /// Size, samples and glass opacity of playback.
    pub view: BenchView,
    /// Compositing mode.
    pub mode: Mode,
    /// Methods to run (those that do not support `mode` are left out).
    pub methods: &'a [MethodKind],
    /// Frames to measure.
    pub frames: &'a [u32],
    /// Timed repetitions per frame and method.
    pub repeats: u32,
    /// Also time `merged` on a device with wgpu's indirect-call validation off.
    pub unvalidated: Option<&'a Gpu>,
    /// Also play `merged` on this device (`bench --backend/--limits`): the method
    /// `merged_device`, on the tier and draw path the device allows.
    pub other_device: Option<&'a Gpu>,
    /// The file the `presorted` methods play (`None`: they presort `geometry` themselves).
    pub presorted: Option<&'a trisort_format::Presorted>,
}

/// Error of one method's frames against the exact reference.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ErrorSummary {
    /// Frames identical to the reference on every ordered pixel.
    pub frames_exact: u32,
    /// Frames compared.
    pub frames: u32,
    /// Mean over frames of the fraction of pixels with any channel different.
    pub pixels_differing_fraction: f64,
    /// Mean over frames of the fraction of *ordered* pixels (no unordered sample of the
    /// merged bake) with any channel different.
    pub pixels_differing_ordered_fraction: f64,
    /// Largest channel difference over all frames, in 1/255.
    pub max_channel_diff: u8,
    /// Mean LDR-FLIP over frames.
    pub flip_mean: f64,
    /// Smallest PSNR over frames (dB; 100 for identical).
    pub psnr_min: f64,
}

/// One method in one group.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MethodRow {
    /// Method name; `merged_unvalidated` for the merged player with indirect validation off.
    pub method: String,
    /// What configuration it ran (e.g. OIT's budget).
    pub variant: String,
    /// Mode.
    pub mode: String,
    /// MSAA samples.
    pub samples: u32,
    /// The headline time per frame (ms): GPU timestamps where the device has them, else wall.
    pub ms_per_frame: f64,
    /// 95th percentile of the headline time.
    pub ms_p95: f64,
    /// Maximum of the headline time.
    pub ms_max: f64,
    /// GPU timestamp times.
    pub gpu_ms: Option<Summary>,
    /// Wall times (encode, submit, wait).
    pub wall_ms: Summary,
    /// Per measured frame: mean headline ms.
    pub ms_along_path: Vec<(u32, f64)>,
    /// Mean triangles submitted per frame.
    pub triangles_per_frame: f64,
    /// Mean draw commands per frame.
    pub draws_per_frame_mean: f64,
    /// Largest draw commands in a frame.
    pub draws_per_frame_max: u32,
    /// Mean fragment-shader invocations per frame as the device counts them (pipeline
    /// statistics; lavapipe counts rasterized fragments).
    pub fragment_invocations_per_frame: Option<f64>,
    /// Mean vertex-shader invocations per frame (pipeline statistics).
    pub vertex_invocations_per_frame: Option<f64>,
    /// Mean fragments shaded per frame (the counting pass: fragments passing the depth test
    /// in submission order, times layers and, for per-sample shading, samples).
    pub fragments_shaded_per_frame: f64,
    /// Mean pixels covered per frame (counting pass).
    pub pixels_covered_per_frame: f64,
    /// `fragments_shaded / pixels_covered` (mean over frames).
    pub overdraw: f64,
    /// Error against the exact reference.
    pub error: ErrorSummary,
    /// The occlusion-query method's sort: queries, readbacks and cycles per frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub occlusion_queries: Option<crate::vis_sort::QueryStats>,
}

/// A group's rows, methods in table order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GroupReport {
    /// MSAA samples.
    pub samples: u32,
    /// Mode.
    pub mode: String,
    /// Rows.
    pub rows: Vec<MethodRow>,
    /// Methods left out because the device cannot run them at this configuration.
    pub skipped: Vec<Skipped>,
}

/// A method left out of a group.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Skipped {
    /// Method name.
    pub method: String,
    /// Why (the renderer's message).
    pub why: String,
}

impl GroupReport {
    /// The row of `method`.
    pub fn row(&self, method: &str) -> Option<&MethodRow> {
        self.rows.iter().find(|r| r.method == method)
    }

    /// `merged` over `source` headline time (the paper reports 1.35–2.7).
    pub fn merged_over_source(&self) -> Option<f64> {
        Some(self.row("merged")?.ms_per_frame / self.row("source")?.ms_per_frame)
    }
}

/// Runs one group: builds its methods, measures each frame's error and counts against the
/// exact reference, times the methods interleaved, and returns one row per method.
/// `progress(message)` reports each step.
pub fn run_group(
    gpu: &Gpu,
    input: &GroupInput<'_>,
    progress: &dyn Fn(&str),
) -> Result<GroupReport, BenchError> {
    let (methods, skipped) = build_methods(gpu, input, progress)?;
    let counts = count_frames(gpu, input, &methods, progress)?;

    progress("timing");
    let refs: Vec<&dyn Method> = methods.iter().map(|m| m.as_ref()).collect();
    let timings = time_methods(&refs, input.frames, input.repeats, &|done, total| {
        if done % methods.len().max(1) == 0 {
            progress(&format!("timing: {done}/{total} calls"));
        }
    })?;
    let rows = methods
        .iter()
        .zip(counts)
        .zip(timings)
        .map(|((m, c), t)| c.row(m.as_ref(), input, &t))
        .collect();
    Ok(GroupReport {
        samples: input.view.samples,
        mode: input.mode.name().into(),
        rows,
        skipped,
    })
}

/// A group's methods, in table order.
type Methods<'a> = Vec<Box<dyn Method + 'a>>;

/// The group's methods that support its mode, in table order, and the rivals left out
/// because the device cannot run them at this configuration.
fn build_methods<'a>(
    gpu: &'a Gpu,
    input: &GroupInput<'a>,
    progress: &dyn Fn(&str),
) -> Result<(Methods<'a>, Vec<Skipped>), BenchError> {
    let view = input.view;
    let mode = input.mode;
    let mut methods: Methods<'a> = Vec::new();
    let mut skipped = Vec::new();
    for &kind in input.methods {
        if !kind.supports(mode) {
            continue;
        }
        progress(&format!("building {}", kind.name()));
        match kind {
            MethodKind::Default => {
                let m: Box<dyn Method> = if mode == Mode::Depth {
                    Box::new(default_depth(
                        gpu,
                        input.geometry,
                        input.frame_states,
                        input.baked.settings,
                        &input.baked.environment,
                        view,
                    )?)
                } else {
                    Box::new(DefaultMethod::new(
                        gpu,
                        input.geometry,
                        input.frame_states,
                        &input.baked.environment,
                        view,
                    )?)
                };
                methods.push(m);
            }
            MethodKind::Source => methods.push(Box::new(PlayerMethod::new(
                "source",
                "V_f only, one draw".into(),
                gpu,
                input.source,
                mode,
                view,
            )?)),
            MethodKind::Merged => {
                methods.push(Box::new(PlayerMethod::new(
                    "merged",
                    "indirect validation on (wgpu default)".into(),
                    gpu,
                    input.baked,
                    mode,
                    view,
                )?));
                if let Some(g) = input.unvalidated {
                    methods.push(Box::new(PlayerMethod::new(
                        "merged_unvalidated",
                        "indirect validation off".into(),
                        g,
                        input.baked,
                        mode,
                        view,
                    )?));
                }
                if let Some(g) = input.other_device {
                    let tier = trisort_gpu::Bindings::for_limits(&g.device.limits());
                    let path = DrawPath::for_device(&g.adapter, &g.device);
                    methods.push(Box::new(PlayerMethod::new(
                        "merged_device",
                        format!(
                            "{:?} backend, {} bindings, {} draws",
                            g.info.backend,
                            tier.name(),
                            path.name()
                        ),
                        g,
                        input.baked,
                        mode,
                        view,
                    )?));
                }
            }
            MethodKind::Oit
            | MethodKind::Peeling
            | MethodKind::Presorted
            | MethodKind::OcclusionQuery => {
                match crate::rivals::build(kind, gpu, input, progress) {
                    Ok(built) => methods.extend(built),
                    // A rival the device cannot run at this size (OIT's node pool over the
                    // storage-buffer limit) is left out of the table, saying why, rather
                    // than losing the other methods' figures.
                    Err(BenchError::Reference(ReferenceError::Unsupported(why))) => {
                        progress(&format!("leaving out {}: {why}", kind.name()));
                        skipped.push(Skipped {
                            method: kind.name().into(),
                            why,
                        });
                    }
                    Err(e) => return Err(e),
                }
            }
        }
    }
    Ok((methods, skipped))
}

/// One method's error and counts, summed over the measured frames.
struct Counts {
    errors: ErrorSummary,
    triangles: f64,
    draws: f64,
    draws_max: u32,
    /// Pipeline-statistics invocations; `None` where the device has no such queries.
    fragments_dev: Option<f64>,
    vertices_dev: Option<f64>,
    shaded: f64,
    covered: f64,
    overdraw: f64,
}

/// Each method's [`Counts`] over the group's frames: its image against the exact reference
/// (with the merged bake's unordered samples), triangles and draws, pipeline statistics,
/// and the counting pass's fragments and covered pixels.
fn count_frames(
    gpu: &Gpu,
    input: &GroupInput<'_>,
    methods: &[Box<dyn Method + '_>],
    progress: &dyn Fn(&str),
) -> Result<Vec<Counts>, BenchError> {
    let view = input.view;
    progress("exact reference");
    let reference = ExactReference::new(
        gpu,
        input.geometry,
        input.frame_states,
        trisort_gpu::Lighting::pbr(&input.baked.environment),
        ReferenceConfig {
            size: view.size,
            samples: view.samples,
            mode: input.mode,
            glass_opacity: view.glass_opacity,
            max_layers: 4096,
        },
    )?;
    let removed = UnorderedEdges::of_baked(input.baked, input.geometry.triangles.len())?;
    let counter = FragmentCounter::new(
        gpu,
        input.geometry,
        input.frame_states,
        view.size,
        view.glass_opacity,
    )?;
    let mut counts: Vec<Counts> = methods.iter().map(|_| Counts::new()).collect();
    let (w, h) = view.size;
    let pixels = (w as f64) * (h as f64);
    for (i, &f) in input.frames.iter().enumerate() {
        progress(&format!(
            "frame {f} ({}/{}): reference, images and counts",
            i + 1,
            input.frames.len()
        ));
        let reference_frame = reference.render(f, Some(&removed))?;
        let unordered = reference_frame.unordered.iter().filter(|&&u| u).count() as f64;
        for (m, a) in methods.iter().zip(&mut counts) {
            m.prepare(f)?;
            let image = m.image(f)?;
            let c = compare(
                &image,
                &reference_frame.rgba8,
                w,
                h,
                &reference_frame.unordered,
            );
            let e = &mut a.errors;
            e.frames += 1;
            e.frames_exact += (c.pixels_differing_ordered == 0) as u32;
            e.pixels_differing_fraction += c.pixels_differing as f64 / pixels;
            e.pixels_differing_ordered_fraction +=
                c.pixels_differing_ordered as f64 / (pixels - unordered).max(1.0);
            e.max_channel_diff = e.max_channel_diff.max(c.max_channel_diff);
            e.flip_mean += c.flip_mean;
            e.psnr_min = e.psnr_min.min(c.psnr);
            a.triangles += m.triangles(f) as f64;
            let d = m.draws(f);
            a.draws += d as f64;
            a.draws_max = a.draws_max.max(d);
            match pipeline_statistics(m.as_ref(), f)? {
                Some(p) => {
                    a.fragments_dev = a.fragments_dev.map(|x| x + p.fragment_invocations as f64);
                    a.vertices_dev = a.vertices_dev.map(|x| x + p.vertex_invocations as f64);
                }
                None => {
                    a.fragments_dev = None;
                    a.vertices_dev = None;
                }
            }
            let counted = counter.count(f, &m.streams(f), view.samples)?;
            let shaded = counted.fragments;
            a.shaded += shaded as f64;
            a.covered += counted.pixels_covered as f64;
            a.overdraw += if counted.pixels_covered > 0 {
                shaded as f64 / counted.pixels_covered as f64
            } else {
                0.0
            };
        }
    }
    Ok(counts)
}

impl Counts {
    fn new() -> Counts {
        Counts {
            errors: ErrorSummary {
                psnr_min: f64::INFINITY,
                ..Default::default()
            },
            triangles: 0.0,
            draws: 0.0,
            draws_max: 0,
            fragments_dev: Some(0.0),
            vertices_dev: Some(0.0),
            shaded: 0.0,
            covered: 0.0,
            overdraw: 0.0,
        }
    }

    /// The table row of method `m` from these sums (means over the group's frames) and its
    /// timings `t`.
    fn row(self, m: &dyn Method, input: &GroupInput<'_>, t: &[Timing]) -> MethodRow {
        let n = input.frames.len().max(1) as f64;
        let gpu: Vec<f64> = t.iter().filter_map(|x| x.gpu_ms).collect();
        let gpu_ms = (gpu.len() == t.len() && !t.is_empty()).then(|| Summary::of(&gpu));
        let wall_ms = Summary::of(&t.iter().map(|x| x.wall_ms).collect::<Vec<_>>());
        let headline = gpu_ms.unwrap_or(wall_ms);
        let mut errors = self.errors;
        if errors.frames > 0 {
            errors.pixels_differing_fraction /= errors.frames as f64;
            errors.pixels_differing_ordered_fraction /= errors.frames as f64;
            errors.flip_mean /= errors.frames as f64;
        } else {
            errors.psnr_min = 0.0;
        }
        MethodRow {
            method: m.name().to_string(),
            variant: m.variant(),
            mode: input.mode.name().into(),
            samples: input.view.samples,
            ms_per_frame: headline.mean,
            ms_p95: headline.p95,
            ms_max: headline.max,
            gpu_ms,
            wall_ms,
            ms_along_path: along_path(input.frames, t, gpu_ms.is_some()),
            triangles_per_frame: self.triangles / n,
            draws_per_frame_mean: self.draws / n,
            draws_per_frame_max: self.draws_max,
            fragment_invocations_per_frame: self.fragments_dev.map(|x| x / n),
            vertex_invocations_per_frame: self.vertices_dev.map(|x| x / n),
            fragments_shaded_per_frame: self.shaded / n,
            pixels_covered_per_frame: self.covered / n,
            overdraw: self.overdraw / n,
            error: errors,
            occlusion_queries: m.query_stats(),
        }
    }
}

/// Mean headline time per measured frame, in frame order.
fn along_path(frames: &[u32], timings: &[Timing], gpu: bool) -> Vec<(u32, f64)> {
    frames
        .iter()
        .map(|&f| {
            let v: Vec<f64> = timings
                .iter()
                .filter(|t| t.frame == f)
                .map(|t| {
                    if gpu {
                        t.gpu_ms.unwrap_or(0.0)
                    } else {
                        t.wall_ms
                    }
                })
                .collect();
            (f, v.iter().sum::<f64>() / v.len().max(1) as f64)
        })
        .collect()
}
