//! The reference crate's integration tests, one binary: the OIT renderer (`oit`) and the
//! depth peeling renderer (`peeling`) against the exact reference.

mod oit;
mod peeling;
