//! The paths crate's integration tests, one binary with a module per kind of path, sharing the
//! scenes and helpers of `common`.

mod common;

mod demo;
mod errors;
mod generators;
mod gltf_paths;
mod real_scenes;
mod toml_paths;
