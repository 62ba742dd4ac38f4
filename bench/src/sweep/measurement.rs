//! What one bake measures: its size and figures, its play time and its error against the
//! exact reference.

use std::time::Instant;

use trisort_format::{Baked, FileKind};
use trisort_gpu::Gpu;
use trisort_player::headless::{HeadlessConfig, HeadlessRenderer};
use trisort_player::Mode;
use trisort_reference::compare;

use super::{SweepConfig, PLAY_REPEATS};
use crate::BenchError;

/// What a bake measured, shared by identical variants.
#[derive(Clone, Debug)]
pub(super) struct Measured {
    pub(super) record_seconds: f64,
    pub(super) merge_seconds: f64,
    pub(super) baked_bytes: u64,
    pub(super) strategy_layout: String,
    pub(super) stats: trisort_format::MergeStats,
    pub(super) draws: Vec<u32>,
    pub(super) play_ms: Vec<f64>,
    pub(super) wall_ms: Vec<f64>,
    pub(super) pixels_differing: u64,
    pub(super) max_channel_diff: u8,
    pub(super) flip: Vec<f64>,
    /// Played off the recorded pattern (the robust factor's points only).
    pub(super) robustness: Vec<super::robustness::ConditionError>,
}

/// Size, figures, play time and error of one bake.
pub(super) fn measure(
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
            ..HeadlessConfig::recorded(baked)
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
        robustness: Vec::new(),
    })
}

pub(super) fn median(v: &mut [f64]) -> f64 {
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

pub(super) fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        f64::NAN
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

pub(super) fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NAN, f64::max)
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
}
