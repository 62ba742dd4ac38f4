//! Benchmark support: the cost of one peel pass, and of the capture pass that replaces a
//! frame's peel passes, against a plain pass over the same triangles, measured in the same
//! run (ratios, not absolute times, are what transfer between machines).

use std::time::Instant;

use trisort_format::{FrameState, Geometry};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Gpu;

use crate::capture::Capture;
use crate::peeler::Peeler;
use crate::RecordError;

/// Wall times of one pass, median over the repeats, in milliseconds.
#[derive(Clone, Copy, Debug)]
pub struct PassCost {
    /// A peel layer, mean over the first three of the frame (the first; the second, the
    /// discard test against the previous layer active; and the check for more), including the
    /// gather pass and phase 1's readback (ids and alpha). Until 2026-12 this divided three
    /// layers' time by two, overstating it by 1.5×.
    pub peel_ms: f64,
    /// The same layer's render pass alone (no gather, no readback).
    pub peel_render_ms: f64,
    /// The pass that replaces all of a frame's phase-1 peel passes where the device can
    /// (`capture.wgsl`: the depth prepass of the always-opaque triangles, then every fragment
    /// in front of them at every sample onto per-sample lists), over the same triangles,
    /// without reading the lists back. `None` where the device cannot capture.
    pub capture_render_ms: Option<f64>,
    /// The same capture with reading back the lists and sorting every sample's fragments into
    /// peel order (what phase 1 then walks). `None` where the device cannot capture.
    pub capture_ms: Option<f64>,
    /// A plain pass: the same triangles, same vertex stage, depth test `Less`, one colour
    /// written per pixel (no per-sample shading, no discard test), same MSAA count.
    pub plain_ms: f64,
}

/// Measures [`PassCost`] at `frame` with `repeats` repetitions of each pass, interleaved.
pub fn pass_cost(
    gpu: &Gpu,
    geometry: &Geometry,
    frames: &[FrameState],
    view: View,
    frame: u32,
    repeats: u32,
) -> Result<PassCost, RecordError> {
    let all: Vec<u32> = (0..geometry.triangles.len() as u32).collect();
    let peeler = Peeler::new(gpu, geometry, &all, frames, view)?.with_readback(true, false);
    let mut capture = if crate::capture::supported(gpu) {
        Some(Capture::new(
            gpu,
            geometry,
            &all,
            frames,
            view,
            true,
            &Default::default(),
        )?)
    } else {
        None
    };
    let (mut peel, mut render, mut plain) = (vec![], vec![], vec![]);
    let (mut captured, mut capture_render) = (vec![], vec![]);
    // Warm up pipelines (and grow the capture's pool to the frame).
    peeler.time_render(frame, 1, false)?;
    peeler.time_render(frame, 1, true)?;
    if let Some(c) = capture.as_mut() {
        c.frame(frame, |_| Ok(()))?;
    }
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        let (before, _) = crate::readback_counters();
        // The first and second layers, then a third to learn whether anything is left (a
        // peel stopped at `max_layers` renders and reads back one layer more): divide by the
        // layers actually peeled, counted.
        peeler.peel(frame, 2, |_, _, _| Ok(true))?;
        let layers = (crate::readback_counters().0 - before).max(1);
        peel.push(t.elapsed().as_secs_f64() * 1000.0 / layers as f64);
        render.push(peeler.time_render(frame, 1, false)?);
        plain.push(peeler.time_render(frame, 1, true)?);
        if let Some(c) = capture.as_mut() {
            capture_render.push(c.time_draw(frame)?);
            let t = Instant::now();
            let mut list = Vec::new();
            c.frame(frame, |band| {
                for slot in 0..band.slots() {
                    band.sorted(slot, &mut list);
                }
                Ok(())
            })?;
            captured.push(t.elapsed().as_secs_f64() * 1000.0);
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(|a, b| a.total_cmp(b));
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    Ok(PassCost {
        peel_ms: median(&mut peel),
        peel_render_ms: median(&mut render),
        plain_ms: median(&mut plain),
        capture_render_ms: capture.as_ref().map(|_| median(&mut capture_render)),
        capture_ms: capture.as_ref().map(|_| median(&mut captured)),
    })
}
