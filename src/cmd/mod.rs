//! The subcommands (DESIGN.md § CLI contract).

mod bake;
mod bench;
mod demo;
mod export_order;
mod inspect;
pub mod merge;
mod play;
pub mod record;
pub mod verify;
mod window;

use std::process::ExitCode;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};

use trisort_format::RecordSettings;

use crate::common::{default_size, parse_range, parse_size, FrameRange};

/// trisort: bake fixed camera paths into one depth-sorted index buffer with a sliding window
/// per frame, and play, verify and measure the result.
#[derive(Parser, Debug)]
#[command(name = "trisort", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Summarise a scene (.glb/.gltf), a recording or a baked file.
    Inspect(inspect::InspectArgs),
    /// Record a path over a scene: per-frame visible sets and occlusion graphs (GPU).
    Record(record::RecordArgs),
    /// Merge recordings into a baked file (sorted index buffer + sliding windows).
    Merge(merge::MergeArgs),
    /// Record and merge in one go.
    Bake(bake::BakeArgs),
    /// Play a baked file headless to PNG frames (or in a window).
    Play(play::PlayArgs),
    /// Check a baked file: graph rules against its recording, images against the exact reference.
    Verify(verify::VerifyArgs),
    /// Measure frame times and accuracy of the merged player against its rivals.
    Bench(bench::BenchArgs),
    /// Bake and play the built-in procedural car and print its figures.
    Demo(demo::DemoArgs),
    /// Write the order-only export of a baked file: each sorted triangle's glTF source.
    ExportOrder(export_order::ExportOrderArgs),
}

/// Recording options shared by `record` and `bake`.
#[derive(Args, Debug, Clone)]
pub struct RecordOpts {
    /// Recording size, WIDTHxHEIGHT.
    #[arg(long, default_value = default_size(), value_parser = parse_size)]
    pub size: (u32, u32),
    /// MSAA samples (1 or 4).
    #[arg(long, default_value_t = RecordSettings::DEFAULT_SAMPLES)]
    pub samples: u32,
    /// Accumulated opacity at which a sample counts as saturated.
    #[arg(long, default_value_t = RecordSettings::DEFAULT_SATURATION)]
    pub saturation: f32,
    /// Opacity at which transmissive glass is recorded.
    #[arg(long, default_value_t = RecordSettings::DEFAULT_GLASS_OPACITY)]
    pub glass_opacity: f32,
    /// Safety bound on peel layers per frame (a frame hitting it is marked truncated).
    #[arg(long, default_value_t = RecordSettings::DEFAULT_MAX_LAYERS)]
    pub max_layers: u32,
    /// Frames to record, half-open `a..b` (default: all).
    #[arg(long, value_parser = parse_range)]
    pub frames: Option<FrameRange>,
    /// Sampling rate for `--path gltf` and generated paths.
    #[arg(long, default_value_t = 30.0)]
    pub fps: f64,
    /// Record the scene as it is: do not split triangles that pass through each other
    /// (within a group of nodes that never move relative to each other) along their
    /// intersection first. Such pairs make depth-order cycles, which the bake can only break
    /// by leaving some samples unordered.
    #[arg(long)]
    pub keep_intersections: bool,
    /// Robust recording: union visibility and edges over N sample patterns, the recorded one
    /// and N − 1 moved by up to --robust-tolerance pixels, so another rasterizer's snapping
    /// or a modest resize opens fewer holes (costs N times the peel).
    #[arg(long, value_name = "N", default_value_t = RecordSettings::default().robust.patterns)]
    pub robust: u32,
    /// Robust recording: also keep every triangle that may be the nearest surface somewhere in
    /// a sample's box of ±--robust-tolerance pixels: its footprint grown by the box reaches the
    /// sample and it is not behind a bound on the nearest opaque surface over the whole box
    /// (one capture of the grown triangles per frame in phase 1, whose opaque triangles bound
    /// the box where they close over it; three passes on devices that cannot capture), with
    /// the edges of the grown triangles' layers (phase 2).
    /// The default; `--conservative=false` records the recorded pattern only (fewer
    /// triangles a frame, exact only where played as recorded).
    #[arg(
        long,
        value_name = "BOOL",
        num_args = 0..=1,
        require_equals = true,
        default_value_t = RecordSettings::default().robust.conservative,
        default_missing_value = "true",
        action = clap::ArgAction::Set
    )]
    pub conservative: bool,
    /// Tolerance in pixels of --robust's jittered patterns and of --conservative.
    #[arg(long, value_name = "PX", default_value_t = RecordSettings::default().robust.tolerance)]
    pub robust_tolerance: f32,
}

impl RecordOpts {
    /// Options recording the whole path with `settings`, sampling generated paths at `fps`.
    pub fn new(settings: RecordSettings, fps: f64) -> RecordOpts {
        RecordOpts {
            size: (settings.width, settings.height),
            samples: settings.samples,
            saturation: settings.saturation,
            glass_opacity: settings.glass_opacity,
            max_layers: settings.max_layers,
            frames: None,
            fps,
            keep_intersections: !settings.split_intersections,
            robust: settings.robust.patterns,
            conservative: settings.robust.conservative,
            robust_tolerance: settings.robust.tolerance,
        }
    }

    /// The settings stored in the recording.
    pub fn settings(&self) -> RecordSettings {
        RecordSettings {
            width: self.size.0,
            height: self.size.1,
            samples: self.samples,
            saturation: self.saturation,
            glass_opacity: self.glass_opacity,
            max_layers: self.max_layers,
            split_intersections: !self.keep_intersections,
            robust: trisort_format::Robust {
                patterns: self.robust,
                tolerance: self.robust_tolerance,
                conservative: self.conservative,
            },
        }
    }
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Inspect(a) => inspect::run(a),
        Command::Record(a) => record::run(a),
        Command::Merge(a) => merge::run(a),
        Command::Bake(a) => bake::run(a),
        Command::Play(a) => play::run(a),
        Command::Verify(a) => verify::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Demo(a) => demo::run(a),
        Command::ExportOrder(a) => export_order::run(a),
    }
}
