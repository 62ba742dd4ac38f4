//! trisort-capi's tests: one binary, a module per subject.

mod api;
mod baked;
mod cpp_wrapper;
mod gpu_data;
mod header;
mod light_variants;
