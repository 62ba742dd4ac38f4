//! The sweep itself: one recording per distinct recording settings, one exact reference per
//! glass opacity, one merge and measurement per distinct bake.

use std::collections::hash_map::Entry;
use std::collections::HashMap;
use std::path::Path;
use std::time::Instant;

use trisort_bake::{record_in_memory, RecordTarget, Silent, Working};
use trisort_format::{Phase, RecordSettings, Recording};
use trisort_gpu::Gpu;
use trisort_merger::MergeOptions;
use trisort_player::Mode;
use trisort_reference::{ExactReference, ReferenceConfig};

use super::factors::{number, same_settings, variants, Factor, Variant};
use super::measurement::{max, mean, measure, Measured};
use super::output::write_outputs;
use super::robustness;
use super::{SweepConfig, SweepPoint, SweepReport};
use crate::BenchError;

/// Runs the sweep of the working scene along its path and writes its outputs into `out_dir`
/// (created if missing). `progress` receives one line per step (recordings take minutes on
/// big scenes).
pub fn run(
    gpu: &Gpu,
    working: &Working,
    config: &SweepConfig,
    out_dir: &Path,
    progress: &dyn Fn(&str),
) -> Result<SweepReport, BenchError> {
    let base = config.base_settings();
    base.validate()
        .map_err(|e| BenchError::Invalid(format!("sweep settings: {e}")))?;
    let (scene, timeline) = (&working.scene, &working.timeline);
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
    let variants = variants(config, base);
    let sweep = Sweep {
        gpu,
        scene,
        timeline,
        config,
        frames: &frames,
        progress,
    };
    let measured = sweep.bake_all(base, &variants)?;
    let report = sweep.report(base, &variants, &measured);
    // Draws along the path of the segment variants too, when that factor ran.
    let segment_draws: Vec<(String, Vec<u32>)> = variants
        .iter()
        .filter(|v| v.factor == Factor::Segment && v.merge.segment.is_some())
        .map(|v| {
            (
                format!("segment {}", v.value),
                find(&measured, v).draws.clone(),
            )
        })
        .collect();
    write_outputs(&report, &segment_draws, out_dir)?;
    progress(&format!(
        "sweep: wrote sweep.csv, sweep.json and 3 plots into {}",
        out_dir.display()
    ));
    Ok(report)
}

/// Every distinct bake with the settings and merge options it was made with.
type Bakes = Vec<(RecordSettings, MergeOptions, Measured)>;

/// The measurement of `v`'s bake.
fn find<'a>(measured: &'a Bakes, v: &Variant) -> &'a Measured {
    &measured
        .iter()
        .find(|(s, m, _)| same_settings(s, &v.settings) && *m == v.merge)
        .expect("every variant was measured")
        .2
}

/// What every step of one sweep shares.
struct Sweep<'a> {
    gpu: &'a Gpu,
    scene: &'a trisort_scene::Scene,
    timeline: &'a trisort_paths::Timeline,
    config: &'a SweepConfig,
    /// The frames compared.
    frames: &'a [u32],
    progress: &'a dyn Fn(&str),
}

