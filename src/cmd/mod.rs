//! The subcommands (README § Using it lists their options and `--json` keys).

mod bake;
mod bench;
mod demo;
mod export_order;
mod export_shaders;
mod inspect;
pub mod merge;
mod play;
mod presort;
pub mod record;
mod upgrade;
pub mod verify;
mod window;

use std::process::ExitCode;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};

use trisort_bake::spec::ProfileChoice;
use trisort_format::{DepthAt, ProfileName, RecordSettings};

use crate::common::{default_size, option_parser, parse_bits, parse_range, parse_size, FrameRange};

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
    /// Depth-presort a scene for free viewpoints (paper 000): per viewpoint partition, a list of
    /// triangle copies with half-space tests, sorted for every camera outside a bounding
    /// polyhedron.
    Presort(presort::PresortArgs),
    /// Measure frame times and accuracy of the merged player against its rivals.
    Bench(bench::BenchArgs),
    /// Bake and play the built-in procedural car and print its figures.
    Demo(demo::DemoArgs),
    /// Write the order-only export of a baked file: each sorted triangle's glTF source.
    ExportOrder(export_order::ExportOrderArgs),
    /// Write the player's vertex and fragment shaders for hosts (GLSL ES 3.00, SPIR-V or
    /// WGSL) with their binding layout.
    ExportShaders(export_shaders::ExportShadersArgs),
    /// Rewrite a baked file of an earlier format version in the current one (frames, draws
    /// and figures unchanged).
    Upgrade(upgrade::UpgradeArgs),
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
    /// Frames, half-open `a..b` (default: all). `bake` bakes the range as a clip of those
    /// frames alone (one path; `play` numbers them from 0, `inspect` shows where they start
    /// on the path); `record` records the range as a part of a sharded bake.
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
    /// What the bake assumes about the rasterizer that plays it (BENCHMARKS § Raster
    /// profiles): `conformant` (the default) for GPUs with the standard sample locations, 8
    /// sub-pixel bits and depth at the sample; `exact` for the recorded pattern only
    /// (`--conservative=false`); `snap4` for GPUs snapping to as few as 4 bits; `browser` for
    /// SwiftShader (the web build). Every profile but `exact` records conservatively: it keeps
    /// every triangle that may be the nearest surface somewhere in a sample's box of
    /// ±tolerance pixels, for corners snapped to the profile's grids and depth where the
    /// profile takes it, with the edges of the grown triangles' layers (phase 2).
    #[arg(long, value_name = "NAME", value_parser = option_parser::<ProfileName>())]
    pub raster_profile: Option<ProfileName>,
    /// Conservative recording on or off. `--conservative=false` is `--raster-profile exact`;
    /// `--conservative` (true) the default profile. Contradicting --raster-profile is an
    /// error.
    #[arg(
        long,
        value_name = "BOOL",
        num_args = 0..=1,
        require_equals = true,
        default_missing_value = "true",
        action = clap::ArgAction::Set
    )]
    pub conservative: Option<bool>,
    /// Tolerance in pixels of --robust's jittered patterns and of the conservative recording
    /// (default: the raster profile's: 1/512 conformant and snap4, 3/32 browser, 1/8 exact).
    /// The conservative recording adds half a step of the profile's coarsest sub-pixel grid
    /// (1/512 px at 8 bits, 1/32 px at 4).
    #[arg(long, value_name = "PX")]
    pub robust_tolerance: Option<f32>,
    /// The raster profile's sub-pixel grids, `N` or `LEAST..MOST` bits (4..=16; default: the
    /// profile's: 8 conformant, 4..8 snap4 and browser).
    #[arg(long, value_name = "BITS", value_parser = parse_bits)]
    pub subpixel_bits: Option<(u32, u32)>,
    /// Where the raster profile's rasterizer takes a sample's depth (default: the profile's:
    /// `pixel` for browser, `sample` otherwise).
    #[arg(long, value_name = "WHERE", value_parser = option_parser::<DepthAt>())]
    pub depth_at: Option<DepthAt>,
}

impl RecordOpts {
    /// The settings stored in the recording: the named raster profile (by default the
    /// conformant one, `exact` under `--conservative=false`) with the knobs given on top.
    pub fn settings(&self) -> Result<RecordSettings> {
        let robust = ProfileChoice {
            name: self.raster_profile,
            conservative: self.conservative,
            patterns: self.robust,
            tolerance: self.robust_tolerance,
            subpixel_bits: self.subpixel_bits,
            depth_at: self.depth_at,
        }
        .robust()?;
        Ok(RecordSettings {
            width: self.size.0,
            height: self.size.1,
            samples: self.samples,
            saturation: self.saturation,
            glass_opacity: self.glass_opacity,
            max_layers: self.max_layers,
            split_intersections: !self.keep_intersections,
            robust,
        })
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
        Command::Presort(a) => presort::run(a),
        Command::Demo(a) => demo::run(a),
        Command::ExportOrder(a) => export_order::run(a),
        Command::ExportShaders(a) => export_shaders::run(a),
        Command::Upgrade(a) => upgrade::run(a),
    }
}
