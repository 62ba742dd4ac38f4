//! The pipeline's inputs: the scene, the path over it, the scene made the one a recording is
//! made of (crossing triangles split), and the light.

use std::path::{Path, PathBuf};
use std::time::Instant;

use trisort_format::{Clip, Environment, FrameState, RecordSettings};
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

/// One `--path` argument: a path spec, named when given as `NAME=SPEC`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PathArg {
    /// The clip's name, if given.
    pub name: Option<String>,
    /// The path spec (a TOML file, `gltf[:…]`, `orbit:…`, `dolly:…`, `demo`).
    pub spec: String,
}

/// Parses `[NAME=]SPEC`: the text before the first `=` is a clip name when it is one
/// ([`Clip::check_name`]: letters, digits, `_`, `-`, `.`), so `tour=examples/car-tour.toml`
/// is named `tour` while `orbit:frames=24` and `gltf:animation=Open` (a `:` before the `=`)
/// are specs. A TOML file whose name holds `=` is given as `./a=b.toml`.
pub fn parse_path_arg(arg: &str) -> PathArg {
    match arg.split_once('=') {
        Some((name, spec)) if Clip::check_name(name).is_ok() && !spec.is_empty() => PathArg {
            name: Some(name.to_string()),
            spec: spec.to_string(),
        },
        _ => PathArg {
            name: None,
            spec: arg.to_string(),
        },
    }
}

/// Loads the paths `args` (`[NAME=]SPEC` each) over `scene` at `fps` as one timeline of
/// clips: each path's frames (only `range` of them, for one path) one after the other, each
/// path a clip with its name, rate, hash and first frame. One whole path keeps its timeline
/// as it is (its hash too); a bundle's timeline runs at its first clip's rate.
pub fn load_clips(
    args: &[String],
    scene: &Scene,
    fps: f64,
    range: Option<crate::spec::FrameRange>,
) -> Result<(Timeline, Vec<Clip>), BakeError> {
    let clips_error = |text: String| Err(BakeError::Clips(text));
    if args.is_empty() {
        return clips_error(
            "no path given: give --path SPEC (or --path NAME=SPEC, repeated)".into(),
        );
    }
    if args.len() > 1 && range.is_some() {
        return clips_error(format!(
            "--frames takes a range of one path; this bake has {} paths (bake each range of a \
             bundle as a path of its own)",
            args.len()
        ));
    }
    let mut frames: Vec<FrameState> = Vec::new();
    let mut clips: Vec<Clip> = Vec::new();
    let mut rate = None;
    let mut only = None;
    for arg in args {
        let PathArg { name, spec } = parse_path_arg(arg);
        let name = match name {
            Some(n) => n,
            None if args.len() == 1 => Clip::DEFAULT_NAME.to_string(),
            None => {
                return clips_error(format!(
                    "path {arg:?}: the paths of a bundle are named: give --path NAME={arg} \
                     (NAME: letters, digits, _, - and .)"
                ))
            }
        };
        if clips.iter().any(|c| c.name == name) {
            return clips_error(format!(
                "two paths are named {name:?}; each clip needs its own name"
            ));
        }
        let timeline = load_path(&spec, scene, fps)?;
        let n = timeline.frames.len() as u32;
        let r = match range {
            Some(r) => r.resolve(n)?,
            None => 0..n,
        };
        clips.push(Clip {
            name,
            first: frames.len() as u32,
            count: r.end - r.start,
            fps: Some(timeline.fps),
            path_hash: timeline.hash(),
            path_first: r.start,
        });
        frames.extend_from_slice(&timeline.frames[r.start as usize..r.end as usize]);
        rate.get_or_insert(timeline.fps);
        if args.len() == 1 && r == (0..n) {
            only = Some(timeline);
        }
    }
    let timeline = only.unwrap_or(Timeline {
        fps: rate.unwrap_or(fps),
        frames,
    });
    Ok((timeline, clips))
}

/// The scene and path a recording is made of: what `record` and `bake` start from.
pub struct Working {
    /// The scene, its crossing triangles split when the settings ask for it.
    pub scene: Scene,
    /// The path's frames over it (a bundle's: its clips' frames one after the other).
    pub timeline: Timeline,
    /// The clips the timeline is made of ([`Clip::DEFAULT_NAME`] for one unnamed path).
    pub clips: Vec<Clip>,
    /// What was split (`None` when the settings keep intersections).
    pub split: Option<SplitReport>,
    /// Seconds the split took.
    pub split_seconds: f64,
}

impl Working {
    /// The scene and one whole path as they are (already split or not, as `split` says):
    /// one clip, [`Clip::DEFAULT_NAME`], of every frame at the timeline's rate.
    pub fn whole(
        scene: Scene,
        timeline: Timeline,
        split: Option<SplitReport>,
        split_seconds: f64,
    ) -> Working {
        let clips = vec![Clip::whole(
            timeline.frames.len() as u32,
            Some(timeline.fps),
            timeline.hash(),
        )];
        Working {
            scene,
            timeline,
            clips,
            split,
            split_seconds,
        }
    }

    /// Loads the scene `scene_spec` and the paths `paths` over it (at `fps`; `range` of one
    /// path's frames, [`load_clips`]) and makes the scene the one a recording with `settings`
    /// is made of ([`working_scene`]: a bundle's crossing triangles are split over all its
    /// frames).
    pub fn load(
        scene_spec: &str,
        paths: &[String],
        fps: f64,
        range: Option<crate::spec::FrameRange>,
        settings: &RecordSettings,
    ) -> Result<Working, BakeError> {
        let mut scene = load_scene(scene_spec)?;
        let (timeline, clips) = load_clips(paths, &scene, fps, range)?;
        let from = format!("path {}", paths.join(", path "));
        let t0 = Instant::now();
        let split = working_scene(&mut scene, scene_spec, &timeline.frames, &from, settings)?;
        Ok(Working {
            scene,
            timeline,
            clips,
            split,
            split_seconds: t0.elapsed().as_secs_f64(),
        })
    }

    /// The scene and paths `settings` name, made the ones its recording is made of.
    pub fn for_settings(settings: &crate::Settings) -> Result<Working, BakeError> {
        Working::load(
            &settings.scene,
            &settings.paths,
            settings.fps,
            settings.frames,
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
