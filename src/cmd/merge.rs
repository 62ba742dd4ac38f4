//! `trisort merge REC... -o BAKED`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::Args;
use trisort_format::{Bridge, Choice, FileKind, Layout, Seeding, Strategy};
use trisort_merger::MergeOptions;

use trisort_bake::inputs::{check_compatible, read_recordings};
use trisort_bake::textures::TextureFormat;

use crate::common::{choice_parser, option_parser, print_json};

/// Merge options shared by `merge`, `bake` and `demo`; every default is
/// [`MergeOptions::default`]'s.
#[derive(Args, Debug, Clone)]
pub struct MergeOpts {
    /// Merge strategy.
    #[arg(long, value_parser = choice_parser::<Strategy>(),
          default_value_t = MergeOptions::default().strategy)]
    pub strategy: Choice<Strategy>,
    /// Matrix layout.
    #[arg(long, value_parser = choice_parser::<Layout>(),
          default_value_t = MergeOptions::default().layout)]
    pub layout: Choice<Layout>,
    /// What a copy may span besides frames where its triangle is visible.
    #[arg(long, value_parser = option_parser::<Bridge>(),
          default_value_t = MergeOptions::default().bridge)]
    pub bridge: Bridge,
    /// Keep only equal-depth (tie) edges: plays only with the depth test.
    #[arg(long)]
    pub depth_only: bool,
    /// Cut the path into segments of N frames with their own matrices, so no frame needs more
    /// than N draws whatever the path's length (0: one matrix for the whole path). The
    /// default, 64, changes nothing on paths of up to 64 frames (BENCHMARKS.md § Sweep).
    #[arg(long, default_value_t = MergeOptions::DEFAULT_SEGMENT)]
    pub segment: u32,
    /// How the matrix is seeded.
    #[arg(long, value_parser = option_parser::<Seeding>(),
          default_value_t = MergeOptions::default().seeding)]
    pub seeding: Seeding,
    /// The light stored in the baked file, which players shade with: `studio` (the built-in
    /// studio with a sun) or an equirectangular Radiance .hdr file (row 0 at the zenith,
    /// column 0 looking along +X, the middle column along −X), prefiltered at bake time (a
    /// file named `studio`: `./studio`).
    #[arg(long, value_name = "studio|FILE.hdr", default_value = STUDIO)]
    pub environment: String,
    /// How the baked file stores its textures: `rgba8` (uncompressed), `etc2` (OpenGL ES 3 and
    /// mobile Vulkan GPUs), `astc` (4×4; needs a trisort built with `--features astc`) or
    /// `bc7` (desktop GPUs). A player uploads the blocks where its device samples them and
    /// decodes them elsewhere; a texture whose alpha decides visibility is compressed only if
    /// its alpha stays exact, and one whose size is not a power of two stays RGBA8
    /// (`--json` `textures` says which and the colour error).
    #[arg(long, value_name = "rgba8|etc2|astc|bc7", default_value = "rgba8",
          value_parser = parse_textures)]
    pub textures: TextureFormat,
}

/// `--textures`' parser.
fn parse_textures(s: &str) -> Result<TextureFormat, String> {
    s.parse()
}

/// `--environment`'s name of the built-in studio.
const STUDIO: &str = "studio";

impl MergeOpts {
    /// The `--environment` light: the built-in studio, or an .hdr file.
    pub fn light(&self) -> trisort_bake::Light {
        trisort_bake::Light::parse(&self.environment)
    }

    /// The merger's options (`--segment 0`: no segments).
    pub fn options(&self) -> MergeOptions {
        MergeOptions {
            strategy: self.strategy,
            layout: self.layout,
            bridge: self.bridge,
            depth_only: self.depth_only,
            segment: (self.segment > 0).then_some(self.segment),
            seeding: self.seeding,
            allow_mixed_devices: false,
        }
    }
}

/// Arguments of `merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Recordings (frame ranges of one scene and path, in any order).
    #[arg(required = true)]
    recordings: Vec<PathBuf>,
    /// Output baked file.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    opts: MergeOpts,
    /// Merge recordings made on different devices (adapter, driver or backend), which are
    /// refused otherwise: the bake is then exact on none of them. Warns, and the baked file's
    /// device names every device with its frames (`mixed: …`).
    #[arg(long)]
    allow_mixed_devices: bool,
    /// Join the recordings (frame ranges of one path, e.g. one per shard) into the one
    /// recording a single machine would have written, write it to REC, and bake from it: the
    /// baked file and REC are then byte for byte those of a one-machine `bake` (whose
    /// recording is `BAKED.rec`).
    #[arg(long, value_name = "REC", conflicts_with = "allow_mixed_devices")]
    join: Option<PathBuf>,
    /// Print the figures as JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(a: MergeArgs) -> Result<ExitCode> {
    let mut recs = read_recordings(&a.recordings)?;
    for (r, f) in recs.iter().zip(&a.recordings) {
        if r.phase != trisort_format::Phase::Graphs {
            bail!(
                "{}: a recording with no graphs (phase 1 only); record phase 2 first \
                 (record --phase graphs)",
                f.display()
            );
        }
    }
    check_compatible(&recs, &a.recordings, a.allow_mixed_devices, &mut |w| {
        eprintln!("trisort: warning: {w}")
    })?;
    // Before anything is written: a bad light leaves no output.
    let environment = a.opts.light().load()?;
    let mut names: Vec<String> = a
        .recordings
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    let t0 = std::time::Instant::now();
    if let Some(join) = &a.join {
        let joined =
            trisort_merger::join(&recs).map_err(|error| trisort_bake::BakeError::Merge {
                error,
                files: names.clone(),
            })?;
        trisort_format::write_file_atomic(FileKind::Recording, join, &joined)
            .with_context(|| format!("writing {}", join.display()))?;
        recs = vec![joined];
        names = vec![join.display().to_string()];
    }
    let opts = MergeOptions {
        allow_mixed_devices: a.allow_mixed_devices,
        ..a.opts.options()
    };
    let (baked, textures) = trisort_bake::merge_to_file(
        &recs,
        &names,
        &opts,
        environment,
        a.opts.textures,
        &a.output,
    )?;
    let seconds = t0.elapsed().as_secs_f64();
    if a.json {
        let mut v = trisort_bake::figures::baked_json(&baked, seconds);
        v["clips"] = trisort_bake::figures::clips_json(&baked);
        v["textures"] = textures.to_json();
        print_json(&v);
    } else {
        println!("{}", trisort_bake::figures::merge_summary(&baked, seconds));
        if textures.format != TextureFormat::Rgba8 {
            println!("{}", textures.summary());
        }
        println!("wrote {}", a.output.display());
    }
    Ok(ExitCode::SUCCESS)
}
