//! trisort's integration tests: one test binary (as in ripgrep's `tests/tests.rs`), one module
//! per subject, all sharing the [`support`] harness. Most run the real `trisort` binary on real
//! scenes; `verify_images` drives the libraries directly. Run one subject with
//! `cargo test --test tests -- <module>::`.

mod support;

mod bad_input;
mod bake_play_cli;
mod bench_cli;
mod bundle_cli;
mod c_host;
mod cli_basics;
mod clips_cli;
mod compressed_gltf;
mod environment_cli;
mod export_order;
mod extremes;
mod extremes_no_lost_work;
mod format_reader;
mod format_upgrade;
mod gpu_budget;
mod long_paths;
mod merge_car;
mod presort_cli;
mod record_cli;
mod self_check_cli;
mod shard_cli;
mod texture_upload_cli;
mod variants_cli;
mod verify_cli;
mod verify_forged;
mod verify_images;
mod verify_report;
mod webgl2_cli;
mod window_cli;
