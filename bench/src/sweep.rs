//! The speed/accuracy sweep (`trisort bench SCENE --path P --sweep --out DIR`): one factor at
//! a time around the defaults, each point baked, played and compared with the exact reference
//! at the playback settings.
//!
//! Factors and the values tried (the default is the configuration's value, added where it is
//! not among them):
//!
//! | factor | values | what is redone |
//! |---|---|---|
//! | `record-size` | 0.5×, 1×, 2× the playback size | record + merge |
//! | `samples` | 1, 4 (recorded; played at the playback count) | record + merge |
//! | `saturation` | 0.99, 0.998, 1.0 | record + merge |
//! | `glass-opacity` | 0, 0.3, 0.6 (recorded, played and referenced at it) | record + merge |
//! | `bridge` | hidden, ignored | merge |
//! | `strategy-layout` | auto, and lib lbi ilb ibl bli bil × paper compact | merge |
//! | `segment` | none, 64, 16, 4 | merge |
//!
//! Every point with the default recording shares it; identical bakes (the default point of
//! every factor) are baked and played once. `bake_seconds` is what it costs to get the point
//! from what the factor cannot reuse: record + merge for the recording factors, the merge
//! alone for the merge factors (`bake_includes_record` says which); `record_seconds` and
//! `merge_seconds` are always both reported.
//!
//! Error is measured against [`ExactReference`] at the playback size and samples in `blend`
//! mode with the point's glass opacity; reference frames are rendered once per glass opacity.
//! Pixels at unordered samples (cycles the merger broke) count as differing like any other:
//! this is the error a user sees.
//!
//! Outputs in the output folder, each written atomically: `sweep.csv`, `sweep.json`,
//! `sweep-error-vs-bake-time.svg`, `sweep-error-vs-baked-size.svg`,
//! `sweep-draws-along-path.svg`.

use std::collections::HashMap;
use std::path::Path;
use std::str::FromStr;
use std::time::Instant;

use serde::Serialize;
use trisort_format::{Baked, FileKind, Phase, RecordSettings, Recording};
use trisort_merger::{Bridge, LayoutChoice, MergeOptions, StrategyChoice};
use trisort_player::headless::{HeadlessConfig, HeadlessRenderer};
use trisort_player::Mode;
use trisort_recorder::RecordJob;
use trisort_reference::{compare, ExactReference, ReferenceConfig};
use trisort_gpu::Gpu;

use crate::plot::{write_atomic, write_svg, write_svg_labelled, Chart, Series, Style};
use crate::BenchError;

/// Timed renders of each compared frame per point (after one untimed warm-up render of each);
/// a frame's time is their median.
pub const PLAY_REPEATS: u32 = 5;

/// Layer bound of the sweep's recordings and references (the CLI's `--max-layers` default).
pub const MAX_LAYERS: u32 = 256;

/// What the sweep varies, one factor at a time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Factor {
    /// Recording size: 0.5×, 1×, 2× the playback size.
    RecordSize,
    /// Recorded MSAA samples: 1, 4.
    Samples,
    /// Saturation threshold: 0.99, 0.998, 1.0.
    Saturation,
    /// Glass opacity: 0, 0.3, 0.6 (recorded, played and referenced at it).
    GlassOpacity,
    /// Bridge policy: hidden, ignored.
    Bridge,
    /// Strategy × layout: auto, and the six strategies × paper, compact.
    StrategyLayout,
    /// Segment length: none, 64, 16, 4.
    Segment,
}

impl Factor {
    /// Every factor, in the order the sweep runs them.
    pub const ALL: [Factor; 7] = [
        Factor::RecordSize,
        Factor::Samples,
        Factor::Saturation,
        Factor::GlassOpacity,
        Factor::Bridge,
        Factor::StrategyLayout,
        Factor::Segment,
    ];

    /// The factor's name on the command line and in the outputs (`record-size`, …).
    pub fn name(self) -> &'static str {
        match self {
            Factor::RecordSize => "record-size",
            Factor::Samples => "samples",
            Factor::Saturation => "saturation",
            Factor::GlassOpacity => "glass-opacity",
            Factor::Bridge => "bridge",
            Factor::StrategyLayout => "strategy-layout",
            Factor::Segment => "segment",
        }
    }

    /// Whether the factor changes the recording (otherwise only the merge is redone).
    pub fn records(self) -> bool {
        matches!(
            self,
            Factor::RecordSize | Factor::Samples | Factor::Saturation | Factor::GlassOpacity
        )
    }

    /// Parses a comma-separated list of factor names; `all` (or an empty string) gives every
    /// factor. Duplicates are dropped; the sweep runs them in [`Factor::ALL`]'s order.
    pub fn parse_list(list: &str) -> Result<Vec<Factor>, BenchError> {
        let mut out = Vec::new();
        for word in list.split(',').map(str::trim).filter(|w| !w.is_empty()) {
            if word == "all" {
                return Ok(Factor::ALL.to_vec());
            }
            let f: Factor = word.parse()?;
            if !out.contains(&f) {
                out.push(f);
            }
        }
        if out.is_empty() {
            return Ok(Factor::ALL.to_vec());
        }
        out.sort_by_key(|f| Factor::ALL.iter().position(|a| a == f));
        Ok(out)
    }
}

