//! The reference crate's integration tests, one binary: the OIT renderer (`oit`), the depth
//! peeling renderer (`peeling`) and the 8-bit sRGB player (`deploy`) against the exact
//! reference.

mod deploy;
mod oit;
mod peeling;
