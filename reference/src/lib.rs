//! trisort's exact reference renderer, the default pipeline it is compared with, and image
//! verification of baked files.
//!
//! - [`ExactReference`]: the full scene peeled per sample with the recorder's peeler, its
//!   layers composited through the player's shader, blend state and target (`blend`,
//!   `saturate`), or a z-buffer of every triangle through the player itself (`depth`).
//! - [`DefaultRenderer`]: every triangle with the depth test, opaque first, transparent
//!   unsorted after: what engines do today.
//! - [`Srgb8Player`]: the player on an 8-bit sRGB target (the deployment error).
//! - [`compare()`]: pixel, PSNR and FLIP figures, difference and mask images.
//! - [`ImageVerifier`]: `trisort verify --scene`: a baked file's frames against the reference,
//!   with the pass/fail rule of the recorded pattern.
//!
//! It is a crate of its own because it is the one place that needs both the recorder (the
//! peeler) and the player (its pipeline state and headless renderer): the player ships without
//! the recorder, the recorder does not depend on the player, and the graph validator
//! (`trisort-verify`) reads only the file formats. The CLI (`verify`, `demo`, later `bench`)
//! uses it.
#![deny(missing_docs)]

pub mod compare;
pub mod default_pipeline;
pub mod deploy;
pub mod exact;
pub mod frames;
pub mod html;
pub mod oit;
pub mod peeling;
pub mod presorted;
pub mod report;
mod target;
pub mod verify;
pub mod vis_sort;

pub use compare::{compare, Comparison};
pub use default_pipeline::DefaultRenderer;
pub use deploy::Srgb8Player;
pub use exact::{ExactReference, ReferenceConfig, ReferenceFrame, UnorderedEdges};
pub use oit::{OitConfig, OitFrame, OitRenderer};
pub use peeling::{PeeledFrame, PeelingConfig, PeelingRenderer};
pub use presorted::PresortedRenderer;
pub use verify::{FrameImageReport, ImageCheck, ImageVerifier, VerifiedFrame};
pub use vis_sort::VisSortRenderer;

/// Errors of the reference renderers.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    /// Peeling failed (device limits, lost device).
    #[error("peeling the full scene: {0}")]
    Peel(#[from] trisort_recorder::RecordError),
    /// The player failed (structure, device).
    #[error("player: {0}")]
    Player(#[from] trisort_player::PlayerError),
    /// A GPU target or readback failed.
    #[error(transparent)]
    Gpu(#[from] trisort_gpu::GpuError),
    /// The device lacks something the reference needs.
    #[error("unsupported device: {0}")]
    Unsupported(String),
    /// wgpu reported a validation error.
    #[error("wgpu: {0}")]
    Wgpu(String),
    /// The inputs do not fit together.
    #[error("{0}")]
    Invalid(String),
}