impl FromStr for Factor {
    type Err = BenchError;
    fn from_str(s: &str) -> Result<Factor, BenchError> {
        Factor::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Factor::ALL.iter().map(|f| f.name()).collect();
                BenchError::Invalid(format!(
                    "unknown sweep factor `{s}` (expected {} or all)",
                    names.join(", ")
                ))
            })
    }
}

impl std::fmt::Display for Factor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The sweep's defaults and playback settings.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepConfig {
    /// Playback size (width, height); also the default recording size.
    pub size: (u32, u32),
    /// Playback MSAA samples (1 or 4); also the default recorded count.
    pub samples: u32,
    /// Default saturation threshold.
    pub saturation: f32,
    /// Default glass opacity.
    pub glass_opacity: f32,
    /// Frames to play and compare (every bake covers the whole path); empty: every frame.
    pub frames: Vec<u32>,
    /// Factors to run; empty: every factor.
    pub factors: Vec<Factor>,
}

impl SweepConfig {
    /// The CLI's defaults at playback `size` and `samples`: saturation 0.998, glass opacity 0,
    /// every frame, every factor.
    pub fn new(size: (u32, u32), samples: u32) -> SweepConfig {
        SweepConfig {
            size,
            samples,
            saturation: 0.998,
            glass_opacity: 0.0,
            frames: Vec::new(),
            factors: Factor::ALL.to_vec(),
        }
    }
}

/// One point of the sweep.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepPoint {
    /// The factor varied ([`Factor::name`]).
    pub factor: String,
    /// Its value here (e.g. `0.5x (128x128)`, `lib/paper`, `none`).
    pub value: String,
    /// Whether this is the default configuration (the same bake under every factor).
    pub is_default: bool,
    /// Wall time of the recording this point's bake was merged from, seconds.
    pub record_seconds: f64,
    /// Wall time of the merge, seconds.
    pub merge_seconds: f64,
    /// Cost of the point: record + merge for the recording factors, merge only for the others.
    pub bake_seconds: f64,
    /// Whether `bake_seconds` includes the recording.
    pub bake_includes_record: bool,
    /// Size of the baked file (the exact bytes `trisort merge` writes).
    pub baked_bytes: u64,
    /// Triangles in the index buffer (copies).
    pub index_triangles: u64,
    /// |G|: triangles visible at least once.
    pub unique_visible: u64,
    /// Weight of the intra-frame cycle edges the merger removed (samples whose order it
    /// could not keep).
    pub unordered_samples: u64,
    /// Mean over frames of triangles drawn but not visible.
    pub drawn_not_visible_mean: f64,
    /// Mean indirect draws per frame over the path.
    pub draws_per_frame_mean: f64,
    /// Most indirect draws in one frame.
    pub draws_per_frame_max: u32,
    /// Mean over the compared frames of a frame's GPU time (timestamp queries; the median of
    /// [`PLAY_REPEATS`] renders), ms; NaN (null in JSON) where the device has no timestamps.
    pub play_ms_mean: f64,
    /// Largest frame GPU time (each the median of its repeats), ms (NaN without timestamps).
    pub play_ms_max: f64,
    /// Mean wall time of a played frame (submit, wait, read back; median of its repeats), ms.
    pub wall_ms_mean: f64,
    /// Pixels differing from the reference, summed over the compared frames.
    pub pixels_differing: u64,
    /// `pixels_differing` ÷ (compared frames × pixels).
    pub pixels_differing_fraction: f64,
    /// Largest colour-channel difference over the compared frames, 1/255 units.
    pub max_channel_diff: u8,
    /// Mean LDR-FLIP over the compared frames (0 identical).
    pub flip_mean: f64,
}

/// The sweep's results.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepReport {
    /// The device ([`Gpu::describe`]).
    pub device: String,
    /// Playback size.
    pub size: (u32, u32),
    /// Playback samples.
    pub samples: u32,
    /// Frames compared.
    pub frames: Vec<u32>,
    /// Frames of the path.
    pub path_frames: u32,
    /// Triangles of the scene.
    pub scene_triangles: u64,
    /// Strategy and layout the default (`auto`) merge chose.
    pub default_merge: String,
    /// The points, factor by factor in the order run, values in the order listed above.
    pub points: Vec<SweepPoint>,
    /// Draws per frame along the path of the default bake: (frame, draws).
    pub draws_along_path: Vec<(u32, u32)>,
}

