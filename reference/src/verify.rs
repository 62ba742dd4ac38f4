//! Image verification of a baked file (`trisort verify --scene`): each frame played by the
//! player (or captured elsewhere: `--frames-dir`) against the exact reference of the full
//! scene, at the same size, sample count and mode.
//!
//! What may differ comes from the recordings, never from the baked file (a file cannot excuse its
//! own errors): a pixel is *unordered*, and excused, only when one of its samples has consecutive
//! peel fragments a, b with a → b an edge on a cycle of the recording's E_f
//! ([`UnorderedEdges::of_recordings`]). Without a recording no pixel is excused. With one, the
//! reference also takes the path (cameras, poses), the recorded pattern and the recording device
//! from it, not from the file.
//!
//! The rule ([`ImageCheck`]):
//! - At the recorded pattern (the recorded size and sample count, no sub-pixel offset, on
//!   whatever device: the device a file names is the file's word, and a renamed one once
//!   turned a check into a measurement that passed a reversed buffer):
//!   `depth` fails a frame that is not bit-exact on its ordered pixels (a transparent
//!   fragment drawn after a farther one still blends over it); `blend` and `saturate` fail a
//!   frame with an ordered pixel more than 1/255 off in a colour channel. A truncated
//!   reference peel fails too. Frames captured elsewhere are held to the same rule at the
//!   recorded size and sample count, whatever their device (that is what signing off a head
//!   unit's frames means).
//! - Off the pattern (another size or sample count, or a sub-pixel offset): the error is
//!   measured, and a frame fails only when `max_error` is given and its
//!   `max_channel_diff_ordered` (the largest colour-channel difference on ordered pixels, in
//!   1/255 units) exceeds it.
//!
//! The 8-bit sRGB deployment error is measured alongside when asked and never gates.

use serde::Serialize;
use trisort_format::{Baked, DeviceInfo, FrameState, Geometry, RecordSettings, Recording};
use trisort_gpu::{Gpu, Lighting, Shading, ToneMap};
use trisort_player::{HeadlessConfig, HeadlessRenderer, Mode};

use crate::compare::{compare, holes_and_order_errors, Comparison};
use crate::deploy::Srgb8Player;
use crate::exact::{DrawnSets, ExactReference, ReferenceConfig, ReferenceFrame, UnorderedEdges};
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
    /// The frames are captured elsewhere ([`ImageVerifier::verify_captured`]): no player and
    /// no sRGB figure here, and the recorded pattern is the recorded size and sample count
    /// whatever the device that drew them.
    pub captured: bool,
    /// Shift of the projection in pixels (x right, y down) applied to the player and to the
    /// exact reference alike (`verify --subpixel-offset`, a test aid standing for another
    /// GPU's vertex snapping); anything but zero is off the recorded pattern.
    pub subpixel_offset: [f64; 2],
    /// Surface model of the player and the reference alike (both light with the baked file's
    /// environment).
    pub shading: Shading,
    /// Tone map of [`Shading::Pbr`].
    pub tone_map: ToneMap,
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
            captured: false,
            subpixel_offset: [0.0, 0.0],
            shading: Shading::Pbr,
            tone_map: ToneMap::Neutral,
        }
    }

    /// Whether this check is at the recorded pattern of `settings` (the recording's, or the
    /// file's without one): the recorded size and sample count, no sub-pixel offset, on
    /// whatever device (the device a file names is the file's word).
    pub fn at_recorded_pattern(&self, settings: &RecordSettings) -> bool {
        self.size == (settings.width, settings.height)
            && self.samples == settings.samples.max(1)
            && self.subpixel_offset == [0.0, 0.0]
    }
}

/// One frame's figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrameImageReport {
    /// Frame index.
    pub frame: u32,
    /// Whether the frame passes the rule (see the module documentation).
    pub ok: bool,
    /// Samples whose consecutive peel fragments form an edge on a cycle of the recording's
    /// E_f (excusable), as the reference's peel finds them; 0 without a recording.
    pub unordered_samples: u64,
    /// The recording's weight of those edges in this frame: at the recorded pattern the peel
    /// finds exactly these samples.
    pub unordered_samples_recorded: u64,
    /// Pixels with at least one unordered sample.
    pub unordered_pixels: u64,
    /// The player's (or the captured) frame against the reference.
    #[serde(flatten)]
    pub comparison: Comparison,
    /// Samples whose nearest fragment in the reference (in the tie rule's order; in `depth`,
    /// the first the depth test passes) is of a triangle the file does not draw in the frame.
    pub hole_samples: u64,
    /// Pixels that differ (depth: at all; blend, saturate: by more than 1/255) and have a
    /// hole sample: something the file should draw is missing.
    pub hole_pixels: u64,
    /// Ordered pixels that differ as much without a hole sample: what is drawn is drawn in
    /// the wrong order (or wrongly otherwise).
    pub order_error_pixels: u64,
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
    /// The player's frame, or the captured one.
    pub player: Vec<u8>,
    /// The reference.
    pub reference: ReferenceFrame,
}

