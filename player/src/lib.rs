//! The player: draws each baked frame, already depth-sorted, with one multi-draw-indirect call.
//!
//! A [`Baked`](trisort_format::Baked) file holds one sorted index buffer (front to back) and,
//! per frame, a window of indirect draws over it. [`Player::new`] uploads everything once;
//! [`Player::draw`] binds the frame's uniforms by dynamic offset and issues exactly one
//! `multi_draw_indexed_indirect` into the caller's render pass (none for an empty window; on
//! adapters without `DownlevelFlags::INDIRECT_EXECUTION`, the same ranges one `draw_indexed`
//! at a time).
//!
//! Modes ([`Mode`]) and their blend equations (`s` the fragment, `d` the target):
//! - `blend`: back to front (the reversed index buffer and draw lists), no depth test, *over*
//!   with straight alpha: `rgb = s.a·s.rgb + (1 − s.a)·d.rgb`, `a = s.a + (1 − s.a)·d.a`.
//! - `depth`: front to back, depth test `Less` with depth writes, the same *over* blend (opaque
//!   fragments have `s.a = 1` and replace).
//! - `saturate`: front to back, no depth test, *under* with premultiplied colour on a target
//!   cleared to alpha 0: `rgb = (1 − d.a)·(s.a·s.rgb) + d.rgb`, `a = (1 − d.a)·s.a + d.a`
//!   (blend factors `OneMinusDstAlpha`, `One`). This is the exact front-to-back equivalent of
//!   `blend`; the paper's `SrcAlphaSaturated` factor (`min(s.a, 1 − d.a)`) equals it only when
//!   every fragment is opaque or fully transparent. The background goes under the result at
//!   the end: `rgb + (1 − a)·background`.
//!
//! [`headless`] renders frames to 8-bit pixels for the CLI and the tests; [`draw_calls`] is
//! the small trait the player draws through (implemented by `wgpu::RenderPass` and by a
//! recorder of calls).
#![deny(missing_docs)]

pub mod budget;
pub mod commands;
pub mod config;
pub mod draw_calls;
mod error;
#[cfg(not(target_arch = "wasm32"))]
pub mod headless;
pub mod on_screen;
mod player;
pub mod self_check;

pub use budget::GpuBudget;
pub use config::{playback_warnings, DrawPath, PlayerConfig};
pub use draw_calls::{Call, CallLog, DrawCalls};
pub use error::PlayerError;
#[cfg(not(target_arch = "wasm32"))]
pub use headless::{render_frames, HeadlessConfig, HeadlessRenderer, RenderedFrame};
pub use on_screen::{OnScreen, OnScreenSettings};
pub use player::{
    baked_from_bytes, blend_state, clip_index, fragment_entry_point, open_baked, Player,
};
#[cfg(not(target_arch = "wasm32"))]
pub use self_check::{SelfCheck, SelfCheckFrame};
pub use trisort_format::{Mode, ParseOptionError};
/// The background every frame is drawn over (re-exported from the GPU crate for hosts).
pub use trisort_gpu::BACKGROUND;
pub use trisort_gpu::{Shading, ToneMap};

/// Instance flags with wgpu's indirect-call validation (`VALIDATION_INDIRECT_CALL`) switched
/// on or off, the other flags as wgpu chooses them (build type and `WGPU_*` environment).
///
/// wgpu validates every indirect draw on the GPU by default, even in release builds: a compute
/// pass checks each `DrawIndexedIndirectArgs` against the bound buffers before the draw. The
/// player checks every draw of a baked file against its index buffer on the CPU when it loads
/// it ([`Player::new`]), so hosts that trust that check may turn the GPU pass off. The flag is
/// read when the *instance* creates a device, so it must be chosen before the device exists:
/// `trisort_gpu::Gpu::with_flags(instance_flags(false))`, or set
/// `wgpu::InstanceDescriptor::flags` in a host's own setup.
pub fn instance_flags(validate_indirect: bool) -> wgpu::InstanceFlags {
    let mut flags = wgpu::InstanceFlags::from_build_config().with_env();
    flags.set(
        wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL,
        validate_indirect,
    );
    flags
}
