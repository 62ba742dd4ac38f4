//! The sweep's "played elsewhere" error axis: each point of the `robust` factor is played off
//! its recorded sample pattern, as another rasterizer or another size would play it, and its
//! error is split into holes and order errors.
//!
//! Conditions ([`conditions`]): the projection shifted by 1/16, 1/8 and 1/4 px in x (a test
//! aid standing for another GPU's snapping, `play --subpixel-offset`), and played at 1.5× and
//! 2× the playback size. In each, per compared frame:
//! - `holes`: pixels where a scene triangle the frame does not draw is the nearest surface at
//!   some sample (the background or the interior shows where the scene has a surface): the
//!   depth-mode frame against the z-buffer of the frame's window followed by every scene
//!   triangle ([`trisort_player::SelfCheck::against_scene`]);
//! - `blend_differing`: pixels of the blend-mode frame differing from the exact reference
//!   shifted or sized the same way;
//! - `order_errors`: those of them that are not holes (drawn, but in an order the recorded
//!   pattern did not constrain).

use serde::Serialize;
use trisort_format::Baked;
use trisort_gpu::Gpu;
use trisort_player::headless::{HeadlessConfig, HeadlessRenderer};
use trisort_player::{Mode, SelfCheck};
use trisort_reference::{ExactReference, ReferenceConfig};

use super::SweepConfig;
use crate::BenchError;

/// One way of playing a bake away from its recorded pattern.
#[derive(Clone, Debug, PartialEq)]
pub struct Condition {
    /// Its name in the outputs (`offset 1/16`, `size 1.5x`).
    pub name: String,
    /// Playback size.
    pub size: (u32, u32),
    /// Projection shift in pixels (x right, y down).
    pub offset: [f64; 2],
}

/// The conditions for playback `size`: offsets of 1/512 (the conformant raster profile's
/// tolerance), 1/16, 1/8 and 1/4 px in x, then 1.5× and 2× the size.
pub fn conditions(size: (u32, u32)) -> Vec<Condition> {
    let mut out: Vec<Condition> = [(512, "1/512"), (16, "1/16"), (8, "1/8"), (4, "1/4")]
        .into_iter()
        .map(|(d, name)| Condition {
            name: format!("offset {name}"),
            size,
            offset: [1.0 / d as f64, 0.0],
        })
        .collect();
    for (k, name) in [(1.5, "1.5x"), (2.0, "2x")] {
        let scale = |v: u32| ((v as f64 * k).round() as u32).max(1);
        out.push(Condition {
            name: format!("size {name}"),
            size: (scale(size.0), scale(size.1)),
            offset: [0.0, 0.0],
        });
    }
    out
}

/// One bake's error under one [`Condition`], summed over the compared frames.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ConditionError {
    /// [`Condition::name`].
    pub condition: String,
    /// Pixels where a triangle the frame leaves out is the nearest surface.
    pub holes: u64,
    /// `holes` ÷ (compared frames × pixels at the condition's size).
    pub holes_fraction: f64,
    /// Blend-mode pixels differing from the exact reference under the condition.
    pub blend_differing: u64,
    /// Of those, the pixels that are not holes.
    pub order_errors: u64,
}

/// The exact reference's blend frames under each condition (glass at `glass`), lit by the
/// bake's `environment`.
pub(super) fn references(
    gpu: &Gpu,
    scene: &trisort_format::Geometry,
    path: &[trisort_format::FrameState],
    config: &SweepConfig,
    frames: &[u32],
    glass: f32,
    environment: &trisort_format::Environment,
) -> Result<Vec<Vec<Vec<u8>>>, BenchError> {
    // One reference per size: the offset conditions share it (only the offset changes).
    let mut at: Option<((u32, u32), ExactReference)> = None;
    let mut out = Vec::new();
    for c in conditions(config.size) {
        if at.as_ref().is_none_or(|(size, _)| *size != c.size) {
            let reference = ExactReference::new(
                gpu,
                scene,
                path,
                trisort_gpu::Lighting::pbr(environment),
                ReferenceConfig {
                    size: c.size,
                    samples: config.samples,
                    mode: Mode::Blend,
                    glass_opacity: glass,
                    max_layers: 4096,
                },
            )?;
            at = Some((c.size, reference));
        }
        let (_, reference) = at.as_ref().expect("set above");
        reference.set_subpixel_offset(c.offset);
        out.push(
            frames
                .iter()
                .map(|&f| Ok(reference.render(f, None)?.rgba8))
                .collect::<Result<Vec<_>, BenchError>>()?,
        );
    }
    Ok(out)
}

/// `baked`'s error under each condition against `references` (from [`references`], same
/// conditions and frames).
pub(super) fn measure(
    gpu: &Gpu,
    scene: &trisort_format::Geometry,
    baked: &Baked,
    config: &SweepConfig,
    frames: &[u32],
    references: &[Vec<Vec<u8>>],
) -> Result<Vec<ConditionError>, BenchError> {
    let mut out = Vec::new();
    // The check and the player at the current size: the offset conditions share one size, so
    // they share the renderers (only the projection's offset changes between them).
    let mut at: Option<((u32, u32), SelfCheck, HeadlessRenderer)> = None;
    for (c, reference) in conditions(config.size).iter().zip(references) {
        if at.as_ref().is_none_or(|(size, _, _)| *size != c.size) {
            let check = SelfCheck::against_scene(gpu, baked, scene, c.size, config.samples)?;
            let player = HeadlessRenderer::new(
                gpu,
                baked,
                &HeadlessConfig {
                    size: c.size,
                    samples: config.samples,
                    ..HeadlessConfig::recorded(baked)
                },
            )?;
            at = Some((c.size, check, player));
        }
        let (_, check, player) = at.as_ref().expect("set above");
        check.set_subpixel_offset(c.offset);
        player.set_subpixel_offset(c.offset);
        let mut e = ConditionError {
            condition: c.name.clone(),
            holes: 0,
            holes_fraction: 0.0,
            blend_differing: 0,
            order_errors: 0,
        };
        for (&f, reference) in frames.iter().zip(reference) {
            let holes = check.images(f)?.mask;
            let played = player.render(f)?.rgba8;
            for (k, hole) in holes.iter().enumerate() {
                let differs = played[k * 4..k * 4 + 3] != reference[k * 4..k * 4 + 3];
                e.holes += *hole as u64;
                e.blend_differing += differs as u64;
                e.order_errors += (differs && !hole) as u64;
            }
        }
        let pixels = frames.len() as f64 * c.size.0 as f64 * c.size.1 as f64;
        e.holes_fraction = if pixels > 0.0 {
            e.holes as f64 / pixels
        } else {
            0.0
        };
        out.push(e);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conditions_are_four_offsets_and_two_sizes() {
        let c = conditions((128, 64));
        let names: Vec<_> = c.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "offset 1/512",
                "offset 1/16",
                "offset 1/8",
                "offset 1/4",
                "size 1.5x",
                "size 2x"
            ]
        );
        assert_eq!(c[0].offset, [1.0 / 512.0, 0.0]);
        assert_eq!(c[1].offset, [0.0625, 0.0]);
        assert_eq!(c[0].size, (128, 64));
        assert_eq!((c[4].size, c[5].size), ((192, 96), (256, 128)));
        assert_eq!(c[5].offset, [0.0, 0.0]);
    }
}
