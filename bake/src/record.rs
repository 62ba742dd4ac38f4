//! Recording to a file, resumable: finished frames are kept in `OUT.partial/` until the
//! recording is written.

use std::ops::Range;
use std::path::Path;

use trisort_format::{FileKind, Phase, RecordSettings, Recording};
use trisort_gpu::Gpu;
use trisort_paths::Timeline;
use trisort_recorder::partial::{partial_path, PartialDir};
use trisort_recorder::{record, RecordJob};
use trisort_scene::Scene;

use crate::{BakeError, Events, Working};

/// What to record: the phase, the frames, the settings and G when phase 1 ran elsewhere.
pub struct RecordTarget<'a> {
    /// Recording settings.
    pub settings: &'a RecordSettings,
    /// Frames to record (`None`: the whole path).
    pub frames: Option<Range<u32>>,
    /// Phase 1 only, or both phases.
    pub phase: Phase,
    /// G from phase-1 recordings of the whole path made elsewhere (shards), if any.
    pub known_visible: Option<Vec<u32>>,
}

impl RecordTarget<'_> {
    /// The recorder's job for `scene` along `timeline`.
    fn job<'w>(&self, scene: &'w Scene, timeline: &'w Timeline) -> RecordJob<'w> {
        RecordJob {
            geometry: &scene.geometry,
            frames: &timeline.frames,
            scene_hash: scene.hash(),
            path_hash: timeline.hash(),
            settings: *self.settings,
            range: self.frames.clone(),
            phase: self.phase,
            known_visible: self.known_visible.clone(),
            internals: Default::default(),
        }
    }
}

/// Records `scene` along `timeline` as `target` says, in memory (no partial directory,
/// nothing written); the path's rate travels with the recording. `scene` is recorded as it
/// is: give [`Working::scene`] for the scene with its crossing triangles split.
pub fn record_in_memory(
    gpu: &Gpu,
    scene: &Scene,
    timeline: &Timeline,
    target: RecordTarget<'_>,
    events: &mut dyn Events,
) -> Result<Recording, trisort_recorder::RecordError> {
    let job = target.job(scene, timeline);
    let recorded = record(gpu, &job, None, |p| events.progress(&p));
    events.recorded();
    let mut rec = recorded?;
    rec.fps = Some(timeline.fps);
    rec.clips[0].fps = rec.fps;
    Ok(rec)
}

/// Records `working` as `target` says, resuming from `OUT.partial/` (a note says how many
/// frames it found), and writes `output` atomically; the path's rate travels with the
/// recording into the baked file (players default to it).
pub fn record_to_file(
    gpu: &Gpu,
    working: &Working,
    target: RecordTarget<'_>,
    output: &Path,
    events: &mut dyn Events,
) -> Result<Recording, BakeError> {
    let job = target.job(&working.scene, &working.timeline);
    let partial_dir = partial_path(output);
    let (partial, resumed) = PartialDir::open(&partial_dir, &job)?;
    if resumed > 0 {
        events.note(&format!(
            "resuming: {resumed} finished frame results in {}",
            partial_dir.display()
        ));
    }
    let recorded = record(gpu, &job, Some(&partial), |p| events.progress(&p));
    events.recorded();
    let mut rec = recorded.map_err(|source| BakeError::Record {
        output: output.to_path_buf(),
        source,
    })?;
    rec.fps = Some(working.timeline.fps);
    rec.clips = working.clips.clone();
    trisort_format::write_file_atomic(FileKind::Recording, output, &rec)?;
    partial.remove()?;
    Ok(rec)
}
