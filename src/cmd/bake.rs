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

/// Records and merges, storing `environment` (`MergeOpts::environment`, loaded by the caller
/// before anything else so a bad light costs no work and leaves no output); returns the
/// recording, the baked file and the seconds of each step.
pub fn bake(
    gpu: &Gpu,
    scene: &trisort_scene::Scene,
    timeline: &trisort_paths::Timeline,
    record: &RecordOpts,
    merge: &MergeOpts,
    environment: trisort_format::Environment,
    output: &Path,
) -> Result<(Recording, Baked, f64, f64)> {
    let t0 = Instant::now();
    let rec_path = recording_path(output);
    let rec = record_to_file(gpu, scene, timeline, record, Phase::Graphs, None, &rec_path)?;
    let record_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let baked = merge_to_file(
        std::slice::from_ref(&rec),
        &merge.options(),
        environment,
        output,
        &[rec_path.display().to_string()],
    )?;
    Ok((rec, baked, record_s, t1.elapsed().as_secs_f64()))
}

pub fn run(a: BakeArgs) -> Result<ExitCode> {
    // First: a bad light fails before the scene is loaded and split.
    let environment = a.merge.environment()?;
    let (scene, timeline, split) =
        load_working(&a.scene, &a.path, a.record.fps, &a.record.settings()?)?;
    let gpu = crate::common::open_gpu()?;
    let (rec, baked, record_s, merge_s) = bake(
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
        v["merge_seconds"] = merge_s.into();
        v["seconds"] = (record_s + merge_s).into();
        print_json(&v);
    } else {
        println!(
            "recorded {} frames on {} in {:.1} s: |G| = {} of {} triangles",
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
