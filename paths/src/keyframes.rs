//! The TOML keyframe path format (documented in the crate root): reading, checking with file
//! positions, and sampling into frames.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

use glam::{DMat4, DVec3};
use serde::Deserialize;
use toml::Spanned;
use trisort_format::{Camera, FrameState};
use trisort_scene::Scene;

use crate::error::{line_column, similar_names, Location, PathError, Problem};
use crate::interpolate::{Interpolation, Track};
use crate::poses::{pivot_pose, pose_if_moved};
use crate::view::DEFAULT_YFOV_DEGREES;
use crate::view::{check_clip, check_fov_degrees, default_clip, look_at, Bounds};
use crate::Timeline;

/// Frames per second when the file gives none.
const DEFAULT_FPS: f64 = 30.0;
/// Longest timeline a TOML file may ask for (a typo such as `time = 1e9` must not allocate
/// billions of frames).
pub(crate) const MAX_FRAMES: usize = 1_000_000;
/// Key positions within this distance of a whole frame are snapped to it, so that `time`
/// keys land exactly on frames despite rounding (0.1 s × 30 fps = 3.0000000000000004).
const SNAP: f64 = 1e-6;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PathFile {
    fps: Option<Spanned<f64>>,
    frames: Option<Spanned<i64>>,
    interpolation: Option<Interpolation>,
    camera: Option<CameraSection>,
    #[serde(default)]
    node: Vec<Spanned<NodeSection>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraSection {
    up: Option<Spanned<[f64; 3]>>,
    yfov: Option<Spanned<f64>>,
    znear: Option<Spanned<f64>>,
    zfar: Option<Spanned<toml::Value>>,
    interpolation: Option<Interpolation>,
    #[serde(default)]
    key: Vec<Spanned<CameraKey>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraKey {
    frame: Option<Spanned<f64>>,
    time: Option<Spanned<f64>>,
    eye: Option<Spanned<[f64; 3]>>,
    target: Option<Spanned<[f64; 3]>>,
    up: Option<Spanned<[f64; 3]>>,
    yfov: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NodeSection {
    name: Spanned<String>,
    axis: Option<Spanned<[f64; 3]>>,
    pivot: Option<Spanned<[f64; 3]>>,
    interpolation: Option<Interpolation>,
    #[serde(default)]
    key: Vec<Spanned<NodeKey>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NodeKey {
    frame: Option<Spanned<f64>>,
    time: Option<Spanned<f64>>,
    angle: Option<Spanned<f64>>,
    translation: Option<Spanned<[f64; 3]>>,
}

/// Reads and samples a TOML path file.
pub(crate) fn load_file(path: &Path, scene: &Scene) -> Result<Timeline, PathError> {
    let text = std::fs::read_to_string(path).map_err(|source| PathError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse(&text, path, scene)
}

/// Error context: the file's name and text, to turn spans into lines and columns.
struct Ctx<'a> {
    path: &'a Path,
    text: &'a str,
}

impl Ctx<'_> {
    fn at(&self, span: Range<usize>, problem: Problem) -> PathError {
        PathError::Invalid {
            at: Location::at_offset(self.path.display().to_string(), self.text, span.start),
            problem,
        }
    }

    fn whole(&self, problem: Problem) -> PathError {
        PathError::Invalid {
            at: Location::whole(self.path.display().to_string()),
            problem,
        }
    }

    fn finite(&self, v: &Spanned<f64>, what: &str) -> Result<f64, PathError> {
        let x = *v.get_ref();
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.at(v.span(), Problem::NonFinite { what: what.into() }))
        }
    }

    fn finite3(&self, v: &Spanned<[f64; 3]>, what: &str) -> Result<[f64; 3], PathError> {
        let x = *v.get_ref();
        if x.iter().all(|c| c.is_finite()) {
            Ok(x)
        } else {
            Err(self.at(v.span(), Problem::NonFinite { what: what.into() }))
        }
    }

    /// The frame position of a key given by `frame` or `time` (exactly one), snapped to a
    /// whole frame within [`SNAP`].
    fn position(
        &self,
        key_span: Range<usize>,
        frame: &Option<Spanned<f64>>,
        time: &Option<Spanned<f64>>,
        fps: f64,
    ) -> Result<f64, PathError> {
        let (pos, span) = match (frame, time) {
            (Some(f), None) => (self.finite(f, "frame")?, f.span()),
            (None, Some(t)) => (self.finite(t, "time")? * fps, t.span()),
            _ => {
                return Err(self.at(
                    key_span,
                    Problem::Inconsistent("a key needs exactly one of `frame` or `time`".into()),
                ))
            }
        };
        if !pos.is_finite() || pos < 0.0 {
            return Err(self.at(
                span,
                Problem::Inconsistent(format!("key position {pos} is negative or too large")),
            ));
        }
        if pos >= MAX_FRAMES as f64 {
            return Err(self.at(
                span,
                Problem::Inconsistent(format!(
                    "key at frame {pos} is beyond the limit of {MAX_FRAMES} frames"
                )),
            ));
        }
        let whole = pos.round();
        Ok(if (pos - whole).abs() <= SNAP {
            whole
        } else {
            pos
        })
    }
}

/// Keys of one property of one track, by position, with the span of the key for errors.
type Keys<const N: usize> = Vec<(f64, [f64; N], Range<usize>)>;

/// A track from keys in file order: sorts them by position; two keys at one position are an
/// error. `None` when there are no keys.
fn track<const N: usize>(
    ctx: &Ctx,
    mut keys: Keys<N>,
    mode: Interpolation,
    what: &str,
) -> Result<Option<Track<N>>, PathError> {
    keys.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in keys.windows(2) {
        if w[0].0 == w[1].0 {
            return Err(ctx.at(
                w[1].2.clone(),
                Problem::Inconsistent(format!("two {what} keys at frame {}", w[1].0)),
            ));
        }
    }
    if keys.is_empty() {
        return Ok(None);
    }
    Ok(Some(Track::new(
        keys.into_iter().map(|(p, v, _)| (p, v)).collect(),
        mode,
    )))
}

/// One node's rotation and translation tracks.
struct NodeTrack {
    node: u32,
    rest: DMat4,
    axis: DVec3,
    pivot: DVec3,
    angle: Option<Track<1>>,
    translation: Option<Track<3>>,
}

/// Parses, checks and samples a TOML path.
pub(crate) fn parse(text: &str, path: &Path, scene: &Scene) -> Result<Timeline, PathError> {
    let file: PathFile = toml::from_str(text).map_err(|e| {
        let (line, column) = line_column(text, e.span().map_or(0, |s| s.start));
        PathError::Syntax {
            path: path.to_path_buf(),
            line,
            column,
            message: e.message().trim().to_string(),
        }
    })?;
    let ctx = Ctx { path, text };
    let fps = path_fps(&ctx, &file)?;
    let global = file.interpolation.unwrap_or_default();
    let Some(camera) = &file.camera else {
        return Err(ctx.whole(Problem::Inconsistent(
            "no [camera] section: a path needs camera keys".into(),
        )));
    };
    let cam = CameraTracks::parse(&ctx, camera, global, fps)?;
    let mut nodes: Vec<NodeTrack> = Vec::new();
    for section in &file.node {
        let track = NodeTrack::parse(&ctx, scene, section, &nodes, global, fps)?;
        nodes.push(track);
    }
    nodes.sort_by_key(|t| t.node);
    let frame_count = frame_count(&ctx, &file, &cam, &nodes)?;
    sample(&ctx, scene, camera, &cam, &nodes, frame_count, fps)
}

/// The path's frame rate: `fps` if given (positive), else [`DEFAULT_FPS`].
fn path_fps(ctx: &Ctx, file: &PathFile) -> Result<f64, PathError> {
    Ok(match &file.fps {
        Some(f) => {
            let fps = ctx.finite(f, "fps")?;
            if fps <= 0.0 {
                return Err(ctx.at(
                    f.span(),
                    Problem::Inconsistent(format!("fps must be positive, not {fps}")),
                ));
            }
            fps
        }
        None => DEFAULT_FPS,
    })
}

/// The camera's tracks, with what frame errors need to point at the right key.
struct CameraTracks {
    eye: Track<3>,
    target: Track<3>,
    up: Track<3>,
    fov: Track<1>,
    /// Camera keys by frame, for pointing frame errors at the key that set the frame.
    key_at: BTreeMap<u64, Range<usize>>,
    /// Where errors about the camera as a whole point: its first key.
    span: Range<usize>,
}

impl CameraTracks {
    fn parse(
        ctx: &Ctx,
        camera: &CameraSection,
        global: Interpolation,
        fps: f64,
    ) -> Result<CameraTracks, PathError> {
        // Errors about the camera as a whole point at its first key (a `Spanned` camera table
        // fails on an implicit `[camera]` created by `[[camera.key]]`).
        let camera_span = camera.key.first().map_or(0..0, |k| k.span());
        let cam_mode = camera.interpolation.unwrap_or(global);
        let default_up = match &camera.up {
            Some(u) => ctx.finite3(u, "up")?,
            None => [0.0, 1.0, 0.0],
        };
        let default_yfov = match &camera.yfov {
            Some(y) => {
                let deg = ctx.finite(y, "yfov")?;
                check_fov_degrees(deg).map_err(|p| ctx.at(y.span(), p))?;
                deg
            }
            None => DEFAULT_YFOV_DEGREES,
        };
        let (mut eyes, mut targets, mut ups): (Keys<3>, Keys<3>, Keys<3>) = Default::default();
        let mut fovs: Keys<1> = Vec::new();
        // Camera keys by frame, for pointing frame errors at the key that set the frame.
        let mut key_at: BTreeMap<u64, Range<usize>> = BTreeMap::new();
        for key in &camera.key {
            let span = key.span();
            let k = key.get_ref();
            let pos = ctx.position(span.clone(), &k.frame, &k.time, fps)?;
            if pos.fract() == 0.0 {
                key_at.insert(pos as u64, span.clone());
            }
            if k.eye.is_none() && k.target.is_none() && k.up.is_none() && k.yfov.is_none() {
                return Err(ctx.at(
                    span,
                    Problem::Inconsistent(
                        "a camera key sets none of `eye`, `target`, `up`, `yfov`".into(),
                    ),
                ));
            }
            if let Some(v) = &k.eye {
                eyes.push((pos, ctx.finite3(v, "eye")?, v.span()));
            }
            if let Some(v) = &k.target {
                targets.push((pos, ctx.finite3(v, "target")?, v.span()));
            }
            if let Some(v) = &k.up {
                ups.push((pos, ctx.finite3(v, "up")?, v.span()));
            }
            if let Some(v) = &k.yfov {
                let deg = ctx.finite(v, "yfov")?;
                check_fov_degrees(deg).map_err(|p| ctx.at(v.span(), p))?;
                fovs.push((pos, [deg], v.span()));
            }
        }
        let eye_track = track(ctx, eyes, cam_mode, "eye")?.ok_or_else(|| {
            ctx.at(
                camera_span.clone(),
                Problem::Inconsistent("no camera key sets `eye`".into()),
            )
        })?;
        let target_track = track(ctx, targets, cam_mode, "target")?.ok_or_else(|| {
            ctx.at(
                camera_span.clone(),
                Problem::Inconsistent("no camera key sets `target`".into()),
            )
        })?;
        let up_track = track(ctx, ups, cam_mode, "up")?
            .unwrap_or_else(|| Track::new(vec![(0.0, default_up)], cam_mode));
        let fov_track = track(ctx, fovs, cam_mode, "yfov")?
            .unwrap_or_else(|| Track::new(vec![(0.0, [default_yfov])], cam_mode));

        Ok(CameraTracks {
            eye: eye_track,
            target: target_track,
            up: up_track,
            fov: fov_track,
            key_at,
            span: camera_span,
        })
    }
}

impl NodeTrack {
    /// One `[[node]]` section's tracks; a node that already has one in `seen` is an error.
    fn parse(
        ctx: &Ctx,
        scene: &Scene,
        section: &Spanned<NodeSection>,
        seen: &[NodeTrack],
        global: Interpolation,
        fps: f64,
    ) -> Result<NodeTrack, PathError> {
        let s = section.get_ref();
        let name = s.name.get_ref();
        let Some(node) = scene.node_by_name(name) else {
            let names = scene.geometry.nodes.iter().map(|n| n.name.as_str());
            return Err(ctx.at(
                s.name.span(),
                Problem::UnknownNode {
                    name: name.clone(),
                    similar: similar_names(name, names),
                },
            ));
        };
        if seen.iter().any(|t| t.node == node) {
            return Err(ctx.at(
                s.name.span(),
                Problem::Inconsistent(format!("node {name:?} has two tracks")),
            ));
        }
        let mode = s.interpolation.unwrap_or(global);
        let (mut angles, mut moves): (Keys<1>, Keys<3>) = Default::default();
        for key in &s.key {
            let span = key.span();
            let k = key.get_ref();
            let pos = ctx.position(span.clone(), &k.frame, &k.time, fps)?;
            if k.angle.is_none() && k.translation.is_none() {
                return Err(ctx.at(
                    span,
                    Problem::Inconsistent(
                        "a node key sets neither `angle` nor `translation`".into(),
                    ),
                ));
            }
            if let Some(a) = &k.angle {
                angles.push((pos, [ctx.finite(a, "angle")?], a.span()));
            }
            if let Some(t) = &k.translation {
                moves.push((pos, ctx.finite3(t, "translation")?, t.span()));
            }
        }
        let angle = track(ctx, angles, mode, "angle")?;
        let translation = track(ctx, moves, mode, "translation")?;
        if angle.is_none() && translation.is_none() {
            return Err(ctx.at(
                section.span(),
                Problem::Inconsistent(format!("node {name:?} has no keys")),
            ));
        }
        let axis = match (&s.axis, &angle) {
            (Some(a), _) => {
                let v = DVec3::from(ctx.finite3(a, "axis")?);
                if v.length() == 0.0 {
                    return Err(ctx.at(
                        a.span(),
                        Problem::Inconsistent("the rotation axis is zero".into()),
                    ));
                }
                v.normalize()
            }
            (None, Some(_)) => {
                return Err(ctx.at(
                    s.name.span(),
                    Problem::Inconsistent(format!("node {name:?} has `angle` keys but no `axis`")),
                ))
            }
            (None, None) => DVec3::Y,
        };
        let pivot = match &s.pivot {
            Some(p) => DVec3::from(ctx.finite3(p, "pivot")?),
            None => DVec3::ZERO,
        };
        Ok(NodeTrack {
            node,
            rest: DMat4::from_cols_array(&scene.geometry.nodes[node as usize].rest),
            axis,
            pivot,
            angle,
            translation,
        })
    }
}

/// Frames on the path: `frames` if given, else up to the last key of any track.
fn frame_count(
    ctx: &Ctx,
    file: &PathFile,
    cam: &CameraTracks,
    nodes: &[NodeTrack],
) -> Result<usize, PathError> {
    Ok(match &file.frames {
        Some(f) => {
            let n = *f.get_ref();
            if n <= 0 {
                return Err(ctx.at(f.span(), Problem::ZeroFrames));
            }
            if n as u64 > MAX_FRAMES as u64 {
                return Err(ctx.at(
                    f.span(),
                    Problem::Inconsistent(format!("more than {MAX_FRAMES} frames")),
                ));
            }
            n as usize
        }
        None => {
            let mut last = cam
                .eye
                .last_position()
                .max(cam.target.last_position())
                .max(cam.up.last_position())
                .max(cam.fov.last_position());
            for t in nodes {
                if let Some(a) = &t.angle {
                    last = last.max(a.last_position());
                }
                if let Some(m) = &t.translation {
                    last = last.max(m.last_position());
                }
            }
            last.floor() as usize + 1
        }
    })
}

/// Samples the tracks at every frame: views, clip planes (defaults from the scene's bounds
/// seen along the path) and node poses.
fn sample(
    ctx: &Ctx,
    scene: &Scene,
    camera: &CameraSection,
    cam: &CameraTracks,
    nodes: &[NodeTrack],
    frame_count: usize,
    fps: f64,
) -> Result<Timeline, PathError> {
    // Clip planes.
    let frame_error = |frame: usize, problem: Problem| match cam.key_at.get(&(frame as u64)) {
        Some(span) => ctx.at(span.clone(), problem),
        None => ctx.whole(problem),
    };
    let mut views = Vec::with_capacity(frame_count);
    for f in 0..frame_count {
        let t = f as f64;
        let eye = DVec3::from(cam.eye.sample(t));
        let target = DVec3::from(cam.target.sample(t));
        let up = DVec3::from(cam.up.sample(t));
        let view = look_at(eye, target, up, f).map_err(|p| frame_error(f, p))?;
        views.push((eye, view, cam.fov.sample(t)[0]));
    }
    let znear = camera
        .znear
        .as_ref()
        .map(|z| (ctx.finite(z, "znear"), z.span()));
    let zfar = match &camera.zfar {
        None => None,
        Some(z) => Some((zfar_value(ctx, z)?, z.span())),
    };
    let (znear, zfar) = match (znear, zfar) {
        (Some((near, _)), Some((far, _))) => (near?, far),
        (near, far) => {
            let bounds = Bounds::of_scene(scene).map_err(|p| ctx.whole(p))?;
            let (dnear, dfar) = default_clip(&bounds, views.iter().map(|v| v.0));
            let near = match near {
                Some((n, _)) => n?,
                None => dnear,
            };
            (near, far.map_or(Some(dfar.max(2.0 * near)), |f| f.0))
        }
    };
    let clip_span = camera
        .znear
        .as_ref()
        .map(|z| z.span())
        .or(camera.zfar.as_ref().map(|z| z.span()))
        .unwrap_or(cam.span.clone());
    check_clip(znear, zfar).map_err(|p| ctx.at(clip_span, p))?;

    let mut frames = Vec::with_capacity(frame_count);
    for (f, (_, view, fov)) in views.into_iter().enumerate() {
        let t = f as f64;
        let mut poses = Vec::new();
        for n in nodes {
            let angle = n.angle.as_ref().map_or(0.0, |a| a.sample(t)[0]);
            let translation = n
                .translation
                .as_ref()
                .map_or(DVec3::ZERO, |m| DVec3::from(m.sample(t)));
            let local = pivot_pose(n.rest, translation, n.pivot, n.axis, angle.to_radians());
            poses.extend(pose_if_moved(n.node, &n.rest.to_cols_array(), local));
        }
        frames.push(FrameState {
            camera: Camera {
                view: view.to_cols_array(),
                yfov: fov.to_radians(),
                znear,
                zfar,
            },
            poses,
        });
    }
    Ok(Timeline { fps, frames })
}

/// `zfar`: a positive number, or the string `"infinite"` (`None`).
fn zfar_value(ctx: &Ctx, z: &Spanned<toml::Value>) -> Result<Option<f64>, PathError> {
    let span = z.span();
    match z.get_ref() {
        toml::Value::Float(x) => {
            if x.is_finite() {
                Ok(Some(*x))
            } else {
                Err(ctx.at(
                    span,
                    Problem::NonFinite {
                        what: "zfar (write \"infinite\" for an infinite far plane)".into(),
                    },
                ))
            }
        }
        toml::Value::Integer(i) => Ok(Some(*i as f64)),
        toml::Value::String(s) if s == "infinite" => Ok(None),
        other => Err(ctx.at(
            span,
            Problem::Inconsistent(format!(
                "zfar must be a number or \"infinite\", not {other}"
            )),
        )),
    }
}
