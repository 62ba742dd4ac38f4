//! Where a phase's layers come from: one capture pass a frame where the device can capture
//! fragments, else one depth-peeling pass a layer; and what they are for.

use trisort_format::{FrameState, Geometry, Robust};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Gpu;

use crate::{capture, captures, Internals, Peeler, RecordError};

/// Where a phase's layers come from: one capture pass a frame, or one peel pass a layer.
pub(crate) enum Layers<'g> {
    Capture(std::cell::RefCell<capture::Capture<'g>>),
    Peel(Peeler<'g>),
}

/// What a phase's layers are for, which decides what is drawn and read back.
#[derive(Clone, Copy)]
pub(crate) enum Purpose {
    /// Phase 1: ids and opacity until saturation (a capture may stop at the first opaque
    /// fragment; a peeler reads back alpha, not depth).
    Visibility,
    /// Phase 2: ids and depth of every layer (a peeler reads back depth, not alpha).
    Graphs,
    /// Phase 2 of `record --conservative`: the triangles grown by this tolerance in pixels
    /// (the grown peel, `Peeler::build` with `grow`).
    Grown(Robust),
}

impl<'g> Layers<'g> {
    /// Capture where the device can (and `internals` do not say otherwise), else peel, as
    /// `purpose` needs.
    pub(crate) fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        triangles: &[u32],
        frames: &[FrameState],
        view: View,
        purpose: Purpose,
        internals: &Internals,
    ) -> Result<Self, RecordError> {
        let (g, t, f, i) = (geometry, triangles, frames, internals);
        if captures(gpu, internals) {
            let c = match purpose {
                Purpose::Visibility => capture::Capture::new(gpu, g, t, f, view, true, i)?,
                Purpose::Graphs => capture::Capture::new(gpu, g, t, f, view, false, i)?,
                Purpose::Grown(robust) => {
                    let grow = capture::Grow::Peel(&robust);
                    capture::Capture::grown(gpu, g, t, f, view, grow, i)?
                }
            };
            return Ok(Layers::Capture(std::cell::RefCell::new(c)));
        }
        Ok(Layers::Peel(match purpose {
            Purpose::Visibility => {
                Peeler::build(gpu, g, t, f, view, None, i)?.with_readback(true, false)
            }
            // Opacity too: the tie rule's order may reach a triangle before saturation.
            Purpose::Graphs => {
                Peeler::build(gpu, g, t, f, view, None, i)?.with_readback(true, true)
            }
            Purpose::Grown(robust) => {
                Peeler::build(gpu, g, t, f, view, Some(&robust), i)?.with_readback(false, true)
            }
        }))
    }

    pub(crate) fn set_frame_subpixel_offset(&self, frame: u32, offset: [f64; 2]) {
        match self {
            Layers::Capture(c) => c.borrow().set_frame_subpixel_offset(frame, offset),
            Layers::Peel(p) => p.set_frame_subpixel_offset(frame, offset),
        }
    }

    pub(crate) fn triangles(&self) -> usize {
        match self {
            Layers::Capture(c) => c.borrow().triangles(),
            Layers::Peel(p) => p.triangles(),
        }
    }
}
