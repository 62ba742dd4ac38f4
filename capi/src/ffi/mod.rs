//! The `extern "C"` functions of `include/trisort.h`.
//!
//! Conventions (also in the header):
//! - Every function returns a [`TrisortStatus`] (except [`trisort_abi_version`],
//!   [`trisort_last_error`] and the `close` functions). On failure, [`trisort_last_error`]
//!   copies a message naming the file and the problem (per thread, until the next call).
//! - No panic crosses the boundary: each entry point runs under `catch_unwind` and reports one
//!   as [`TrisortStatus::Panic`].
//! - Handles are opened and closed by the library (`trisort_open_*` / `trisort_close`). The
//!   host never frees library memory: arrays are copied into host buffers. Each copy function
//!   takes `out`, its capacity `cap` in elements and `len`: it stores the element count in
//!   `*len` (when `len` is not null); with `out` null it only reports it, with `cap` too small
//!   it returns [`TrisortStatus::BufferTooSmall`] and copies nothing.
//! - Strings (names) are copied the same way as UTF-8 bytes plus a terminating NUL: `*len`
//!   is the length in bytes without the NUL, and `cap` must be at least `*len + 1`.
//! - Matrices are 16 floats, column major.

mod baked;
mod boundary;
mod environment;
mod materials;
mod order;
mod playback;
mod types;

pub use baked::*;
pub use boundary::{trisort_abi_version, trisort_last_error};
pub use environment::*;
pub use materials::*;
pub use order::*;
pub use playback::*;
pub use types::*;
