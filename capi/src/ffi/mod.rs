//! The `extern "C"` functions of `include/trisort.h`.
//!
//! The conventions every function follows (status and last error, out parameters, the
//! out/cap/len copy convention, strings, enums as `uint32_t`, column-major matrices, units and
//! coordinates, handles, lifetimes, threads, panics, versions) are written once, in C terms, at
//! the top of `include/trisort.h`: `capi/cbindgen.toml`'s `header`.

mod baked;
pub mod boundary;
mod environment;
mod gpu_data;
mod materials;
mod order;
mod playback;
mod types;

pub use baked::*;
pub use boundary::{
    trisort_abi_version, trisort_format_version, trisort_last_error, trisort_version_string,
};
pub use environment::*;
pub use gpu_data::*;
pub use materials::*;
pub use order::*;
pub use playback::*;
pub use types::*;