/// One configuration to bake and measure.
#[derive(Clone, Debug)]
struct Variant {
    factor: Factor,
    value: String,
    settings: RecordSettings,
    merge: MergeOptions,
}

/// What a bake measured, shared by identical variants.
#[derive(Clone, Debug)]
struct Measured {
    record_seconds: f64,
    merge_seconds: f64,
    baked_bytes: u64,
    strategy_layout: String,
    stats: trisort_format::MergeStats,
    draws: Vec<u32>,
    play_ms: Vec<f64>,
    wall_ms: Vec<f64>,
    pixels_differing: u64,
    max_channel_diff: u8,
    flip: Vec<f64>,
}

fn settings_key(s: &RecordSettings) -> (u32, u32, u32, u32, u32, u32) {
    (
        s.width,
        s.height,
        s.samples,
        s.saturation.to_bits(),
        s.glass_opacity.to_bits(),
        s.max_layers,
    )
}

fn same_settings(a: &RecordSettings, b: &RecordSettings) -> bool {
    settings_key(a) == settings_key(b)
}

/// The default merge options of the CLI (`auto`, `auto`, `hidden`, no segments).
fn default_merge() -> MergeOptions {
    MergeOptions::default()
}

fn strategy_name(s: StrategyChoice) -> &'static str {
    match s {
        StrategyChoice::Lib => "lib",
        StrategyChoice::Lbi => "lbi",
        StrategyChoice::Ilb => "ilb",
        StrategyChoice::Ibl => "ibl",
        StrategyChoice::Bli => "bli",
        StrategyChoice::Bil => "bil",
        StrategyChoice::Auto => "auto",
    }
}

fn layout_name(l: LayoutChoice) -> &'static str {
    match l {
        LayoutChoice::Paper => "paper",
        LayoutChoice::Compact => "compact",
        LayoutChoice::Auto => "auto",
    }
}

/// A float as the sweep names it (`0.998`, `1`, `0.3`).
fn number(v: f32) -> String {
    let s = format!("{v}");
    if s.contains('.') {
        s
    } else {
        format!("{s}.0")
    }
}

/// `values` with `default` added (at its sorted place) when it is not among them.
fn with_default(mut values: Vec<f32>, default: f32) -> Vec<f32> {
    if !values.contains(&default) {
        values.push(default);
        values.sort_by(f32::total_cmp);
    }
    values
}

fn variants(config: &SweepConfig, base: RecordSettings) -> Vec<Variant> {
    let merge = default_merge();
    let factors: Vec<Factor> = if config.factors.is_empty() {
        Factor::ALL.to_vec()
    } else {
        Factor::ALL
            .into_iter()
            .filter(|f| config.factors.contains(f))
            .collect()
    };
    let mut out = Vec::new();
    for factor in factors {
        let v = |value: String, settings: RecordSettings, merge: MergeOptions| Variant {
            factor,
            value,
            settings,
            merge,
        };
        match factor {
            Factor::RecordSize => {
                for (k, name) in [(0.5, "0.5x"), (1.0, "1x"), (2.0, "2x")] {
                    let w = ((base.width as f64 * k).round() as u32).max(1);
                    let h = ((base.height as f64 * k).round() as u32).max(1);
                    let s = RecordSettings {
                        width: w,
                        height: h,
                        ..base
                    };
                    out.push(v(format!("{name} ({w}x{h})"), s, merge));
                }
            }
            Factor::Samples => {
                let mut counts = vec![1, 4];
                if !counts.contains(&base.samples) {
                    counts.push(base.samples);
                    counts.sort();
                }
                for n in counts {
                    let s = RecordSettings { samples: n, ..base };
                    out.push(v(format!("{n}"), s, merge));
                }
            }
            Factor::Saturation => {
                for x in with_default(vec![0.99, 0.998, 1.0], base.saturation) {
                    let s = RecordSettings {
                        saturation: x,
                        ..base
                    };
                    out.push(v(number(x), s, merge));
                }
            }
            Factor::GlassOpacity => {
                for x in with_default(vec![0.0, 0.3, 0.6], base.glass_opacity) {
                    let s = RecordSettings {
                        glass_opacity: x,
                        ..base
                    };
                    out.push(v(number(x), s, merge));
                }
            }
            Factor::Bridge => {
                for b in [Bridge::Hidden, Bridge::Ignored, Bridge::Visible] {
                    let m = MergeOptions { bridge: b, ..merge };
                    out.push(v(b.name().to_string(), base, m));
                }
            }
            Factor::StrategyLayout => {
                out.push(v("auto/auto".into(), base, merge));
                for s in [
                    StrategyChoice::Lib,
                    StrategyChoice::Lbi,
                    StrategyChoice::Ilb,
                    StrategyChoice::Ibl,
                    StrategyChoice::Bli,
                    StrategyChoice::Bil,
                ] {
                    for l in [LayoutChoice::Paper, LayoutChoice::Compact] {
                        let m = MergeOptions {
                            strategy: s,
                            layout: l,
                            ..merge
                        };
                        out.push(v(
                            format!("{}/{}", strategy_name(s), layout_name(l)),
                            base,
                            m,
                        ));
                    }
                }
            }
            Factor::Segment => {
                for seg in [None, Some(64), Some(16), Some(4)] {
                    let m = MergeOptions {
                        segment: seg,
                        ..merge
                    };
                    let name = seg.map_or("none".to_string(), |n| n.to_string());
                    out.push(v(name, base, m));
                }
            }
        }
    }
    out
}

