//! `trisort record SCENE --path P -o REC`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use serde_json::json;
use trisort_format::{DeviceInfo, FileKind, Phase, Recording};
use trisort_gpu::Gpu;
use trisort_recorder::partial::{partial_path, PartialDir};
use trisort_recorder::{record, RecordJob};

use crate::cmd::RecordOpts;
use crate::common::{load_working, print_json, progress_bar, FrameRange};

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
    /// or `demo`.
    #[arg(long)]
    path: String,
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

/// The raster profile in one line, for summaries: `conformant (±0.001953125 px, corners
/// snapped to 8 sub-pixel bits, depth at the sample)`.
pub fn profile_summary(s: &trisort_format::RecordSettings) -> String {
    let r = &s.robust;
    if !r.conservative {
        return format!("{} (the recorded pattern only)", r.profile.name);
    }
    format!(
        "{} (±{} px, corners snapped to {} sub-pixel bits, depth {})",
        r.profile.name,
        r.tolerance,
        r.profile.bits_text(),
        r.profile.depth_text()
    )
}

/// `--json`'s `raster_profile` (record, merge, bake, inspect): what the bake assumes about
/// the rasterizer that plays it (DESIGN's CLI contract, third wave): the profile's `name`, its
/// `tolerance` in pixels, the sub-pixel grids (`subpixel_bits`: `[least, most]`), where depth
/// is taken (`depth_at`), the recorded sample pattern (`size`, `samples`, `sample_locations`:
/// `standard`), whether the recording was `conservative`, and its jittered `patterns`.
pub fn raster_profile_json(s: &trisort_format::RecordSettings) -> serde_json::Value {
    let r = &s.robust;
    json!({
        "name": r.profile.name,
        "tolerance": r.tolerance,
        "subpixel_bits": [r.profile.subpixel_bits_min, r.profile.subpixel_bits_max],
        "depth_at": r.profile.depth_at,
        "size": [s.width, s.height],
        "samples": s.samples,
        "sample_locations": "standard",
        "conservative": r.conservative,
        "patterns": r.patterns,
    })
}

/// The `--json` figures of a recording (DESIGN's CLI contract).
pub fn recording_json(rec: &Recording, seconds: Option<f64>) -> serde_json::Value {
    let g = rec.unique_visible.len();
    let per_frame: Vec<_> = rec
        .frames
        .iter()
        .map(|f| {
            let covered = if rec.phase == Phase::Graphs {
                Some(f.covered.len())
            } else {
                None
            };
            json!({
                "frame": f.frame,
                "visible": f.visible.len(),
                "covered": covered,
                "ignored": covered.map(|c| g - c),
                "edges": f.edges.len(),
                "ties": f.ties.len(),
                "layers": f.layers[0] + f.layers[1],
                "layers_visibility": f.layers[0],
                "layers_graphs": f.layers[1],
                "truncated": f.truncated,
            })
        })
        .collect();
    json!({
        "frames": rec.frames.len(),
        "path_frames": rec.frame_states.len(),
        "phase": format!("{:?}", rec.phase).to_lowercase(),
        "scene_triangles": rec.scene_triangles,
        "unique_visible": g,
        "device": rec.device.adapter,
        "robust": {
            "patterns": rec.settings.robust.patterns,
            "tolerance": rec.settings.robust.tolerance,
            "conservative": rec.settings.robust.conservative,
        },
        "raster_profile": raster_profile_json(&rec.settings),
        "per_frame": per_frame,
        "seconds": seconds,
    })
}

/// Adds `record --json`'s `intersections_split` (pairs of triangles split along their
/// intersection before recording), `intersections_split_across_groups` (those of them of parts
/// that move apart) and `triangles_added` (0 and 0 with `--keep-intersections`).
pub fn add_split_json(v: &mut serde_json::Value, split: Option<&trisort_intersect::SplitReport>) {
    v["intersections_split"] = split
        .map_or(0, |r| r.pairs_split + r.pairs_split_across_groups)
        .into();
    v["intersections_split_across_groups"] =
        split.map_or(0, |r| r.pairs_split_across_groups).into();
    v["triangles_added"] = split.map_or(0, |r| r.triangles_added).into();
    v["intersections_left"] = split.map_or(0, |r| r.pairs_skipped_sliver).into();
}