/// What the reference is rendered from: the recordings where given, else the baked file.
struct Truth<'a> {
    settings: RecordSettings,
    device: &'a DeviceInfo,
    frame_states: &'a [FrameState],
    /// Excusable edges; `None`: no pixel is excused.
    unordered: Option<UnorderedEdges>,
}

impl<'a> Truth<'a> {
    fn new(
        baked: &'a Baked,
        recordings: &'a [Recording],
        scene_triangles: usize,
        mode: Mode,
    ) -> Result<Truth<'a>, ReferenceError> {
        let Some(first) = recordings.first() else {
            return Ok(Truth {
                settings: baked.settings,
                device: &baked.device,
                frame_states: &baked.frame_states,
                unordered: None,
            });
        };
        let path = first.frame_states.len();
        if recordings
            .iter()
            .any(|r| r.frame_states != first.frame_states)
        {
            return Err(ReferenceError::Invalid(
                "the recordings are of different paths".into(),
            ));
        }
        if path != baked.frames.len() {
            return Err(ReferenceError::Invalid(format!(
                "the recorded path has {path} frames, the baked file {}",
                baked.frames.len()
            )));
        }
        // A depth-only file holds only the edges depth mode needs, and is its own order only
        // where the depth test is on.
        let depth_mode = baked.merge.depth_only && mode == Mode::Depth;
        let unordered = UnorderedEdges::of_recordings(recordings, depth_mode, scene_triangles)?;
        Ok(Truth {
            settings: first.settings,
            device: &first.device,
            frame_states: &first.frame_states,
            unordered: Some(unordered),
        })
    }
}

/// A baked file, its full scene and the renderers to compare them frame by frame.
pub struct ImageVerifier<'g> {
    check: ImageCheck,
    at_pattern: bool,
    /// Frames are played here on a device other than the one the recording (or, without
    /// one, the file) names.
    other_device: bool,
    /// `None` for frames captured elsewhere.
    player: Option<HeadlessRenderer<'g>>,
    reference: ExactReference<'g>,
    srgb8: Option<Srgb8Player<'g>>,
    unordered: Option<UnorderedEdges>,
    /// What the file draws, for telling holes.
    drawn: DrawnSets,
    /// Triangles of the scene.
    scene_triangles: usize,
}