/// Runs the sweep of `scene` along `timeline` and writes its outputs into `out_dir` (created
/// if missing). `progress` receives one line per step (recordings take minutes on big scenes).
pub fn run(
    gpu: &Gpu,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    config: &SweepConfig,
    out_dir: &Path,
    progress: &dyn Fn(&str),
) -> Result<SweepReport, BenchError> {
    let (w, h) = config.size;
    if w == 0 || h == 0 {
        return Err(BenchError::Invalid(format!(
            "playback size {w}x{h}: both must be positive"
        )));
    }
    if config.samples != 1 && config.samples != 4 {
        return Err(BenchError::Invalid(format!(
            "playback samples {}: 1 or 4",
            config.samples
        )));
    }
    if !(config.saturation > 0.0 && config.saturation <= 1.0) {
        return Err(BenchError::Invalid(format!(
            "saturation {}: in (0, 1]",
            config.saturation
        )));
    }
    if !(0.0..=1.0).contains(&config.glass_opacity) {
        return Err(BenchError::Invalid(format!(
            "glass opacity {}: in [0, 1]",
            config.glass_opacity
        )));
    }
    let path_frames = timeline.frames.len() as u32;
    let frames: Vec<u32> = if config.frames.is_empty() {
        (0..path_frames).collect()
    } else {
        config.frames.clone()
    };
    if let Some(&bad) = frames.iter().find(|&&f| f >= path_frames) {
        return Err(BenchError::Invalid(format!(
            "frame {bad} is not on the path ({path_frames} frames)"
        )));
    }
    std::fs::create_dir_all(out_dir).map_err(|source| BenchError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;

    let base = RecordSettings {
        width: w,
        height: h,
        samples: config.samples,
        saturation: config.saturation,
        // + 0.0: −0 is 0 here, so that it matches the listed value 0 bit for bit.
        glass_opacity: config.glass_opacity + 0.0,
        max_layers: MAX_LAYERS,
    };
    let variants = variants(config, base);
    // Recordings in first-use order; the default recording first so that the merge factors
    // share it.
    let mut recording_order: Vec<RecordSettings> = vec![base];
    for v in &variants {
        if !recording_order
            .iter()
            .any(|s| same_settings(s, &v.settings))
        {
            recording_order.push(v.settings);
        }
    }

    let mut references: HashMap<u32, Vec<Vec<u8>>> = HashMap::new();
    let mut measured: Vec<(RecordSettings, MergeOptions, Measured)> = Vec::new();
    let total = variants.len();
    let mut done = 0usize;
    for settings in &recording_order {
        let users: Vec<&Variant> = variants
            .iter()
            .filter(|v| same_settings(&v.settings, settings))
            .collect();
        if users.is_empty() {
            continue;
        }
        progress(&format!(
            "sweep: recording {}x{}, {} samples, saturation {}, glass {} ({} frames)",
            settings.width,
            settings.height,
            settings.samples,
            number(settings.saturation),
            number(settings.glass_opacity),
            path_frames
        ));
        let t = Instant::now();
        let rec = record(gpu, scene, timeline, *settings)?;
        let record_seconds = t.elapsed().as_secs_f64();
        progress(&format!(
            "sweep: recorded in {record_seconds:.2} s: |G| = {} of {} triangles",
            rec.unique_visible.len(),
            rec.scene_triangles
        ));
        let glass_key = settings.glass_opacity.to_bits();
        if let std::collections::hash_map::Entry::Vacant(slot) = references.entry(glass_key) {
            progress(&format!(
                "sweep: exact reference at {w}x{h}, {} samples, glass {}: {} frames",
                config.samples,
                number(settings.glass_opacity),
                frames.len()
            ));
            slot.insert(reference_frames(
                gpu,
                scene,
                timeline,
                config,
                settings.glass_opacity,
                &frames,
            )?);
        }
        let reference = &references[&glass_key];
        for v in users {
            done += 1;
            let known = measured
                .iter()
                .any(|(s, m, _)| same_settings(s, settings) && *m == v.merge);
            if known {
                progress(&format!(
                    "sweep [{done}/{total}] {} = {}: same bake as before",
                    v.factor, v.value
                ));
                continue;
            }
            progress(&format!(
                "sweep [{done}/{total}] {} = {}: merging",
                v.factor, v.value
            ));
            let t = Instant::now();
            let baked = trisort_merger::merge(std::slice::from_ref(&rec), &v.merge)?;
            let merge_seconds = t.elapsed().as_secs_f64();
            let m = measure(
                gpu,
                &baked,
                config,
                &frames,
                reference,
                record_seconds,
                merge_seconds,
            )?;
            progress(&format!(
                "sweep [{done}/{total}] {} = {}: merge {:.2} s, {} index triangles, {:.1} draws/frame, error {} px, FLIP {:.4}",
                v.factor, v.value, merge_seconds, m.stats.index_triangles,
                m.stats.draws_per_frame_mean, m.pixels_differing, mean(&m.flip)
            ));
            measured.push((*settings, v.merge, m));
        }
    }

    let pixels = frames.len() as f64 * w as f64 * h as f64;
    let find = |v: &Variant| -> &Measured {
        &measured
            .iter()
            .find(|(s, m, _)| same_settings(s, &v.settings) && *m == v.merge)
            .expect("every variant was measured")
            .2
    };
    let points: Vec<SweepPoint> = variants
        .iter()
        .map(|v| {
            let m = find(v);
            let includes = v.factor.records();
            SweepPoint {
                factor: v.factor.name().to_string(),
                value: v.value.clone(),
                is_default: same_settings(&v.settings, &base) && v.merge == default_merge(),
                record_seconds: m.record_seconds,
                merge_seconds: m.merge_seconds,
                bake_seconds: if includes {
                    m.record_seconds + m.merge_seconds
                } else {
                    m.merge_seconds
                },
                bake_includes_record: includes,
                baked_bytes: m.baked_bytes,
                index_triangles: m.stats.index_triangles,
                unique_visible: m.stats.unique_visible,
                unordered_samples: m.stats.unordered_samples,
                drawn_not_visible_mean: m.stats.drawn_not_visible_mean,
                draws_per_frame_mean: m.stats.draws_per_frame_mean,
                draws_per_frame_max: m.stats.draws_per_frame_max,
                play_ms_mean: mean(&m.play_ms),
                play_ms_max: max(&m.play_ms),
                wall_ms_mean: mean(&m.wall_ms),
                pixels_differing: m.pixels_differing,
                pixels_differing_fraction: if pixels > 0.0 {
                    m.pixels_differing as f64 / pixels
                } else {
                    0.0
                },
                max_channel_diff: m.max_channel_diff,
                flip_mean: mean(&m.flip),
            }
        })
        .collect();
    let default = measured
        .iter()
        .find(|(s, m, _)| same_settings(s, &base) && *m == default_merge())
        .map(|x| &x.2);
    let report = SweepReport {
        device: gpu.describe(),
        size: config.size,
        samples: config.samples,
        frames,
        path_frames,
        scene_triangles: scene.geometry.triangles.len() as u64,
        default_merge: default.map_or(String::new(), |m| m.strategy_layout.clone()),
        points,
        draws_along_path: default.map_or(Vec::new(), |m| {
            m.draws
                .iter()
                .enumerate()
                .map(|(f, &d)| (f as u32, d))
                .collect()
        }),
    };
    // Draws along the path of the segment variants too, when that factor ran.
    let segment_draws: Vec<(String, Vec<u32>)> = variants
        .iter()
        .filter(|v| v.factor == Factor::Segment && v.merge.segment.is_some())
        .map(|v| (format!("segment {}", v.value), find(v).draws.clone()))
        .collect();
    write_outputs(&report, &segment_draws, out_dir)?;
    progress(&format!(
        "sweep: wrote sweep.csv, sweep.json and 3 plots into {}",
        out_dir.display()
    ));
    Ok(report)
}

/// Records `settings` over the whole path (both phases), in memory.
fn record(
    gpu: &Gpu,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    settings: RecordSettings,
) -> Result<Recording, BenchError> {
    let job = RecordJob {
        geometry: &scene.geometry,
        frames: &timeline.frames,
        scene_hash: scene.hash(),
        path_hash: timeline.hash(),
        settings,
        range: None,
        phase: Phase::Graphs,
        known_visible: None,
    };
    let rec = trisort_recorder::record(gpu, &job, None, |_| {})?;
    if let Some(f) = rec.frames.iter().find(|f| f.truncated) {
        return Err(BenchError::Invalid(format!(
            "frame {} hit the layer bound ({MAX_LAYERS}) while recording {}x{}",
            f.frame, settings.width, settings.height
        )));
    }
    Ok(rec)
}

/// The exact reference's frames at the playback settings with glass opacity `glass`.
fn reference_frames(
    gpu: &Gpu,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    config: &SweepConfig,
    glass: f32,
    frames: &[u32],
) -> Result<Vec<Vec<u8>>, BenchError> {
    let reference = ExactReference::new(
        gpu,
        &scene.geometry,
        &timeline.frames,
        ReferenceConfig {
            size: config.size,
            samples: config.samples,
            mode: Mode::Blend,
            glass_opacity: glass,
            max_layers: 4096,
        },
    )?;
    frames
        .iter()
        .map(|&f| {
            let r = reference.render(f, None)?;
            if r.truncated {
                return Err(BenchError::Invalid(format!(
                    "the exact reference of frame {f} hit its layer bound"
                )));
            }
            Ok(r.rgba8)
        })
        .collect()
}

/// Size, figures, play time and error of one bake.
fn measure(
    gpu: &Gpu,
    baked: &Baked,
    config: &SweepConfig,
    frames: &[u32],
    reference: &[Vec<u8>],
    record_seconds: f64,
    merge_seconds: f64,
) -> Result<Measured, BenchError> {
    // The bytes `trisort merge` writes (`write_file_atomic` writes exactly this encoding).
    let baked_bytes = trisort_format::container::encode(FileKind::Baked, baked).len() as u64;
    let renderer = HeadlessRenderer::new(
        gpu,
        baked,
        &HeadlessConfig {
            size: config.size,
            samples: config.samples,
            mode: Mode::Blend,
            glass_opacity: Some(baked.settings.glass_opacity),
            draw_path: None,
            force_u32: false,
        },
    )?;
    let (w, h) = config.size;
    let mut play_ms = Vec::new();
    let mut wall_ms = Vec::new();
    let mut pixels_differing = 0;
    let mut max_channel_diff = 0;
    let mut flip = Vec::new();
    for &f in frames {
        renderer.render(f)?; // warm-up: pipeline, caches, the frame's uniforms
    }
    for (&f, reference) in frames.iter().zip(reference) {
        let mut image = None;
        let (mut gpu_times, mut wall_times) = (Vec::new(), Vec::new());
        for _ in 0..PLAY_REPEATS.max(1) {
            let t = Instant::now();
            let r = renderer.render(f)?;
            wall_times.push(t.elapsed().as_secs_f64() * 1e3);
            if let Some(ms) = r.gpu_ms {
                gpu_times.push(ms);
            }
            image.get_or_insert(r.rgba8);
        }
        // The frame's time: the median of its repeats (robust to a busy machine's bursts).
        if !gpu_times.is_empty() {
            play_ms.push(median(&mut gpu_times));
        }
        wall_ms.push(median(&mut wall_times));
        let image = image.expect("rendered at least once");
        let c = compare(&image, reference, w, h, &[]);
        pixels_differing += c.pixels_differing;
        max_channel_diff = max_channel_diff.max(c.max_channel_diff);
        flip.push(c.flip_mean);
    }
    Ok(Measured {
        record_seconds,
        merge_seconds,
        baked_bytes,
        strategy_layout: format!("{}/{}", baked.merge.strategy, baked.merge.layout),
        stats: baked.stats.clone(),
        draws: baked.frames.iter().map(|w| w.count).collect(),
        play_ms,
        wall_ms,
        pixels_differing,
        max_channel_diff,
        flip,
    })
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        f64::NAN
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NAN, f64::max)
}

