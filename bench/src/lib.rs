//! trisort's benchmarks: what the speed/accuracy trade costs and buys.
//!
//! - [`methods`]: the renderers compared frame by frame (`default`, `source`, `merged`,
//!   `oit`, `peeling`, `presorted`, `occlusion-query`) behind one [`methods::Method`] trait.
//! - [`harness`]: interleaved, repeated timing (GPU timestamps and wall time) and the
//!   device-independent counts (triangles submitted, fragment-shader invocations, overdraw).
#![deny(missing_docs)]

pub mod harness;
pub mod matrix;
pub mod methods;
pub mod plot;
pub mod report;
mod rivals;
pub mod scaling;
pub mod sweep;
pub mod table;
pub mod vis_sort;

/// Errors of the benchmarks.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A reference renderer failed.
    #[error(transparent)]
    Reference(#[from] trisort_reference::ReferenceError),
    /// The player failed.
    #[error(transparent)]
    Player(#[from] trisort_player::PlayerError),
    /// A GPU target or readback failed.
    #[error(transparent)]
    Gpu(#[from] trisort_gpu::GpuError),
    /// Recording failed.
    #[error(transparent)]
    Record(#[from] trisort_recorder::RecordError),
    /// Merging failed.
    #[error(transparent)]
    Merge(#[from] trisort_merger::MergeError),
    /// wgpu reported an error.
    #[error("wgpu: {0}")]
    Wgpu(String),
    /// Writing an output failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// What failed.
        source: std::io::Error,
    },
    /// The inputs do not fit together.
    #[error("{0}")]
    Invalid(String),
    /// A step of the pipeline (loading, recording, merging, writing) failed.
    #[error(transparent)]
    Bake(#[from] trisort_bake::BakeError),
}
