//! Recording to a file, resumable: finished frames are kept in `OUT.partial/` until the
//! recording is written.

use std::ops::Range;
use std::path::Path;

use trisort_format::{FileKind, Phase, RecordSettings, Recording};
use trisort_gpu::Gpu;
use trisort_recorder::partial::{partial_path, PartialDir};
use trisort_recorder::{record, RecordJob};

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
    let job = RecordJob {
        geometry: &working.scene.geometry,
        frames: &working.timeline.frames,
        scene_hash: working.scene.hash(),
        path_hash: working.timeline.hash(),
        settings: *target.settings,
        range: target.frames,
        phase: target.phase,
        known_visible: target.known_visible,
        internals: Default::default(),
    };
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
    trisort_format::write_file_atomic(FileKind::Recording, output, &rec)?;
    partial.remove()?;
    Ok(rec)
}