impl Sweep<'_> {
    /// Records each distinct recording once (the default `base` first, so that the merge
    /// factors share it), renders the exact reference once per glass opacity, and merges and
    /// measures each distinct bake once.
    fn bake_all(&self, base: RecordSettings, variants: &[Variant]) -> Result<Bakes, BenchError> {
        let mut recording_order: Vec<RecordSettings> = vec![base];
        for v in variants {
            if !recording_order
                .iter()
                .any(|s| same_settings(s, &v.settings))
            {
                recording_order.push(v.settings);
            }
        }
        let mut references: HashMap<u32, Vec<Vec<u8>>> = HashMap::new();
        // The robust factor's references under each off-pattern condition, rendered once.
        let mut elsewhere: Option<Vec<Vec<Vec<u8>>>> = None;
        let mut measured: Bakes = Vec::new();
        let mut done = 0usize;
        // Every bake is lit by the studio, as `bake` lights it by default: made once here.
        let studio = trisort_bake::Light::Studio.load()?;
        for settings in &recording_order {
            let users: Vec<&Variant> = variants
                .iter()
                .filter(|v| same_settings(&v.settings, settings))
                .collect();
            if users.is_empty() {
                continue;
            }
            let (rec, record_seconds) = self.record(*settings)?;
            let glass_key = settings.glass_opacity.to_bits();
            for v in users {
                done += 1;
                let step = format!(
                    "sweep [{done}/{}] {} = {}",
                    variants.len(),
                    v.factor,
                    v.value
                );
                let known = measured
                    .iter()
                    .any(|(s, m, _)| same_settings(s, settings) && *m == v.merge);
                if known {
                    (self.progress)(&format!("{step}: same bake as before"));
                    continue;
                }
                (self.progress)(&format!("{step}: merging"));
                let t = Instant::now();
                let merged = trisort_merger::merge(std::slice::from_ref(&rec), &v.merge)?;
                let merge_seconds = t.elapsed().as_secs_f64();
                let baked = merged.lit(studio.clone());
                // The reference lights like the bake: with its environment.
                if let Entry::Vacant(slot) = references.entry(glass_key) {
                    slot.insert(self.reference_frames(settings.glass_opacity, &baked.environment)?);
                }
                let reference = &references[&glass_key];
                let mut m = measure(
                    self.gpu,
                    &baked,
                    self.config,
                    self.frames,
                    reference,
                    record_seconds,
                    merge_seconds,
                )?;
                if v.factor == Factor::Robust {
                    if elsewhere.is_none() {
                        (self.progress)(&format!(
                            "sweep: exact reference under {} off-pattern conditions",
                            robustness::conditions(self.config.size).len()
                        ));
                        elsewhere = Some(robustness::references(
                            self.gpu,
                            &self.scene.geometry,
                            &self.timeline.frames,
                            self.config,
                            self.frames,
                            settings.glass_opacity,
                            &baked.environment,
                        )?);
                    }
                    m.robustness = robustness::measure(
                        self.gpu,
                        &self.scene.geometry,
                        &baked,
                        self.config,
                        self.frames,
                        elsewhere.as_ref().expect("rendered above"),
                    )?;
                    let holes: Vec<String> = m
                        .robustness
                        .iter()
                        .map(|e| format!("{} {}", e.condition, e.holes))
                        .collect();
                    (self.progress)(&format!("{step}: holes {}", holes.join(", ")));
                }
                (self.progress)(&format!(
                    "{step}: merge {:.2} s, {} index triangles, {:.1} draws/frame, error {} px, FLIP {:.4}",
                    merge_seconds, m.stats.index_triangles,
                    m.stats.draws_per_frame_mean, m.pixels_differing, mean(&m.flip)
                ));
                measured.push((*settings, v.merge, m));
            }
        }
        Ok(measured)
    }

    /// The report: one point per variant (the default recording is `base`), and the default
    /// bake's draws along the path.
    fn report(&self, base: RecordSettings, variants: &[Variant], measured: &Bakes) -> SweepReport {
        let (w, h) = self.config.size;
        let pixels = self.frames.len() as f64 * w as f64 * h as f64;
        let points: Vec<SweepPoint> = variants
            .iter()
            .map(|v| {
                let m = find(measured, v);
                let includes = v.factor.records();
                SweepPoint {
                    factor: v.factor.name().to_string(),
                    value: v.value.clone(),
                    is_default: same_settings(&v.settings, &base)
                        && v.merge == MergeOptions::default(),
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
                    source_triangles_per_frame: m.stats.source_triangles as f64
                        / self.timeline.frames.len().max(1) as f64,
                    robustness: if v.factor == Factor::Robust {
                        m.robustness.clone()
                    } else {
                        Vec::new()
                    },
                }
            })
            .collect();
        let default = measured
            .iter()
            .find(|(s, m, _)| same_settings(s, &base) && *m == MergeOptions::default())
            .map(|x| &x.2);
        SweepReport {
            device: self.gpu.describe(),
            size: self.config.size,
            samples: self.config.samples,
            frames: self.frames.to_vec(),
            path_frames: self.timeline.frames.len() as u32,
            scene_triangles: self.scene.geometry.triangles.len() as u64,
            default_merge: default.map_or(String::new(), |m| m.strategy_layout.clone()),
            points,
            draws_along_path: default.map_or(Vec::new(), |m| {
                m.draws
                    .iter()
                    .enumerate()
                    .map(|(f, &d)| (f as u32, d))
                    .collect()
            }),
        }
    }

    /// Records `settings` over the whole path (both phases), in memory; returns the
    /// recording and its wall time in seconds.
    fn record(&self, settings: RecordSettings) -> Result<(Recording, f64), BenchError> {
        (self.progress)(&format!(
            "sweep: recording {}x{}, {} samples, saturation {}, glass {}, robust {} ({} frames)",
            settings.width,
            settings.height,
            settings.samples,
            number(settings.saturation),
            number(settings.glass_opacity),
            super::factors::robust_name(&settings.robust),
            self.timeline.frames.len()
        ));
        let t = Instant::now();
        let target = RecordTarget {
            settings: &settings,
            frames: None,
            phase: Phase::Graphs,
            known_visible: None,
        };
        let rec = record_in_memory(self.gpu, self.scene, self.timeline, target, &mut Silent)?;
        if let Some(f) = rec.frames.iter().find(|f| f.truncated) {
            return Err(BenchError::Invalid(format!(
                "frame {} hit the layer bound ({}) while recording {}x{}",
                f.frame, settings.max_layers, settings.width, settings.height
            )));
        }
        let seconds = t.elapsed().as_secs_f64();
        (self.progress)(&format!(
            "sweep: recorded in {seconds:.2} s: |G| = {} of {} triangles",
            rec.unique_visible.len(),
            rec.scene_triangles
        ));
        Ok((rec, seconds))
    }

    /// The exact reference's frames at the playback settings with glass opacity `glass`, lit
    /// by `environment`.
    fn reference_frames(
        &self,
        glass: f32,
        environment: &trisort_format::Environment,
    ) -> Result<Vec<Vec<u8>>, BenchError> {
        let config = self.config;
        (self.progress)(&format!(
            "sweep: exact reference at {}x{}, {} samples, glass {}: {} frames",
            config.size.0,
            config.size.1,
            config.samples,
            number(glass),
            self.frames.len()
        ));
        let reference = ExactReference::new(
            self.gpu,
            &self.scene.geometry,
            &self.timeline.frames,
            trisort_gpu::Lighting::pbr(environment),
            ReferenceConfig {
                size: config.size,
                samples: config.samples,
                mode: Mode::Blend,
                glass_opacity: glass,
                max_layers: 4096,
            },
        )?;
        self.frames
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
}
