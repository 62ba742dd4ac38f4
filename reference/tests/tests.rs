//! The reference crate's integration tests, one binary: the OIT renderer (`oit`), the depth
//! peeling renderer (`peeling`), the 8-bit sRGB player (`deploy`) and the occlusion-query sort
//! (`vis_sort`) against the exact reference.

mod deploy;
mod oit;
mod peeling;
mod vis_sort;
