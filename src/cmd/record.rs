//! `trisort record SCENE --path P -o REC`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use serde_json::json;
use trisort_format::{FileKind, Phase, Recording};
use trisort_gpu::Gpu;
use trisort_recorder::partial::{partial_path, PartialDir};
use trisort_recorder::{record, RecordJob};

use crate::cmd::RecordOpts;
use crate::common::{load_path, load_scene, print_json, progress_bar, working_scene};

/// Which phases to run.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum PhaseArg {
    /// Both phases (phase 1 over the whole path, phase 2 over the range).
    All,
    /// Phase 1 only: visible sets.
    Visibility,
    /// Phase 2 over the range, with G from `--visibility` recordings (or phase 1 over the path).
    Graphs,
}

/// Arguments of `record`.
#[derive(Args, Debug)]
pub struct RecordArgs {
    /// Scene (.glb/.gltf, or `demo[:TRIANGLES]`).
    scene: String,
    /// Path: TOML file, `gltf`, `orbit:…`, `dolly:…` or `demo`.
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
    /// Phase-1 recordings of the whole path whose union gives G (for `--phase graphs`).
    #[arg(long, num_args = 1..)]
    visibility: Vec<PathBuf>,
    /// Print the figures as JSON.
    #[arg(long)]
    json: bool,
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
        "per_frame": per_frame,
        "seconds": seconds,
    })
}

/// Adds `record --json`'s `intersections_split` (pairs of triangles split along their
/// intersection before recording) and `triangles_added` (0 and 0 with `--keep-intersections`).
pub fn add_split_json(v: &mut serde_json::Value, split: Option<&trisort_intersect::SplitReport>) {
    v["intersections_split"] = split.map_or(0, |r| r.pairs_split).into();
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
        settings: opts.settings(),
        range,
        phase,
        known_visible,
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
    let rec = record(gpu, &job, Some(&partial), |p| {
        if bar.length() != Some(p.total as u64) || bar.prefix() != format!("phase {}", p.phase) {
            bar.set_prefix(format!("phase {}", p.phase));
            bar.set_length(p.total as u64);
        }
        bar.set_position(p.done as u64);
        bar.set_message(format!("frame {} ({} layers)", p.frame, p.layers));
    })
    .with_context(|| format!("recording {}", output.display()))?;
    bar.finish_and_clear();
    trisort_format::write_file_atomic(FileKind::Recording, output, &rec)?;
    partial.remove()?;
    Ok(rec)
}

pub fn run(a: RecordArgs) -> Result<ExitCode> {
    let t0 = Instant::now();
    let mut scene = load_scene(&a.scene)?;
    let timeline = load_path(&a.path, &scene, a.opts.fps)?;
    let split = working_scene(&mut scene, &timeline.frames, &a.opts.settings());
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
        PhaseArg::Graphs => (
            Phase::Graphs,
            union_of_visibility(&a.visibility, &scene, &timeline)?,
        ),
    };
    let gpu = crate::common::open_gpu()?;
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

/// G from phase-1 recordings that together cover every frame of the path.
fn union_of_visibility(
    files: &[PathBuf],
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
) -> Result<Option<Vec<u32>>> {
    if files.is_empty() {
        return Ok(None);
    }
    let n = timeline.frames.len();
    let mut seen = vec![false; n];
    let mut g = Vec::new();
    for f in files {
        let rec: Recording = crate::cmd::merge::read_recording(f)?;
        if rec.scene_hash != scene.hash()
            || rec.path_hash != timeline.hash()
            || rec.frame_states.len() != n
        {
            bail!("{}: recorded from another scene or path", f.display());
        }
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
    Ok(Some(g))
}
