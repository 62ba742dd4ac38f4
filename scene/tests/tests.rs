//! trisort-scene's integration tests: one test binary (one link instead of one per file), one
//! module per subject. Run one subject with `cargo test -p trisort-scene --test tests --
//! <module>::`.

mod gltf_builder;

mod demo_car;
mod import;
mod import_bad_input;
mod import_built;
mod import_compressed;
mod import_pbr;
mod import_variants;