/// The CSV columns, in order.
pub const CSV_COLUMNS: [&str; 21] = [
    "factor",
    "value",
    "is_default",
    "record_seconds",
    "merge_seconds",
    "bake_seconds",
    "bake_includes_record",
    "baked_bytes",
    "index_triangles",
    "unique_visible",
    "unordered_samples",
    "drawn_not_visible_mean",
    "draws_per_frame_mean",
    "draws_per_frame_max",
    "play_ms_mean",
    "play_ms_max",
    "wall_ms_mean",
    "pixels_differing",
    "pixels_differing_fraction",
    "max_channel_diff",
    "flip_mean",
];

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn csv_float(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        String::new()
    }
}

/// The sweep's points as CSV (a header line, then one line per point; missing figures empty).
pub fn to_csv(points: &[SweepPoint]) -> String {
    let mut out = CSV_COLUMNS.join(",");
    out.push('\n');
    for p in points {
        let fields = [
            csv_field(&p.factor),
            csv_field(&p.value),
            p.is_default.to_string(),
            csv_float(p.record_seconds),
            csv_float(p.merge_seconds),
            csv_float(p.bake_seconds),
            p.bake_includes_record.to_string(),
            p.baked_bytes.to_string(),
            p.index_triangles.to_string(),
            p.unique_visible.to_string(),
            p.unordered_samples.to_string(),
            csv_float(p.drawn_not_visible_mean),
            csv_float(p.draws_per_frame_mean),
            p.draws_per_frame_max.to_string(),
            csv_float(p.play_ms_mean),
            csv_float(p.play_ms_max),
            csv_float(p.wall_ms_mean),
            p.pixels_differing.to_string(),
            csv_float(p.pixels_differing_fraction),
            p.max_channel_diff.to_string(),
            csv_float(p.flip_mean),
        ];
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// One series per factor, in the order the factors ran, with each point's value as label.
fn per_factor(
    points: &[SweepPoint],
    x: impl Fn(&SweepPoint) -> f64,
    y: impl Fn(&SweepPoint) -> f64,
) -> (Vec<Series>, Vec<Vec<String>>) {
    let mut series: Vec<Series> = Vec::new();
    let mut labels: Vec<Vec<String>> = Vec::new();
    for p in points {
        let k = match series.iter().position(|s| s.name == p.factor) {
            Some(k) => k,
            None => {
                series.push(Series {
                    name: p.factor.clone(),
                    points: Vec::new(),
                });
                labels.push(Vec::new());
                series.len() - 1
            }
        };
        series[k].points.push((x(p), y(p)));
        let short = p.value.split(" (").next().unwrap_or(&p.value);
        labels[k].push(if p.is_default {
            format!("{short}*")
        } else {
            short.to_string()
        });
    }
    (series, labels)
}

fn write_outputs(
    report: &SweepReport,
    segment_draws: &[(String, Vec<u32>)],
    out_dir: &Path,
) -> Result<(), BenchError> {
    write_atomic(
        &out_dir.join("sweep.csv"),
        to_csv(&report.points).as_bytes(),
    )?;
    let json = serde_json::to_string_pretty(report)
        .map_err(|e| BenchError::Invalid(format!("sweep.json: {e}")))?;
    write_atomic(&out_dir.join("sweep.json"), json.as_bytes())?;

    let subtitle = format!(
        "{}x{} {}x, {} frames compared",
        report.size.0,
        report.size.1,
        report.samples,
        report.frames.len()
    );
    let error_label = "pixels differing from the exact reference (fraction)";
    let (series, labels) = per_factor(
        &report.points,
        |p| p.bake_seconds,
        |p| p.pixels_differing_fraction,
    );
    write_svg_labelled(
        &out_dir.join("sweep-error-vs-bake-time.svg"),
        &Chart {
            title: format!("Sweep: error vs bake time ({subtitle}; * default)"),
            x_label: "bake seconds (record + merge; merge only for merge factors)".into(),
            y_label: error_label.into(),
            log_x: true,
            log_y: false,
            series,
        },
        Style::Points,
        &labels,
    )?;
    let (series, labels) = per_factor(
        &report.points,
        |p| p.baked_bytes as f64 / (1024.0 * 1024.0),
        |p| p.pixels_differing_fraction,
    );
    write_svg_labelled(
        &out_dir.join("sweep-error-vs-baked-size.svg"),
        &Chart {
            title: format!("Sweep: error vs baked size ({subtitle}; * default)"),
            x_label: "baked file size (MiB)".into(),
            y_label: error_label.into(),
            log_x: true,
            log_y: false,
            series,
        },
        Style::Points,
        &labels,
    )?;
    let along = |name: String, draws: &[u32]| Series {
        name,
        points: draws
            .iter()
            .enumerate()
            .map(|(f, &d)| (f as f64, d as f64))
            .collect(),
    };
    let mut series = vec![Series {
        name: format!("default ({})", report.default_merge),
        points: report
            .draws_along_path
            .iter()
            .map(|&(f, d)| (f as f64, d as f64))
            .collect(),
    }];
    series.extend(segment_draws.iter().map(|(n, d)| along(n.clone(), d)));
    write_svg(
        &out_dir.join("sweep-draws-along-path.svg"),
        &Chart {
            title: format!(
                "Draws per frame along the path ({} frames)",
                report.path_frames
            ),
            x_label: "frame".into(),
            y_label: "indirect draws".into(),
            log_x: false,
            log_y: false,
            series,
        },
        Style::Lines,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_mean_max() {
        assert!(median(&mut []).is_nan());
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(mean(&[]).is_nan() && max(&[]).is_nan());
        assert_eq!((mean(&[1.0, 2.0]), max(&[1.0, 2.0])), (1.5, 2.0));
    }

    #[test]
    fn factors_parse_and_name() {
        for f in Factor::ALL {
            assert_eq!(f.name().parse::<Factor>().unwrap(), f);
        }
        assert_eq!(Factor::parse_list("all").unwrap(), Factor::ALL.to_vec());
        assert_eq!(Factor::parse_list("").unwrap(), Factor::ALL.to_vec());
        assert_eq!(
            Factor::parse_list("segment, bridge,segment").unwrap(),
            vec![Factor::Bridge, Factor::Segment]
        );
        let e = Factor::parse_list("bridge,colour").unwrap_err().to_string();
        assert!(e.contains("colour") && e.contains("record-size"), "{e}");
    }

    #[test]
    fn variants_cover_every_value_around_the_defaults() {
        let config = SweepConfig::new((256, 128), 4);
        let base = RecordSettings {
            width: 256,
            height: 128,
            samples: 4,
            saturation: 0.998,
            glass_opacity: 0.0,
            max_layers: MAX_LAYERS,
        };
        let v = variants(&config, base);
        let count = |f: Factor| v.iter().filter(|x| x.factor == f).count();
        assert_eq!(count(Factor::RecordSize), 3);
        assert_eq!(count(Factor::Samples), 2);
        assert_eq!(count(Factor::Saturation), 3);
        assert_eq!(count(Factor::GlassOpacity), 3);
        assert_eq!(count(Factor::Bridge), 3);
        assert_eq!(count(Factor::StrategyLayout), 13);
        assert_eq!(count(Factor::Segment), 4);
        // Each factor has exactly one default point, and it is the same bake.
        for f in Factor::ALL {
            let defaults = v
                .iter()
                .filter(|x| {
                    x.factor == f && same_settings(&x.settings, &base) && x.merge == default_merge()
                })
                .count();
            assert_eq!(defaults, 1, "{f}");
        }
        let sizes: Vec<_> = v
            .iter()
            .filter(|x| x.factor == Factor::RecordSize)
            .map(|x| (x.settings.width, x.settings.height))
            .collect();
        assert_eq!(sizes, vec![(128, 64), (256, 128), (512, 256)]);
        // Merge factors reuse the default recording.
        assert!(v
            .iter()
            .filter(|x| !x.factor.records())
            .all(|x| same_settings(&x.settings, &base)));
        // A default outside the listed values is added.
        let odd = SweepConfig {
            saturation: 0.95,
            glass_opacity: 0.1,
            factors: vec![Factor::Saturation, Factor::GlassOpacity],
            ..config
        };
        let v = variants(
            &odd,
            RecordSettings {
                saturation: 0.95,
                glass_opacity: 0.1,
                ..base
            },
        );
        let values: Vec<_> = v.iter().map(|x| x.value.as_str()).collect();
        assert_eq!(
            values,
            ["0.95", "0.99", "0.998", "1.0", "0.0", "0.1", "0.3", "0.6"]
        );
    }

    #[test]
    fn csv_has_one_line_per_point_and_quotes_commas() {
        let p = SweepPoint {
            factor: "strategy-layout".into(),
            value: "a,b".into(),
            is_default: false,
            record_seconds: 1.0,
            merge_seconds: 0.5,
            bake_seconds: 0.5,
            bake_includes_record: false,
            baked_bytes: 10,
            index_triangles: 3,
            unique_visible: 2,
            unordered_samples: 0,
            drawn_not_visible_mean: 0.0,
            draws_per_frame_mean: 1.5,
            draws_per_frame_max: 2,
            play_ms_mean: f64::NAN,
            play_ms_max: f64::NAN,
            wall_ms_mean: 2.0,
            pixels_differing: 0,
            pixels_differing_fraction: 0.0,
            max_channel_diff: 0,
            flip_mean: 0.0,
        };
        let csv = to_csv(&[p.clone(), p]);
        let lines: Vec<_> = csv.lines().collect();
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0].split(',').count(), CSV_COLUMNS.len());
        assert!(lines[1].starts_with("strategy-layout,\"a,b\",false,1,0.5,0.5,false,10,"));
        assert!(lines[1].contains(",2,,,2,0,0,0,0"), "{}", lines[1]);
    }
}
