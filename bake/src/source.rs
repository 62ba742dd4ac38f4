//! The pipeline's inputs: the scene, the path over it, the scene made the one a recording is
//! made of (crossing triangles split), and the light.

use std::path::{Path, PathBuf};
use std::time::Instant;

use trisort_format::{Environment, FrameState, RecordSettings};
use trisort_intersect::SplitReport;
use trisort_paths::Timeline;
use trisort_scene::Scene;

use crate::BakeError;

/// Loads a scene: a `.glb`/`.gltf` file, or `demo` / `demo:TRIANGLES` for the built-in car.
/// The importer's notes are in [`Scene::notes`].
pub fn load_scene(spec: &str) -> Result<Scene, BakeError> {
    if let Some(rest) = spec.strip_prefix("demo") {
        let triangles = match rest.strip_prefix(':') {
            Some(n) => n.parse().map_err(|_| BakeError::DemoSpec {
                spec: spec.to_string(),
            })?,
            None if rest.is_empty() => trisort_scene::demo_car::DEFAULT_TRIANGLES,
            None => return Ok(trisort_scene::load(Path::new(spec))?),
        };
        return Ok(trisort_scene::demo_car::demo_car(triangles));
    }
    Ok(trisort_scene::load(Path::new(spec))?)
}

/// Loads a path over a scene (`demo` gives the demo car's default path), sampling `gltf` and
/// generated paths at `fps`.
pub fn load_path(spec: &str, scene: &Scene, fps: f64) -> Result<Timeline, BakeError> {
    if spec == "demo" {
        return Ok(trisort_paths::demo_default(scene));
    }
    let opts = trisort_paths::PathOptions { fps };
    Ok(trisort_paths::load(spec, scene, &opts)?)
}

/// The scene and path a recording is made of: what `record` and `bake` start from.
pub struct Working {
    /// The scene, its crossing triangles split when the settings ask for it.
    pub scene: Scene,
    /// The path's frames over it.
    pub timeline: Timeline,
    /// What was split (`None` when the settings keep intersections).
    pub split: Option<SplitReport>,
    /// Seconds the split took.
    pub split_seconds: f64,
}

impl Working {
    /// Loads the scene `scene_spec` and the path `path_spec` over it (at `fps`) and makes the
    /// scene the one a recording with `settings` is made of ([`working_scene`]).
    pub fn load(
        scene_spec: &str,
        path_spec: &str,
        fps: f64,
        settings: &RecordSettings,
    ) -> Result<Working, BakeError> {
        let mut scene = load_scene(scene_spec)?;
        let timeline = load_path(path_spec, &scene, fps)?;
        let from = format!("path {path_spec}");
        let t0 = Instant::now();
        let split = working_scene(&mut scene, scene_spec, &timeline.frames, &from, settings)?;
        Ok(Working {
            scene,
            timeline,
            split,
            split_seconds: t0.elapsed().as_secs_f64(),
        })
    }

    /// The scene and path `settings` name, made the ones its recording is made of.
    pub fn for_settings(settings: &crate::Settings) -> Result<Working, BakeError> {
        Working::load(
            &settings.scene,
            &settings.path,
            settings.fps,
            &settings.record,
        )
    }

    /// What the split did, in one line, when it changed anything: `split N pairs of
    /// triangles that pass through each other (+T triangles; K pairs left, …) in S s`.
    pub fn split_summary(&self) -> Option<String> {
        let r = self.split.as_ref()?;
        if r.pairs_split == 0 && r.pairs_skipped_sliver == 0 && r.pairs_split_across_groups == 0 {
            return None;
        }
        let across = match r.pairs_split_across_groups {
            0 => String::new(),
            n => format!("{n} of them of parts that move apart, as the first frame poses them; "),
        };
        Some(format!(
            "split {} pairs of triangles that pass through each other ({across}+{} \
             triangles; {} pairs left, their pieces would be slivers) in {:.2} s",
            r.pairs_split + r.pairs_split_across_groups,
            r.triangles_added,
            r.pairs_skipped_sliver,
            self.split_seconds
        ))
    }
}

/// Makes `scene` the scene a recording with `settings` is made of: with
/// `settings.split_intersections`, its triangles that pass through each other (within a rigid
/// group, then across groups as the first frame poses them) are split along their
/// intersection ([`trisort_intersect::working_geometry`]), which changes the scene's
/// triangles and hash. Returns what was split.
///
/// `frames` come from `frames_from` (a path, a recording or a baked file, for the message):
/// their poses must name nodes of the scene (`spec`), or the scene is not the one they were
/// made over, and this is an error naming both rather than an out-of-range node.
pub fn working_scene(
    scene: &mut Scene,
    spec: &str,
    frames: &[FrameState],
    frames_from: &str,
    settings: &RecordSettings,
) -> Result<Option<SplitReport>, BakeError> {
    let nodes = scene.geometry.nodes.len();
    for (f, s) in frames.iter().enumerate() {
        if let Err(why) = trisort_format::camera::check_frame_state(f, s, Some(nodes)) {
            return Err(BakeError::NotTheScene {
                spec: spec.to_string(),
                nodes,
                frames_from: frames_from.to_string(),
                why: why.to_string(),
            });
        }
    }
    let Some(split) = trisort_intersect::working_geometry(&scene.geometry, frames, settings) else {
        return Ok(None);
    };
    *scene.geometry_mut() = split.geometry;
    Ok(Some(split.report))
}

/// The light stored in a baked file, which players shade with.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Light {
    /// The built-in studio with a sun (the default).
    Studio,
    /// An equirectangular Radiance .hdr file, prefiltered at bake time.
    Hdr(PathBuf),
}

impl Light {
    /// `studio` or an .hdr file's path (`--environment`; a file named `studio` is
    /// `./studio`).
    pub fn parse(spec: &str) -> Light {
        if spec == "studio" {
            Light::Studio
        } else {
            Light::Hdr(PathBuf::from(spec))
        }
    }

    /// The environment: the studio, or the .hdr file loaded and prefiltered (an error naming
    /// the file when it cannot be).
    pub fn load(&self) -> Result<Environment, BakeError> {
        match self {
            Light::Studio => Ok(trisort_light::studio()),
            Light::Hdr(path) => Ok(trisort_scene::load_hdr(path)?),
        }
    }
}
