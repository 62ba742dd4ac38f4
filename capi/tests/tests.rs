//! trisort-capi's tests: one binary, a module per subject.

mod api;
mod baked;
mod header;
mod light_variants;
