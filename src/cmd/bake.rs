//! `trisort bake SCENE --path P -o BAKED`: record and merge in one go.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::Args;
use trisort_bake::figures::{
    add_split_json, baked_json, clips_json, merge_summary, recording_json,
};
use trisort_bake::{recording_path, Settings};

use crate::cmd::merge::MergeOpts;
use crate::cmd::RecordOpts;
use crate::common::{load_working, print_json, Console};

/// Arguments of `bake`.
#[derive(Args, Debug)]
pub struct BakeArgs {
    /// Scene (.glb/.gltf, or `demo[:TRIANGLES]`).
    scene: String,
    /// Path: TOML file, `gltf` (or `gltf:animation=NAME,camera=NAME`), `orbit:…`, `dolly:…`
    /// or `demo`. Repeat it as `--path NAME=SPEC` for a bundle: every path recorded and
    /// merged into one sorted index buffer, each a clip of its own (`play --clip NAME`).
    /// With `--frames A..B` (one path) the bake is a clip of those frames alone.
    #[arg(long, required = true)]
    path: Vec<String>,
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

/// The pipeline's settings for `scene` and `paths` from the command line's options; the
/// frame range is resolved against the path once it is loaded.
fn settings(
    scene: &str,
    paths: &[String],
    record: &RecordOpts,
    merge: &MergeOpts,
) -> Result<Settings> {
    Ok(Settings {
        scene: scene.to_string(),
        paths: paths.to_vec(),
        fps: record.fps,
        record: record.settings()?,
        frames: record.frames,
        merge: merge.options(),
        light: merge.light(),
        textures: merge.textures,
    })
}

pub fn run(a: BakeArgs) -> Result<ExitCode> {
    let settings = settings(&a.scene, &a.path, &a.record, &a.merge)?;
    // First: a bad light fails before the scene is loaded and split.
    let environment = settings.light.load()?;
    let working = load_working(&settings)?;
    let gpu = crate::common::open_gpu()?;
    let done = trisort_bake::bake(
        &gpu,
        &working,
        &settings,
        environment,
        &a.output,
        &mut Console::new(),
    )?;
    let (rec, baked) = (&done.recording, &done.baked);
    let (record_s, merge_s) = (done.record_seconds, done.merge_seconds);
    if a.json {
        let mut v = recording_json(rec, Some(record_s));
        let m = baked_json(baked, merge_s);
        for (k, val) in m.as_object().expect("object") {
            v[k] = val.clone();
        }
        add_split_json(&mut v, working.split.as_ref());
        v["record_seconds"] = record_s.into();
        v["recording_reused"] = done.recording_reused.into();
        v["merge_seconds"] = merge_s.into();
        v["clips"] = clips_json(baked);
        v["textures"] = done.textures.to_json();
        v["seconds"] = (record_s + merge_s).into();
        print_json(&v);
    } else {
        let verb = if done.recording_reused {
            "reused the recording of"
        } else {
            "recorded"
        };
        println!(
            "{verb} {} frames on {} in {record_s:.1} s: |G| = {} of {} triangles",
            rec.frames.len(),
            rec.device.adapter,
            rec.unique_visible.len(),
            rec.scene_triangles
        );
        println!("{}", merge_summary(baked, merge_s));
        if done.textures.format != trisort_bake::textures::TextureFormat::Rgba8 {
            println!("{}", done.textures.summary());
        }
        if baked.clips.len() > 1 || baked.clips[0].path_first > 0 {
            for c in &baked.clips {
                let rate = c.fps.map(|f| format!(" at {f} fps")).unwrap_or_default();
                println!(
                    "clip {}: frames {}..{} ({} frames{rate}; path frames {}..{})",
                    c.name,
                    c.first,
                    c.first + c.count,
                    c.count,
                    c.path_first,
                    c.path_first + c.count
                );
            }
        }
        println!(
            "wrote {} (recording: {})",
            a.output.display(),
            recording_path(&a.output).display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
