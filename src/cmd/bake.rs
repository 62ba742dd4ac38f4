//! `trisort bake SCENE --path P -o BAKED`: record and merge in one go.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use trisort_format::{Baked, Phase, Recording};
use trisort_gpu::Gpu;

use crate::cmd::merge::{baked_json, merge_to_file, print_summary, MergeOpts};
use crate::cmd::record::{add_split_json, record_to_file, recording_json};
use crate::cmd::RecordOpts;
use crate::common::{load_working, print_json};

/// Arguments of `bake`.
#[derive(Args, Debug)]
pub struct BakeArgs {
    /// Scene (.glb/.gltf, or `demo[:TRIANGLES]`).
    scene: String,
    /// Path: TOML file, `gltf` (or `gltf:animation=NAME,camera=NAME`), `orbit:…`, `dolly:…`
    /// or `demo`.
    #[arg(long)]
    path: String,
    /// Output baked file. The recording is kept beside it as `BAKED.rec` (verify uses it).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    record: RecordOpts,
    #[command(flatten)]
    merge: MergeOpts,
    /// Print the figures as JSON.
    #[arg(long)]
    json: bool,
}

/// Where `bake` keeps the recording of `output`.
pub fn recording_path(output: &Path) -> PathBuf {
    let mut name = output.file_name().unwrap_or_default().to_os_string();
    name.push(".rec");
    output.with_file_name(name)
}

/// The recording at `path` if it is this bake's, finished: it reads back whole (checksum and
/// structure), and its tool version, scene and path hashes, settings, frames, rate and
/// recording device are those this bake would record with. Recording is deterministic, so
/// such a file is byte for byte what recording again would write. Anything else (no file,
/// a damaged one, another job's) is `None`: it is recorded again and replaced.
fn finished_recording(
    gpu: &Gpu,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    record: &RecordOpts,
    path: &Path,
) -> Result<Option<Recording>> {
    if !path.exists() {
        return Ok(None);
    }
    let Ok(rec) = trisort_format::read_file::<Recording>(trisort_format::FileKind::Recording, path)
    else {
        return Ok(None);
    };
    let n = timeline.frames.len() as u32;
    let range = record
        .frames
        .map(|r| r.resolve(n))
        .transpose()?
        .unwrap_or(0..n);
    let frames: Vec<u32> = rec.frames.iter().map(|f| f.frame).collect();
    let same = rec.tool_version == trisort_format::TOOL_VERSION
        && rec.phase == Phase::Graphs
        && rec.scene_hash == scene.hash()
        && rec.path_hash == timeline.hash()
        && rec.settings == record.settings()?
        && rec.fps == Some(timeline.fps)
        && rec.device == gpu.device_info()
        && frames.iter().copied().eq(range);
    Ok(same.then_some(rec))
}

/// Records and merges, storing `environment` (`MergeOpts::environment`, loaded by the caller
/// before anything else so a bad light costs no work and leaves no output); returns the
/// recording, the baked file, the seconds of each step and whether the recording was this
/// bake's finished one, found beside the output ([`finished_recording`]: a bake killed while
/// merging merges only when run again).
pub fn bake(
    gpu: &Gpu,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    record: &RecordOpts,
    merge: &MergeOpts,
    environment: trisort_format::Environment,
    output: &Path,
) -> Result<(Recording, Baked, f64, f64, bool)> {
    let t0 = Instant::now();
    let rec_path = recording_path(output);
    let finished = finished_recording(gpu, scene, timeline, record, &rec_path)?;
    let reused = finished.is_some();
    let rec = match finished {
        Some(rec) => {
            eprintln!(
                "trisort: resuming: {} is this bake's finished recording (same version, scene, \
                 path, settings and device): merging only",
                rec_path.display()
            );
            rec
        }
        None => record_to_file(gpu, scene, timeline, record, Phase::Graphs, None, &rec_path)?,
    };
    let record_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let baked = merge_to_file(
        std::slice::from_ref(&rec),
        &merge.options(),
        environment,
        output,
        &[rec_path.display().to_string()],
    )?;
    Ok((rec, baked, record_s, t1.elapsed().as_secs_f64(), reused))
}

pub fn run(a: BakeArgs) -> Result<ExitCode> {
    // First: a bad light fails before the scene is loaded and split.
    let environment = a.merge.environment()?;
    let (scene, timeline, split) =
        load_working(&a.scene, &a.path, a.record.fps, &a.record.settings()?)?;
    let gpu = crate::common::open_gpu()?;
    let (rec, baked, record_s, merge_s, reused) = bake(
        &gpu,
        &scene,
        &timeline,
        &a.record,
        &a.merge,
        environment,
        &a.output,
    )?;
    if a.json {
        let mut v = recording_json(&rec, Some(record_s));
        let m = baked_json(&baked, merge_s);
        for (k, val) in m.as_object().expect("object") {
            v[k] = val.clone();
        }
        add_split_json(&mut v, split.as_ref());
        v["record_seconds"] = record_s.into();
        v["recording_reused"] = reused.into();
        v["merge_seconds"] = merge_s.into();
        v["seconds"] = (record_s + merge_s).into();
        print_json(&v);
    } else {
        println!(
            "{} {} frames on {} in {:.1} s: |G| = {} of {} triangles",
            if reused {
                "reused the recording of"
            } else {
                "recorded"
            },
            rec.frames.len(),
            rec.device.adapter,
            record_s,
            rec.unique_visible.len(),
            rec.scene_triangles
        );
        print_summary(&baked, merge_s);
        println!(
            "wrote {} (recording: {})",
            a.output.display(),
            recording_path(&a.output).display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