impl<'g> ImageVerifier<'g> {
    /// Sets up verification of `baked` against the full scene `geometry` (the one whose hash
    /// the file records; the caller checks the hash) and, where given, the `recordings` it was
    /// merged from (the caller checks they are of this scene): they decide which pixels may
    /// be unordered and give the reference its path and pattern. Errors on a scene that lacks
    /// triangles the files name, recordings of another path or length, or where the renderers
    /// cannot be created.
    pub fn new(
        gpu: &'g Gpu,
        baked: &Baked,
        geometry: &Geometry,
        check: ImageCheck,
        recordings: &[Recording],
    ) -> Result<ImageVerifier<'g>, ReferenceError> {
        let truth = Truth::new(baked, recordings, geometry.triangles.len(), check.mode)?;
        let s = &truth.settings;
        // The device the file (or the recording) names does not decide: a file that named
        // another device would otherwise be measured only, and pass, however wrong. Frames
        // played here on another device are held to the recorded pattern's rule, as frames
        // captured elsewhere are; the report says so.
        let at_pattern = check.at_recorded_pattern(s);
        let other_device = !check.captured && gpu.device_info() != *truth.device;
        let player = if check.captured {
            None
        } else {
            Some(HeadlessRenderer::new(
                gpu,
                baked,
                &HeadlessConfig {
                    size: check.size,
                    samples: check.samples,
                    mode: check.mode,
                    glass_opacity: None,
                    draw_path: None,
                    force_u32: false,
                    shading: check.shading,
                    tone_map: check.tone_map,
                    decode_textures: false,
                },
            )?)
        };
        let reference = ExactReference::new(
            gpu,
            geometry,
            truth.frame_states,
            Lighting {
                shading: check.shading,
                tone_map: check.tone_map,
                environment: &baked.environment,
            },
            ReferenceConfig {
                size: check.size,
                samples: check.samples,
                mode: check.mode,
                glass_opacity: s.glass_opacity,
                max_layers: 4096,
            },
        )?;
        let srgb8 = if check.srgb8 && !check.captured {
            Some(Srgb8Player::with_shading(
                gpu,
                baked,
                check.size,
                check.samples,
                check.mode,
                (check.shading, check.tone_map),
            )?)
        } else {
            None
        };
        let verifier = ImageVerifier {
            check,
            at_pattern,
            other_device,
            player,
            reference,
            srgb8,
            unordered: truth.unordered,
            drawn: DrawnSets::new(baked),
            scene_triangles: geometry.triangles.len(),
        };
        if check.subpixel_offset != [0.0, 0.0] {
            verifier.shift(check.subpixel_offset);
        }
        Ok(verifier)
    }

    /// Shifts the projection of the player, the sRGB player and the exact reference by
    /// `offset` pixels ([`ImageCheck::subpixel_offset`]).
    fn shift(&self, offset: [f64; 2]) {
        if let Some(p) = &self.player {
            p.set_subpixel_offset(offset);
        }
        if let Some(p) = &self.srgb8 {
            p.set_subpixel_offset(offset);
        }
        self.reference.set_subpixel_offset(offset);
    }

    /// Whether frames are checked at the recorded pattern (size, sample count, no sub-pixel
    /// offset), whatever device plays them.
    pub fn at_recorded_pattern(&self) -> bool {
        self.at_pattern
    }

    /// Whether frames are played here on a device other than the one the recording (or,
    /// without one, the baked file) names: checked all the same, where at the recorded
    /// pattern.
    pub fn on_other_device(&self) -> bool {
        self.other_device
    }

    /// Plays, references and compares frame `frame`. Errors for a verifier of captured
    /// frames.
    pub fn verify(&self, frame: u32) -> Result<VerifiedFrame, ReferenceError> {
        let player = self.player.as_ref().ok_or_else(|| {
            ReferenceError::Invalid("this verifier checks captured frames: it has no player".into())
        })?;
        let played = player.render(frame)?.rgba8;
        let srgb8 = match &self.srgb8 {
            Some(p) => Some(p.render(frame)?),
            None => None,
        };
        self.judge(frame, played, srgb8)
    }

    /// References frame `frame` and compares `rgba8`, the frame as drawn elsewhere (size ×
    /// 4 bytes, sRGB; alpha ignored), with it. Errors when the image has the wrong length.
    pub fn verify_captured(
        &self,
        frame: u32,
        rgba8: Vec<u8>,
    ) -> Result<VerifiedFrame, ReferenceError> {
        let (w, h) = self.check.size;
        if rgba8.len() != w as usize * h as usize * 4 {
            return Err(ReferenceError::Invalid(format!(
                "frame {frame}: the captured image holds {} bytes, not {w}x{h} RGBA8",
                rgba8.len()
            )));
        }
        self.judge(frame, rgba8, None)
    }

    /// Renders the reference of `frame` and judges `test` (and the sRGB target's frame)
    /// against it.
    fn judge(
        &self,
        frame: u32,
        test: Vec<u8>,
        srgb8: Option<Vec<u8>>,
    ) -> Result<VerifiedFrame, ReferenceError> {
        let (w, h) = self.check.size;
        let reference = self.reference.render(frame, self.unordered.as_ref())?;
        let comparison = compare(&test, &reference.rgba8, w, h, &reference.unordered);
        // Holes: samples whose nearest fragment is of a triangle the file does not draw in
        // this frame. A differing pixel with one is a hole pixel, any other differing ordered
        // pixel an order error (depth: any difference; blend, saturate: over 1/255).
        let mut drawn = vec![false; self.scene_triangles];
        for t in self.drawn.of_frame(frame as usize) {
            if let Some(d) = drawn.get_mut(t as usize) {
                *d = true;
            }
        }
        let samples = (reference.front.len() / (w as usize * h as usize).max(1)).max(1);
        let mut hole_pixel = vec![false; w as usize * h as usize];
        let mut hole_samples = 0u64;
        for (i, &id) in reference.front.iter().enumerate() {
            if id != 0 && !drawn.get(id as usize - 1).copied().unwrap_or(false) {
                hole_samples += 1;
                if let Some(p) = hole_pixel.get_mut(i / samples) {
                    *p = true;
                }
            }
        }
        let tolerance = if self.check.mode == Mode::Depth { 0 } else { 1 };
        let (hole_pixels, order_error_pixels) = holes_and_order_errors(
            &test,
            &reference.rgba8,
            &reference.unordered,
            &hole_pixel,
            tolerance,
        );
        let srgb8 = srgb8.map(|img| compare(&img, &reference.rgba8, w, h, &reference.unordered));
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
            unordered_samples_recorded: self
                .unordered
                .as_ref()
                .map_or(0, |u| u.recorded_weight(frame)),
            unordered_pixels: reference.unordered.iter().filter(|&&u| u).count() as u64,
            comparison,
            hole_samples,
            hole_pixels,
            order_error_pixels,
            layers: reference.layers,
            truncated: reference.truncated,
            srgb8,
        };
        Ok(VerifiedFrame {
            report,
            player: test,
            reference,
        })
    }
}