/// Records with a progress display, resuming from `OUT.partial/`, and writes `output`
/// atomically. Used by `record`, `bake` and `demo`.
pub fn record_to_file(
    gpu: &Gpu,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    opts: &RecordOpts,
    phase: Phase,
    known_visible: Option<Vec<u32>>,
    output: &std::path::Path,
) -> Result<Recording> {
    let n = timeline.frames.len() as u32;
    let range = opts.frames.map(|r| r.resolve(n)).transpose()?;
    let job = RecordJob {
        geometry: &scene.geometry,
        frames: &timeline.frames,
        scene_hash: scene.hash(),
        path_hash: timeline.hash(),
        settings: opts.settings()?,
        range,
        phase,
        known_visible,
        internals: Default::default(),
    };
    let partial_dir = partial_path(output);
    let (partial, resumed) = PartialDir::open(&partial_dir, &job)?;
    if resumed > 0 {
        eprintln!(
            "trisort: resuming: {resumed} finished frame results in {}",
            partial_dir.display()
        );
    }
    let bar = progress_bar(0, "record");
    let mut rec = record(gpu, &job, Some(&partial), |p| {
        if bar.length() != Some(p.total as u64) || bar.prefix() != format!("phase {}", p.phase) {
            bar.set_prefix(format!("phase {}", p.phase));
            bar.set_length(p.total as u64);
        }
        bar.set_position(p.done as u64);
        bar.set_message(format!("frame {} ({} layers)", p.frame, p.layers));
    })
    .with_context(|| format!("recording {}", output.display()))?;
    bar.finish_and_clear();
    // The path's rate travels with the recording into the baked file (players default to it).
    rec.fps = Some(timeline.fps);
    trisort_format::write_file_atomic(FileKind::Recording, output, &rec)?;
    partial.remove()?;
    Ok(rec)
}

pub fn run(mut a: RecordArgs) -> Result<ExitCode> {
    let t0 = Instant::now();
    let (scene, timeline, split) =
        load_working(&a.scene, &a.path, a.opts.fps, &a.opts.settings()?)?;
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
            let known = union_of_visibility(&a.visibility, &scene, &timeline, &a.opts.settings()?)?;
            let (g, devices) = known.unzip();
            visibility_devices = devices.unwrap_or_default();
            (Phase::Graphs, g)
        }
        PhaseArg::Union => return write_union(&a, &scene, &timeline, t0),
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
    let rec = record_to_file(&gpu, &scene, &timeline, &a.opts, phase, known, &a.output)?;
    let secs = t0.elapsed().as_secs_f64();
    if a.json {
        let mut v = recording_json(&rec, Some(secs));
        add_split_json(&mut v, split.as_ref());
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

/// A recording file and the device it was recorded on.
type FileDevice = (PathBuf, DeviceInfo);

/// G from phase-1 recordings that together cover every frame of the path, recorded with
/// `settings`; with the device each file was recorded on (phase 2 must run on the same).
fn union_of_visibility(
    files: &[PathBuf],
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    settings: &trisort_format::RecordSettings,
) -> Result<Option<(Vec<u32>, Vec<FileDevice>)>> {
    if files.is_empty() {
        return Ok(None);
    }
    let n = timeline.frames.len();
    let mut seen = vec![false; n];
    let mut g = Vec::new();
    let mut devices = Vec::new();
    for f in files {
        let rec: Recording = crate::cmd::merge::read_recording(f)?;
        if rec.scene_hash != scene.hash()
            || rec.path_hash != timeline.hash()
            || rec.frame_states.len() != n
        {
            bail!("{}: recorded from another scene or path", f.display());
        }
        let differ = trisort_merger::settings_differences(&rec.settings, settings);
        if !differ.is_empty() {
            bail!(
                "{}: recorded with other settings than this command line's: {}",
                f.display(),
                trisort_merger::list_differences(&differ)
            );
        }
        devices.push((f.clone(), rec.device.clone()));
        for fr in &rec.frames {
            seen[fr.frame as usize] = true;
            g.extend_from_slice(&fr.visible);
        }
    }
    if let Some(missing) = seen.iter().position(|s| !s) {
        bail!("the --visibility recordings do not cover frame {missing} of the path's {n}; G needs every frame");
    }
    g.sort_unstable();
    g.dedup();
    Ok(Some((g, devices)))
}

/// `--shard`: a shard index and count, or `auto` (from the batch scheduler's environment).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShardArg {
    /// Shard `.0` of `.1`.
    Fixed(u32, u32),
    /// From `SLURM_ARRAY_TASK_*` or `JOB_COMPLETION_INDEX` + `TRISORT_SHARDS`.
    Auto,
}

/// Parses `I/N` (0 ≤ I < N) or `auto`.
pub fn parse_shard(s: &str) -> Result<ShardArg, String> {
    if s == "auto" {
        return Ok(ShardArg::Auto);
    }
    let bad = || format!("bad shard {s:?}: expected I/N with 0 <= I < N, or auto");
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (u32, u32) = (i.parse().map_err(|_| bad())?, n.parse().map_err(|_| bad())?);
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok(ShardArg::Fixed(i, n))
}

