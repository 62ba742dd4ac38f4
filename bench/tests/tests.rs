//! The bench crate's integration tests, one binary: the run-time rivals on a real scene
//! (`rivals`), the scaling benchmark (`scaling`) and the speed/accuracy sweep (`sweep`).

mod rivals;
mod scaling;
mod sweep;
