//! The GPU crate's integration tests, one binary: every shader validated by naga (`naga`, no
//! GPU) and a triangle rendered and read back (`gpu_smoke`).

mod gpu_smoke;
mod naga;
