//! Phase 1 of a frame: the triangles reached before each sample saturates, from captured
//! lists or peeled layers, with the conservative set added for `--conservative`.

use std::sync::atomic::{AtomicBool, Ordering::Relaxed};

use trisort_format::RecordSettings;
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Gpu;

use crate::conservative::Conservative;
use crate::envelope;
use crate::layers::Layers;
use crate::partial::Visibility;
use crate::{capture, RecordError, RecordJob};

/// Phase 1's conservative set: the envelope bound where the device can capture
/// ([`envelope`]), else the three conservative passes ([`Conservative`]).
pub(crate) enum PhaseOneConservative<'g> {
    Envelope(Box<envelope::Envelope<'g>>),
    Passes(Box<Conservative<'g>>),
}

impl<'g> PhaseOneConservative<'g> {
    /// The conservative set `job`'s settings ask for at `view` (`None` without
    /// `--conservative`).
    pub(crate) fn of(
        gpu: &'g Gpu,
        job: &RecordJob,
        view: View,
    ) -> Result<Option<Self>, RecordError> {
        let s = &job.settings;
        if !s.robust.conservative {
            return Ok(None);
        }
        let (g, f, t) = (job.geometry, job.frames, &s.robust);
        // The envelope needs a capture, but not the layers' way: recordings peeled
        // (`Internals::peel`) take the same conservative set as captured ones.
        let (passes, i) = (job.internals.conservative_passes, &job.internals);
        // Scenes of 2^24 triangles or more take the passes too.
        let envelope = capture::supported(gpu) && !passes && envelope::Envelope::fits(g);
        Ok(Some(if envelope {
            PhaseOneConservative::Envelope(Box::new(envelope::Envelope::new(
                gpu, g, f, view, t, i,
            )?))
        } else {
            PhaseOneConservative::Passes(Box::new(Conservative::new(gpu, g, f, view, t, i)?))
        }))
    }

    fn visible(&self, frame: u32) -> Result<Vec<u32>, RecordError> {
        match self {
            PhaseOneConservative::Envelope(e) => e.visible(frame),
            PhaseOneConservative::Passes(c) => c.visible(frame),
        }
    }
}

/// Phase 1 of one frame: the visible set, layers used, and whether `max_layers` truncated it.
/// With robust settings, the union over the sample patterns of
/// [`Robust::offsets`](trisort_format::Robust::offsets) (layers add up) and the conservative
/// pass's triangles.
pub(crate) fn visibility_frame(
    source: &Layers,
    conservative: Option<&PhaseOneConservative>,
    frame: u32,
    s: &RecordSettings,
    interleaved: bool,
) -> Result<Visibility, RecordError> {
    let mut visible = vec![];
    // Per drawn triangle (phase 1 draws every scene triangle, in id order): reached before
    // saturation. One flag a triangle instead of one entry a sample and layer to sort.
    let reached: Vec<AtomicBool> = (0..source.triangles())
        .map(|_| AtomicBool::new(false))
        .collect();
    let residual = 1.0 - s.saturation;
    let (mut layers, mut truncated) = (0, false);
    let offsets = s.robust.offsets();
    for &offset in &offsets {
        if offsets.len() > 1 {
            source.set_frame_subpixel_offset(frame, offset);
        }
        let (l, t) = match source {
            Layers::Capture(c) => {
                // Each sample's fragments in peel order, walked as the peel's layers would be:
                // until the sample saturates or `max_layers` fragments were taken. Runs of
                // samples in parallel, each with the most fragments it took and whether any
                // were left; the reached flags are shared (a union).
                let (mut most, mut left) = (0u32, false);
                c.borrow_mut().frame(frame, |band| {
                    let runs = band.walk(
                        || (0u32, false),
                        |(most, left), _, list| {
                            let (mut transmittance, mut taken) = (1.0f32, 0u32);
                            for f in list {
                                if taken == s.max_layers {
                                    *left = true;
                                    break;
                                }
                                reached[(f.id - 1) as usize].store(true, Relaxed);
                                taken += 1;
                                transmittance *= 1.0 - f.alpha;
                                if transmittance <= residual {
                                    break;
                                }
                            }
                            *most = (*most).max(taken);
                        },
                    );
                    for (m, l) in runs {
                        most = most.max(m);
                        left |= l;
                    }
                    Ok(())
                })?;
                (most, left)
            }
            Layers::Peel(peeler) => {
                let slots = peeler.slots();
                let mut transmittance = vec![1.0f32; slots];
                peeler.peel(frame, s.max_layers, |_, layer, done| {
                    for i in 0..slots {
                        let id = layer.ids[i];
                        if id == 0 || done[i] != 0 {
                            continue;
                        }
                        // Reached before saturation: visible (its own opacity does not matter).
                        if interleaved {
                            visible.push(id - 1);
                        } else {
                            reached[(id - 1) as usize].store(true, Relaxed);
                        }
                        transmittance[i] *= 1.0 - layer.alpha[i];
                        if transmittance[i] <= residual {
                            done[i] = 1;
                        }
                    }
                    Ok(true)
                })?
            }
        };
        layers += l;
        truncated |= t;
    }
    if offsets.len() > 1 {
        source.set_frame_subpixel_offset(frame, [0.0, 0.0]);
    }
    visible.extend(
        reached
            .iter()
            .enumerate()
            .filter(|(_, r)| r.load(Relaxed))
            .map(|(t, _)| t as u32),
    );
    if let Some(c) = conservative {
        visible.extend(c.visible(frame)?);
    }
    visible.sort_unstable();
    visible.dedup();
    Ok((visible, layers, truncated))
}
