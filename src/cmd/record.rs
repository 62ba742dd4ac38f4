//! `trisort record SCENE --path P -o REC`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use trisort_bake::figures::{add_split_json, recording_json};
use trisort_bake::inputs::{join_visibility, union_of_visibility};
use trisort_bake::shard::{parse_shard, shard_range, ShardArg};
use trisort_bake::{record_to_file, RecordTarget};
use trisort_format::{FileKind, Phase};

use crate::cmd::RecordOpts;
use crate::common::{load_working, print_json, Console, FrameRange};

/// Which phases to run.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum PhaseArg {
    /// Both phases (phase 1 over the whole path, phase 2 over the range).
    All,
    /// Phase 1 only: visible sets.
    Visibility,
    /// Phase 2 over the range, with G from `--visibility` recordings (or phase 1 over the path).
    Graphs,
    /// No GPU work: join the phase-1 recordings of `--visibility` (frame ranges covering the
    /// path, e.g. one per shard) into one phase-1 recording of the whole path, whose G the
    /// shards' `--phase graphs --visibility OUT` read.
    Union,
}

/// Arguments of `record`.
#[derive(Args, Debug)]
pub struct RecordArgs {
    /// Scene (.glb/.gltf, or `demo[:TRIANGLES]`).
    scene: String,
    /// Path: TOML file, `gltf` (or `gltf:animation=NAME,camera=NAME`), `orbit:…`, `dolly:…`
    /// or `demo`. Repeat it as `--path NAME=SPEC` for a bundle: the paths' frames one after
    /// the other, each a named clip (`--frames`/`--shard` then cut the bundle's frames).
    #[arg(long, required = true)]
    path: Vec<String>,
    /// Output recording.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    opts: RecordOpts,
    /// Phases to run.
    #[arg(long, value_enum, default_value = "all")]
    phase: PhaseArg,
    /// Phase-1 recordings of the whole path whose union gives G (for `--phase graphs` and
    /// `--phase union`).
    #[arg(long, num_args = 1..)]
    visibility: Vec<PathBuf>,
    /// Record shard I of N (0 ≤ I < N): the I-th of N balanced frame ranges of the path
    /// (lengths differ by at most one frame). `auto` takes I and N from a batch scheduler:
    /// Slurm's `SLURM_ARRAY_TASK_ID` (less `SLURM_ARRAY_TASK_MIN`) and
    /// `SLURM_ARRAY_TASK_COUNT`, or Kubernetes' `JOB_COMPLETION_INDEX` with N from
    /// `TRISORT_SHARDS`. `{shard}` in `-o` is replaced by I.
    #[arg(long, value_parser = parse_shard, conflicts_with = "frames")]
    shard: Option<ShardArg>,
    /// Print the figures as JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(mut a: RecordArgs) -> Result<ExitCode> {
    let t0 = Instant::now();
    let settings = a.opts.settings()?;
    let working = load_working(&trisort_bake::Settings {
        fps: a.opts.fps,
        record: settings,
        paths: a.path.clone(),
        ..trisort_bake::Settings::new(&a.scene, "")
    })?;
    let timeline = &working.timeline;
    if let Some(shard) = a.shard {
        let (i, n) = shard.resolve(&|k| std::env::var(k).ok())?;
        let range = shard_range(i, n, timeline.frames.len() as u32)?;
        a.opts.frames = Some(FrameRange::from(range));
        a.output = PathBuf::from(
            a.output
                .to_string_lossy()
                .replace("{shard}", &i.to_string()),
        );
    }
    let mut visibility_devices = Vec::new();
    let (phase, known) = match a.phase {
        PhaseArg::Visibility => {
            if !a.visibility.is_empty() {
                bail!("--visibility goes with --phase graphs");
            }
            (Phase::Visibility, None)
        }
        PhaseArg::All => {
            if !a.visibility.is_empty() {
                bail!("--visibility goes with --phase graphs");
            }
            (Phase::Graphs, None)
        }
        PhaseArg::Graphs => {
            if a.visibility.is_empty() {
                (Phase::Graphs, None)
            } else {
                let (g, devices) = union_of_visibility(&a.visibility, &working, &settings)?;
                visibility_devices = devices;
                (Phase::Graphs, Some(g))
            }
        }
        PhaseArg::Union => return write_union(&a, &working, &settings, t0),
    };
    let gpu = crate::common::open_gpu()?;
    // G from another device's phase 1 is not this device's: its visible sets could fall
    // outside it.
    for (f, device) in &visibility_devices {
        let differ = trisort_merger::device_differences(device, &gpu.device_info());
        if !differ.is_empty() {
            bail!(
                "{}: phase 1 was recorded on another device than this one ({}); record phase 1 \
                 on the kind of device that records phase 2",
                f.display(),
                trisort_merger::list_differences(&differ)
            );
        }
    }
    let target = RecordTarget {
        settings: &settings,
        frames: a
            .opts
            .frames
            .map(|r| r.resolve(timeline.frames.len() as u32))
            .transpose()?,
        phase,
        known_visible: known,
    };
    let rec = record_to_file(&gpu, &working, target, &a.output, &mut Console::new())?;
    let secs = t0.elapsed().as_secs_f64();
    if a.json {
        let mut v = recording_json(&rec, Some(secs));
        add_split_json(&mut v, working.split.as_ref());
        print_json(&v);
    } else {
        println!(
            "recorded frames {:?} of {} ({:?}) on {}: |G| = {} of {} triangles, {:.1} s; wrote {}",
            rec.frame_range(),
            rec.frame_states.len(),
            rec.phase,
            rec.device.adapter,
            rec.unique_visible.len(),
            rec.scene_triangles,
            secs,
            a.output.display()
        );
        let truncated = rec.frames.iter().filter(|f| f.truncated).count();
        if truncated > 0 {
            eprintln!("trisort: warning: {truncated} frames hit --max-layers and are truncated; verify will fail on them");
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// `--phase union`: joins the `--visibility` phase-1 recordings into one phase-1 recording of
/// the whole path (G once, for every shard's phase 2) and writes it atomically.
fn write_union(
    a: &RecordArgs,
    working: &trisort_bake::Working,
    settings: &trisort_format::RecordSettings,
    t0: Instant,
) -> Result<ExitCode> {
    if a.visibility.is_empty() {
        bail!("--phase union needs the phase-1 recordings: --visibility REC...");
    }
    if a.shard.is_some() || a.opts.frames.is_some() {
        bail!("--phase union joins whole-path results; it takes no --shard or --frames");
    }
    let paths = a.path.join(" ");
    let (rec, joined) = join_visibility(&a.visibility, working, settings, (&a.scene, &paths))?;
    trisort_format::write_file_atomic(FileKind::Recording, &a.output, &rec)?;
    let secs = t0.elapsed().as_secs_f64();
    if a.json {
        print_json(&recording_json(&rec, Some(secs)));
    } else {
        println!(
            "joined {} phase-1 recordings of {} frames: |G| = {} of {} triangles; wrote {}",
            joined,
            rec.frames.len(),
            rec.unique_visible.len(),
            rec.scene_triangles,
            a.output.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
