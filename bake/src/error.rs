//! The pipeline's errors: each names the input it is about.

use std::path::PathBuf;

/// Why a step of the pipeline failed.
#[derive(Debug, thiserror::Error)]
pub enum BakeError {
    /// `demo:` followed by something that is not a triangle count.
    #[error("scene {spec}: expected demo:TRIANGLES")]
    DemoSpec {
        /// The scene as given.
        spec: String,
    },
    /// The scene file could not be loaded.
    #[error(transparent)]
    Scene(#[from] trisort_scene::SceneError),
    /// The path could not be loaded or sampled.
    #[error(transparent)]
    Path(#[from] trisort_paths::PathError),
    /// The light (an .hdr file) could not be loaded.
    #[error(transparent)]
    Light(#[from] trisort_scene::EnvironmentError),
    /// Frames (of a path, a recording or a baked file) pose nodes the scene does not have.
    #[error(
        "scene {spec} ({nodes} nodes) is not the scene {frames_from} was made over: {why}; \
         give the same scene file, or for demo the same demo:TRIANGLES"
    )]
    NotTheScene {
        /// The scene as given.
        spec: String,
        /// Its node count.
        nodes: usize,
        /// Where the frames come from (`path P`, a file).
        frames_from: String,
        /// The first frame's problem.
        why: String,
    },
    /// The frame range asked for is empty or past the path's end.
    #[error("frame range {start}..{end} is empty or outside the path's frames 0..{frames}")]
    FrameRange {
        /// First frame asked for.
        start: u32,
        /// One past the last frame asked for.
        end: u32,
        /// Frames of the path.
        frames: u32,
    },
    /// The paths of a bundle cannot be made clips as given (names missing, repeated or
    /// malformed; a frame range over several paths).
    #[error("{0}")]
    Clips(String),
    /// Recordings that cannot be used as given (malformed, of another scene, path, settings
    /// or device, not covering the path).
    #[error("{0}")]
    Input(String),
    /// Shards that do not fit the path or the scheduler's environment.
    #[error("{0}")]
    Shard(String),
    /// Recording failed.
    #[error("recording {}: {source}", .output.display())]
    Record {
        /// The recording being written.
        output: PathBuf,
        /// Why.
        #[source]
        source: trisort_recorder::RecordError,
    },
    /// The recordings could not be merged; `files` name the recordings the merger's error
    /// counts by index.
    #[error("{error} (recordings: {})", numbered(.files))]
    Merge {
        /// The merger's error (not a `source`: the message already says it).
        error: trisort_merger::MergeError,
        /// The recordings' files, in the order given to the merger.
        files: Vec<String>,
    },
    /// Reading or writing a file (a recording, a partial directory, the baked file).
    #[error(transparent)]
    File(#[from] trisort_format::FormatError),
}

/// `0 = a.rec, 1 = b.rec`.
fn numbered(files: &[String]) -> String {
    files
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{i} = {n}"))
        .collect::<Vec<_>>()
        .join(", ")
}
