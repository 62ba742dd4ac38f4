//! Benchmark support: the cost of one peel pass against a plain pass over the same triangles,
//! measured in the same run (ratios, not absolute times, are what transfer between machines).

use std::time::Instant;

use trisort_format::{FrameState, Geometry};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Gpu;

use crate::peeler::Peeler;
use crate::RecordError;

/// Wall times of one pass, median over the repeats, in milliseconds.
#[derive(Clone, Copy, Debug)]
pub struct PassCost {
    /// A peel layer after the first (the discard test against the previous layer active),
    /// including the gather pass and the readback the recorder needs per layer.
    pub peel_ms: f64,
    /// The same layer's render pass alone (no gather, no readback).
    pub peel_render_ms: f64,
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
    let peeler = Peeler::new(gpu, geometry, &all, frames, view)?;
    let (mut peel, mut render, mut plain) = (vec![], vec![], vec![]);
    // Warm up pipelines.
    peeler.time_render(frame, 1, false)?;
    peeler.time_render(frame, 1, true)?;
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        peeler.peel(frame, 2, |_, _, _| Ok(true))?;
        // Two layers were peeled (first and second); the second is the steady-state pass.
        peel.push(t.elapsed().as_secs_f64() * 1000.0 / 2.0);
        render.push(peeler.time_render(frame, 1, false)?);
        plain.push(peeler.time_render(frame, 1, true)?);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(|a, b| a.total_cmp(b));
        v[v.len() / 2]
    };
    Ok(PassCost {
        peel_ms: median(&mut peel),
        peel_render_ms: median(&mut render),
        plain_ms: median(&mut plain),
    })
}
