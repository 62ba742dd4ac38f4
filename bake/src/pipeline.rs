//! The whole bake: record (or reuse this bake's finished recording), merge, light, write.

use std::path::{Path, PathBuf};
use std::time::Instant;

use trisort_format::{Baked, Environment, FileKind, Phase, Recording};
use trisort_gpu::Gpu;
use trisort_merger::MergeOptions;

use crate::textures::{TextureFormat, TextureReport};
use crate::{record_to_file, BakeError, Events, RecordTarget, Settings, Working};

/// Where a bake keeps the recording of `output`: `OUTPUT.rec` beside it (verify reads it).
pub fn recording_path(output: &Path) -> PathBuf {
    let mut name = output.file_name().unwrap_or_default().to_os_string();
    name.push(".rec");
    output.with_file_name(name)
}

/// The recording at `path` if it is this bake's, finished: it reads back whole (checksum and
/// structure), and its tool version, scene and path hashes, settings, frames, rate and
/// recording device are those `settings` would record `working` with on `gpu`. Recording
/// is deterministic, so such a file is byte for byte what recording again would write.
/// Anything else (no file, a damaged one, another job's) is `None`: it is recorded again
/// and replaced.
pub fn finished_recording(
    gpu: &Gpu,
    working: &Working,
    settings: &Settings,
    path: &Path,
) -> Option<Recording> {
    if !path.exists() {
        return None;
    }
    let rec: Recording = trisort_format::read_file(FileKind::Recording, path).ok()?;
    let n = working.timeline.frames.len() as u32;
    let same = rec.tool_version == trisort_format::TOOL_VERSION
        && rec.phase == Phase::Graphs
        && rec.scene_hash == working.scene.hash()
        && rec.path_hash == working.timeline.hash()
        && rec.settings == settings.record
        && rec.fps == Some(working.timeline.fps)
        && rec.device == gpu.device_info()
        && rec.clips == working.clips
        && rec.frames.iter().map(|f| f.frame).eq(0..n);
    same.then_some(rec)
}

/// Merges `recordings` (read from `files`, which errors name), lights the result with
/// `environment`, stores its textures as `textures` asks ([`crate::textures::compress`]) and
/// writes it to `output` atomically.
pub fn merge_to_file(
    recordings: &[Recording],
    files: &[String],
    opts: &MergeOptions,
    environment: Environment,
    textures: TextureFormat,
    output: &Path,
) -> Result<(Baked, TextureReport), BakeError> {
    let merged = trisort_merger::merge(recordings, opts).map_err(|error| BakeError::Merge {
        error,
        files: files.to_vec(),
    })?;
    let mut baked = merged.lit(environment);
    let report = crate::textures::compress(&mut baked.geometry, textures);
    trisort_format::write_file_atomic(FileKind::Baked, output, &baked)?;
    Ok((baked, report))
}

/// A finished bake: the recording, the baked file and what each step took.
pub struct Baking {
    /// The recording (kept beside the output, [`recording_path`]).
    pub recording: Recording,
    /// The baked file, as written.
    pub baked: Baked,
    /// Seconds recording took (reading the finished recording back, when reused).
    pub record_seconds: f64,
    /// Seconds merging and writing took (compressing the textures included).
    pub merge_seconds: f64,
    /// What became of the textures (`--textures`).
    pub textures: TextureReport,
    /// Whether the recording was this bake's finished one, found beside the output
    /// ([`finished_recording`]): a bake killed while merging merges only when run again.
    pub recording_reused: bool,
}

/// Records `working` with `settings` and merges it into `output`, storing `environment`
/// (loaded by the caller from [`Settings::light`] before anything else, so a bad light costs
/// no work and leaves no output).
pub fn bake(
    gpu: &Gpu,
    working: &Working,
    settings: &Settings,
    environment: Environment,
    output: &Path,
    events: &mut dyn Events,
) -> Result<Baking, BakeError> {
    let t0 = Instant::now();
    let rec_path = recording_path(output);
    let finished = finished_recording(gpu, working, settings, &rec_path);
    let recording_reused = finished.is_some();
    let recording = match finished {
        Some(rec) => {
            events.note(&format!(
                "resuming: {} is this bake's finished recording (same version, scene, path, \
                 settings and device): merging only",
                rec_path.display()
            ));
            rec
        }
        None => {
            let target = RecordTarget {
                settings: &settings.record,
                // The whole timeline: a range of the path (`settings.frames`) is already all
                // of it, a clip of its own (`Working::load`).
                frames: None,
                phase: Phase::Graphs,
                known_visible: None,
            };
            record_to_file(gpu, working, target, &rec_path, events)?
        }
    };
    let record_seconds = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let files = [rec_path.display().to_string()];
    let recordings = std::slice::from_ref(&recording);
    let (baked, textures) = merge_to_file(
        recordings,
        &files,
        &settings.merge,
        environment,
        settings.textures,
        output,
    )?;
    Ok(Baking {
        recording,
        baked,
        record_seconds,
        merge_seconds: t1.elapsed().as_secs_f64(),
        textures,
        recording_reused,
    })
}