impl ShardArg {
    /// The shard index and count; `Auto` reads them with `var` (the environment), naming the
    /// variables when they are missing or malformed.
    pub fn resolve(self, var: &dyn Fn(&str) -> Option<String>) -> Result<(u32, u32)> {
        if let ShardArg::Fixed(i, n) = self {
            return Ok((i, n));
        }
        let num = |k: &str| -> Result<Option<u32>> {
            var(k)
                .map(|v| {
                    v.trim()
                        .parse::<u32>()
                        .with_context(|| format!("--shard auto: {k}={v:?} is not a number"))
                })
                .transpose()
        };
        let (i, n, from) = if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
            let min = num("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let n = num("SLURM_ARRAY_TASK_COUNT")?.context(
                "--shard auto: SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not",
            )?;
            let i = id.checked_sub(min).with_context(|| {
                format!(
                    "--shard auto: SLURM_ARRAY_TASK_ID {id} is below SLURM_ARRAY_TASK_MIN {min}"
                )
            })?;
            (i, n, "SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT")
        } else if let Some(i) = num("JOB_COMPLETION_INDEX")? {
            let n = num("TRISORT_SHARDS")?.context(
                "--shard auto: JOB_COMPLETION_INDEX is set but TRISORT_SHARDS (the Job's \
                 completions) is not",
            )?;
            (i, n, "JOB_COMPLETION_INDEX/TRISORT_SHARDS")
        } else {
            bail!(
                "--shard auto: neither SLURM_ARRAY_TASK_ID (a Slurm job array) nor \
                 JOB_COMPLETION_INDEX (a Kubernetes Indexed Job) is set; give --shard I/N"
            );
        };
        if i >= n {
            bail!("--shard auto: shard {i} of {n} ({from}) is out of range");
        }
        Ok((i, n))
    }
}

/// Shard `i` of `n` of a path of `frames` frames: frames `i·frames/n .. (i+1)·frames/n`, so
/// the `n` ranges cover the path in order and their lengths differ by at most one. An error
/// when a shard would be empty (more shards than frames).
pub fn shard_range(i: u32, n: u32, frames: u32) -> Result<std::ops::Range<u32>> {
    if n > frames {
        bail!("{n} shards of a {frames}-frame path: some would be empty; use at most {frames}");
    }
    let at = |k: u32| (k as u64 * frames as u64 / n as u64) as u32;
    Ok(at(i)..at(i + 1))
}

/// `--phase union`: joins the `--visibility` phase-1 recordings into one phase-1 recording of
/// the whole path (G once, for every shard's phase 2) and writes it atomically.
fn write_union(
    a: &RecordArgs,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    t0: Instant,
) -> Result<ExitCode> {
    if a.visibility.is_empty() {
        bail!("--phase union needs the phase-1 recordings: --visibility REC...");
    }
    if a.shard.is_some() || a.opts.frames.is_some() {
        bail!("--phase union joins whole-path results; it takes no --shard or --frames");
    }
    let recs = crate::cmd::merge::read_recordings(&a.visibility)?;
    for (r, f) in recs.iter().zip(&a.visibility) {
        if r.phase != Phase::Visibility {
            bail!(
                "{}: not a phase-1 recording (record it with --phase visibility)",
                f.display()
            );
        }
    }
    crate::cmd::merge::check_compatible(&recs, &a.visibility, false)?;
    let rec = trisort_merger::join(&recs).map_err(|e| {
        anyhow::anyhow!(
            "{}",
            crate::cmd::merge::name_files(&e.to_string(), &a.visibility)
        )
    })?;
    if rec.scene_hash != scene.hash() || rec.path_hash != timeline.hash() {
        bail!(
            "{}: recorded from another scene or path than {} --path {}",
            a.visibility[0].display(),
            a.scene,
            a.path
        );
    }
    let differ = trisort_merger::settings_differences(&rec.settings, &a.opts.settings()?);
    if !differ.is_empty() {
        bail!(
            "{}: recorded with other settings than this command line's: {}",
            a.visibility[0].display(),
            trisort_merger::list_differences(&differ)
        );
    }
    trisort_format::write_file_atomic(FileKind::Recording, &a.output, &rec)?;
    let secs = t0.elapsed().as_secs_f64();
    if a.json {
        print_json(&recording_json(&rec, Some(secs)));
    } else {
        println!(
            "joined {} phase-1 recordings of {} frames: |G| = {} of {} triangles; wrote {}",
            recs.len(),
            rec.frames.len(),
            rec.unique_visible.len(),
            rec.scene_triangles,
            a.output.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
