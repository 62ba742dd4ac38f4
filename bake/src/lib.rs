//! trisort's pipeline as a library: scene → split → path → record (resumable) → merge →
//! light → write.
//!
//! One settings type, [`Settings`], says what to bake; [`Working::load`] makes the scene and
//! path a recording is made of (the glTF or demo scene, its crossing triangles split, the
//! path sampled over it); [`record_to_file`] records with the frames finished so far kept in
//! `OUT.partial/`, so a killed run resumes; [`bake`] records (or reuses this bake's finished
//! recording) and merges, and the pipeline, not the merger, attaches the light. The CLI,
//! `bench` and the tests call this; none of it prints: progress and notes go to the
//! caller's [`Events`].

#![warn(missing_docs)]

mod error;
pub mod figures;
pub mod inputs;
mod pipeline;
mod record;
pub mod shard;
mod source;
pub mod spec;
pub mod textures;

pub use error::BakeError;
pub use pipeline::{bake, finished_recording, merge_to_file, recording_path, Baking};
pub use record::{record_in_memory, record_to_file, RecordTarget};
pub use source::{load_path, load_scene, parse_path_arg, working_scene, Light, PathArg, Working};

use trisort_format::RecordSettings;
use trisort_merger::MergeOptions;

/// What to bake: the whole pipeline's settings in one place.
#[derive(Clone, Debug)]
pub struct Settings {
    /// The scene: a `.glb`/`.gltf` file, or `demo` / `demo:TRIANGLES` for the built-in car.
    pub scene: String,
    /// The paths, one per clip, each `[NAME=]SPEC` ([`source::parse_path_arg`]): SPEC a TOML
    /// file, `gltf[:…]`, `orbit:…`, `dolly:…`, or `demo` for the demo car's default path.
    /// Several make a bundle: their frames follow each other in one recording and one baked
    /// file, each path a named clip of its own rate.
    pub paths: Vec<String>,
    /// Sampling rate of `gltf` and generated paths, in frames per second.
    pub fps: f64,
    /// Recording settings, the raster profile among them (their `split_intersections` says
    /// whether crossing triangles are split first).
    pub record: RecordSettings,
    /// A frame range of the path to bake as a clip of those frames alone (`None`: the whole
    /// path; one path only), resolved against the path once it is loaded.
    pub frames: Option<spec::FrameRange>,
    /// Merge options.
    pub merge: MergeOptions,
    /// The light stored in the baked file.
    pub light: Light,
    /// How the baked file stores its textures (`--textures`; RGBA8 by default).
    pub textures: textures::TextureFormat,
}

impl Settings {
    /// Settings for `scene` and `path` with every default: the default recording settings
    /// (conformant raster profile), 30 fps, the whole path, the default merge, the studio.
    pub fn new(scene: impl Into<String>, path: impl Into<String>) -> Settings {
        Settings {
            scene: scene.into(),
            paths: vec![path.into()],
            fps: 30.0,
            record: RecordSettings::default(),
            frames: None,
            merge: MergeOptions::default(),
            light: Light::Studio,
            textures: textures::TextureFormat::Rgba8,
        }
    }
}

/// What the pipeline tells its caller while it works. Every method has a silent default.
pub trait Events {
    /// A note about the input (an importer's note on the scene, a resumed recording).
    fn note(&mut self, _text: &str) {}
    /// Recording progress: phase `phase` (1 or 2), `done` of `total` frames, the last one
    /// `frame` with `layers` peel layers.
    fn progress(&mut self, _p: &trisort_recorder::Progress) {}
    /// Recording finished (the progress display may go).
    fn recorded(&mut self) {}
}

/// [`Events`] that ignore everything.
pub struct Silent;

impl Events for Silent {}
