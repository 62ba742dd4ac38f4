//! The GPU crate's integration tests, one binary: every shader validated by naga (`naga`, no
//! GPU), a triangle rendered and read back (`gpu_smoke`), the data-texture tier's size check
//! (`tiers`).

mod gpu_smoke;
mod naga;
mod tiers;
