//! The sweep itself: one recording per distinct recording settings, one exact reference per
//! glass opacity, one merge and measurement per distinct bake.

use std::collections::HashMap;
use std::path::Path;
use std::time::Instant;

use trisort_format::{Phase, RecordSettings, Recording};
use trisort_gpu::Gpu;
use trisort_merger::MergeOptions;
use trisort_player::Mode;
use trisort_recorder::RecordJob;
use trisort_reference::{ExactReference, ReferenceConfig};

use super::factors::{default_merge, number, same_settings, variants, Factor, Variant};
use super::measurement::{max, mean, measure, Measured};
use super::output::write_outputs;
use super::{SweepConfig, SweepPoint, SweepReport, MAX_LAYERS};
use crate::BenchError;

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
