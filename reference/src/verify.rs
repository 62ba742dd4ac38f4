//! Image verification of a baked file (`trisort verify --scene`): each frame played by the
//! player against the exact reference of the full scene, at the same size, sample count and
//! mode.
//!
//! The rule ([`ImageCheck`]):
//! - At the recorded pattern (the file's size and sample count, on its recording device):
//!   `depth` fails a frame that is not bit-exact on its ordered pixels (those without an
//!   unordered sample: there the file itself says the order is broken, and a transparent
//!   fragment drawn after a farther one still blends over it); `blend` and `saturate` fail a
//!   frame with an ordered pixel more than 1/255 off in a colour channel. A truncated
//!   reference peel fails too.
//! - Off the pattern (another size, sample count or device): the error is measured, and a
//!   frame fails only when `max_error` is given and its `max_channel_diff_ordered` (the largest
//!   colour-channel difference on ordered pixels, in 1/255 units) exceeds it.
//!
//! The 8-bit sRGB deployment error is measured alongside when asked and never gates.

use serde::Serialize;
use trisort_format::{Baked, Geometry};
use trisort_gpu::Gpu;
use trisort_player::{HeadlessConfig, HeadlessRenderer, Mode};

use crate::compare::{compare, Comparison};
use crate::deploy::Srgb8Player;
use crate::exact::{ExactReference, ReferenceConfig, ReferenceFrame, RemovedEdges};
use crate::ReferenceError;

/// What to verify.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageCheck {
    /// Size (width, height); the recorded one for the recorded pattern.
    pub size: (u32, u32),
    /// MSAA samples; the recorded count for the recorded pattern.
    pub samples: u32,
    /// Compositing mode.
    pub mode: Mode,
    /// Off the pattern: fail a frame whose `max_channel_diff_ordered` exceeds this (1/255
    /// units); `None` measures without failing. Ignored at the recorded pattern.
    pub max_error: Option<u8>,
    /// Also measure the player on an 8-bit sRGB target.
    pub srgb8: bool,
}

impl ImageCheck {
    /// The recorded pattern of `baked` in `mode`, with the sRGB figure.
    pub fn recorded(baked: &Baked, mode: Mode) -> ImageCheck {
        ImageCheck {
            size: (baked.settings.width, baked.settings.height),
            samples: baked.settings.samples.max(1),
            mode,
            max_error: None,
            srgb8: true,
        }
    }
}

/// One frame's figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrameImageReport {
    /// Frame index.
    pub frame: u32,
    /// Whether the frame passes the rule (see the module documentation).
    pub ok: bool,
    /// Samples whose consecutive peel fragments form an edge the merger removed, as the
    /// reference's peel finds them.
    pub unordered_samples: u64,
    /// The removed edges' total weight as the baked file records it.
    pub unordered_samples_recorded: u64,
    /// Pixels with at least one unordered sample.
    pub unordered_pixels: u64,
    /// The player's frame against the reference.
    #[serde(flatten)]
    pub comparison: Comparison,
    /// Peel layers of the reference.
    pub layers: u32,
    /// Whether the reference peel was cut at its layer bound.
    pub truncated: bool,
    /// The player on an 8-bit sRGB target against the reference (never gated on).
    pub srgb8: Option<Comparison>,
}

/// A verified frame with its images (RGBA8, sRGB) for difference output.
pub struct VerifiedFrame {
    /// The figures.
    pub report: FrameImageReport,
    /// The player's frame.
    pub player: Vec<u8>,
    /// The reference.
    pub reference: ReferenceFrame,
}

/// A baked file, its full scene and the renderers to compare them frame by frame.
pub struct ImageVerifier<'g> {
    check: ImageCheck,
    at_pattern: bool,
    player: HeadlessRenderer<'g>,
    reference: ExactReference<'g>,
    srgb8: Option<Srgb8Player<'g>>,
    removed: RemovedEdges,
}

impl<'g> ImageVerifier<'g> {
    /// Sets up verification of `baked` against the full scene `geometry` (the one whose hash
    /// the file records; the caller checks the hash). Errors on a scene that lacks triangles
    /// the file names, or where the renderers cannot be created.
    pub fn new(
        gpu: &'g Gpu,
        baked: &Baked,
        geometry: &Geometry,
        check: ImageCheck,
    ) -> Result<ImageVerifier<'g>, ReferenceError> {
        let removed = RemovedEdges::of_baked(baked, geometry.triangles.len())?;
        let s = &baked.settings;
        let at_pattern = check.size == (s.width, s.height)
            && check.samples == s.samples.max(1)
            && gpu.device_info() == baked.device;
        let player = HeadlessRenderer::new(
            gpu,
            baked,
            &HeadlessConfig {
                size: check.size,
                samples: check.samples,
                mode: check.mode,
                glass_opacity: None,
                draw_path: None,
                force_u32: false,
            },
        )?;
        let reference = ExactReference::new(
            gpu,
            geometry,
            &baked.frame_states,
            ReferenceConfig {
                size: check.size,
                samples: check.samples,
                ..ReferenceConfig::recorded(baked, check.mode)
            },
        )?;
        let srgb8 = if check.srgb8 {
            Some(Srgb8Player::new(
                gpu,
                baked,
                check.size,
                check.samples,
                check.mode,
            )?)
        } else {
            None
        };
        Ok(ImageVerifier {
            check,
            at_pattern,
            player,
            reference,
            srgb8,
            removed,
        })
    }

    /// Whether frames are checked at the recorded pattern (size, samples and device).
    pub fn at_recorded_pattern(&self) -> bool {
        self.at_pattern
    }

    /// Plays, references and compares frame `frame`.
    pub fn verify(&self, frame: u32) -> Result<VerifiedFrame, ReferenceError> {
        let (w, h) = self.check.size;
        let played = self.player.render(frame)?;
        let reference = self.reference.render(frame, Some(&self.removed))?;
        let comparison = compare(&played.rgba8, &reference.rgba8, w, h, &reference.unordered);
        let srgb8 = match &self.srgb8 {
            Some(p) => Some(compare(
                &p.render(frame)?,
                &reference.rgba8,
                w,
                h,
                &reference.unordered,
            )),
            None => None,
        };
        let ok = if self.at_pattern {
            !reference.truncated
                && match self.check.mode {
                    Mode::Depth => comparison.pixels_differing_ordered == 0,
                    Mode::Blend | Mode::Saturate => comparison.pixels_over_tolerance_ordered == 0,
                }
        } else {
            self.check
                .max_error
                .is_none_or(|m| comparison.max_channel_diff_ordered <= m)
        };
        let report = FrameImageReport {
            frame,
            ok,
            unordered_samples: reference.unordered_samples,
            unordered_samples_recorded: self.removed.recorded_weight(frame),
            unordered_pixels: reference.unordered.iter().filter(|&&u| u).count() as u64,
            comparison,
            layers: reference.layers,
            truncated: reference.truncated,
            srgb8,
        };
        Ok(VerifiedFrame {
            report,
            player: played.rgba8,
            reference,
        })
    }
}
