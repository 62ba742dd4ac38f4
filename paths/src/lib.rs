//! Camera and animation paths: the frame timeline.
//!
//! A path gives, for every frame, a camera ([`Camera`]: view matrix, vertical field of view,
//! near and far planes) and the local transforms of the nodes that differ from their rest pose
//! ([`NodePose`]). [`load`] reads one from a *spec*:
//!
//! | spec | path |
//! |---|---|
//! | `gltf` | the scene's own animations and first camera ([§ glTF](#the-gltf-path)) |
//! | `gltf:animation=NAME,camera=NAME` | one animation and/or camera of the scene, by name ([§ glTF](#the-gltf-path)) |
//! | `orbit:k=v,…` (or `orbit`) | a circle around the scene ([§ generators](#generators)) |
//! | `dolly:k=v,…` (or `dolly`) | a straight approach to the scene ([§ generators](#generators)) |
//! | anything else | a TOML keyframe file ([§ TOML](#the-toml-keyframe-format)) |
//!
//! A spec `word:…` whose word is not a generator and that names no existing file is an
//! unknown generator; write `./gltf` for a file named `gltf`.
//!
//! Conventions: world space is the scene's (glTF: right-handed, +Y up, metres); cameras look
//! down their −Z; angles in specs and files are in degrees, in [`Camera`] in radians.
//! Every camera of every path satisfies: finite, invertible view; yfov in (0°, 180°);
//! 0 < znear < zfar (or an infinite far plane). Anything else is a [`PathError`], never a
//! panic.
//!
//! # The TOML keyframe format
//!
//! ```toml
//! fps = 30                        # frames per second (default 30); `time` keys use it
//! interpolation = "catmull-rom"   # default for every track: linear | catmull-rom |
//!                                 # ease-in-out | step (default linear)
//! # frames = 301                  # optional frame count; default: 0..=last key frame
//!
//! [camera]
//! yfov = 45                       # degrees, for frames before any `yfov` key (default 45)
//! up = [0, 1, 0]                  # up vector before any `up` key (default +Y)
//! znear = 0.05                    # default: derived from the scene bounds (below)
//! zfar = 100                      # a number or "infinite"; default: derived
//! interpolation = "catmull-rom"   # overrides the global mode for the camera
//!
//! [[camera.key]]
//! frame = 0                       # or `time = 0.0` (seconds); exactly one of the two
//! eye = [6, 2, 6]                 # each key sets any of eye, target, up, yfov
//! target = [0, 0.6, 0]
//!
//! [[camera.key]]
//! time = 2.5
//! eye = [-6, 2, 6]
//! yfov = 30
//!
//! [[node]]
//! name = "BodyDoorLColor1"        # a scene node (the first one of that name)
//! axis = [0, 0, -1]               # rotation axis, node's local frame (needed for `angle`)
//! pivot = [0, 0, 0]               # a point on the axis, local frame (default: the origin)
//! interpolation = "ease-in-out"   # overrides the global mode for this node
//! key = [
//!   { frame = 60, angle = 0 },    # degrees about `axis`, right-handed
//!   { frame = 90, angle = 60 },
//!   { frame = 120, angle = 0, translation = [0, 0, 0] },
//! ]
//! ```
//!
//! - **Keys and tracks.** Every property (camera eye, target, up, yfov; a node's angle and
//!   translation) is its own track through the keys that set it, so a key may set only what
//!   changes (a pan sets only `target`, a zoom only `yfov`). Keys may come in any order; a
//!   `time` key sits at frame `time × fps` (snapped to a whole frame within 10⁻⁶); two keys of
//!   one track at the same frame are an error. Before its first key a track holds its first
//!   value, after its last key its last value. `eye` and `target` need at least one key each.
//! - **Interpolation.** `linear`; `catmull-rom` (a C¹ cubic through the keys with tangents
//!   (p[k+1] − p[k−1]) / (t[k+1] − t[k−1]), one-sided at the ends; may overshoot); `ease-in-out`
//!   (each segment eased by smoothstep, stopping at every key); `step`. Every mode takes the
//!   key's value exactly at a key frame. Vectors are interpolated per component, angles as
//!   numbers (so 0 → 270 turns three quarters).
//! - **Frames.** Frames 0, 1, …, ⌊last key frame⌋ unless `frames` is given (then exactly that
//!   many; keys beyond it are cut, frames beyond the last key hold it). At most 1,000,000.
//! - **Camera.** Frame f looks from eye(f) at target(f) with up(f) (glam `look_at_rh`).
//! - **Nodes.** A node's local transform at frame f is
//!   `rest · T(translation(f)) · T(pivot) · R(axis, angle(f)) · T(−pivot)`: translation,
//!   axis and pivot are in the node's own frame, the space its mesh's vertices are in; a
//!   missing track contributes nothing. Frames list a node only where its transform differs
//!   from rest.
//! - **Derived clip planes.** Without `znear`: max(¼ × the smallest distance from any
//!   frame's eye to the scene's rest-pose bounding box, 0.002 × bounding radius). Without
//!   `zfar`: the largest distance from any eye to the box's farthest corner plus the bounding
//!   radius. The bounding radius is half the box diagonal. Both are constant over the path.
//! - **Errors** carry file, line and column: TOML syntax and unknown keys; NaN or infinite
//!   values (TOML has `nan` and `inf`); `frames = 0`; yfov outside (0°, 180°); znear ≤ 0 or
//!   ≥ zfar; an unknown node name (with the closest names of the scene); a key with both or
//!   neither of `frame`/`time`, or with nothing to set. Per-frame problems (eye at target, up
//!   parallel to eye → target) name the frame, and the key's line when a camera key sits on
//!   that frame.
//!
//! # The `gltf` path
//!
//! All animations of the scene play together from t = 0, sampled at
//! [`PathOptions::fps`] over t = 0, 1/fps, … up to the end of the longest channel
//! (⌊duration × fps⌋ + 1 frames). Where several channels drive one node property, the last
//! one (in animation, then channel order) wins. Each channel replaces its component (T, R or
//! S) of the node's rest transform (decomposed into scale, rotation, translation) and holds
//! its first / last key outside its key range. Interpolation per glTF 2.0 Appendix C:
//! `LINEAR` (slerp on the shorter arc for rotations), `STEP`, `CUBICSPLINE` (Hermite with the
//! stored tangents × the key interval; rotations normalized).
//!
//! `gltf:animation=NAME,camera=NAME` (both optional, in any order) plays only the animations
//! named NAME (usually one) and takes the camera named NAME; a name the scene lacks is an error
//! that lists the scene's animations or cameras. Names cannot contain `,`.
//!
//! The camera is the scene's first camera (or the one named): view = inverse of its node's world transform at
//! that frame with any scale removed; yfov, znear and zfar are the camera's (its aspect ratio
//! is ignored: the recording size decides). A scene without a camera gets a fixed framing
//! camera: 45° yfov, looking at the bounding-box centre from the direction (1, 0.5, 2) (front
//! right, above, for a model whose front faces +Z), far enough that the bounding sphere fits
//! with 10 % margin, with derived clip planes. A scene without animation gives **one
//! frame**; without animation and camera, one frame of the framing camera.
//!
//! # Generators
//!
//! Both look at the centre of the scene's rest-pose bounding box with +Y up, use derived clip
//! planes (as for TOML) and a 45° field of view unless `fov` is given; the timeline's fps is
//! [`PathOptions::fps`]. Parameters are `name=value`, separated by commas, each optional and
//! at most once.
//!
//! - `orbit:frames=N,degrees=D,elevation=E,distance=K,fov=F,start=S` — the eye circles
//!   the centre about the vertical (+Y) axis at K × bounding radius (half the box diagonal)
//!   and E degrees above the horizontal, from azimuth S (0: on the +Z side) through D degrees
//!   (positive: from +Z towards +X). Defaults: N = 48, D = 360, E = 20, K = 2.75 (the bounding
//!   sphere fits the default 45° field of view), F = 45, S = 0. When D is a whole number of
//!   turns, frame i is at S + D·i/N (a loop that does not repeat frame 0); otherwise at
//!   S + D·i/(N−1) (the last frame ends the sweep). E must be in (−90, 90), K > 0.
//! - `dolly:frames=N,from=x;y;z,to=x;y;z,fov=F` — the eye moves on a straight line from
//!   `from` to `to` (world coordinates; frame i at from + (to − from)·i/(N−1)). Point
//!   components are separated by `;` or `:` (`:` needs no quoting in a shell). Defaults:
//!   N = 48, from = centre + (0, 0.25, 3) × radius, to = centre + (0, 0.1, 1.5) × radius.
//!   An eye on the centre, or straight above or below it, is an error naming the frame.
#![deny(missing_docs)]

mod demo;
mod error;
mod generators;
mod gltf_anim;
mod interpolate;
mod keyframes;
mod poses;
mod view;

use std::path::Path;

use serde::{Deserialize, Serialize};
pub use trisort_format::{Camera, FrameState, NodePose};
use trisort_scene::Scene;

pub use error::{Location, PathError, Problem};

/// A path sampled into frames: what the recorder records and the player plays.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Timeline {
    /// Frames per second the path was authored or sampled at (for playback timing and for
    /// converting times; frames themselves are indexed 0, 1, …).
    pub fps: f64,
    /// One camera and set of node poses per frame; never empty.
    pub frames: Vec<FrameState>,
}

impl Timeline {
    /// The path's identity for recordings and baked files: the BLAKE3 hash of the postcard
    /// encoding of `(frames, fps)`. Equal timelines have equal hashes on every platform.
    pub fn hash(&self) -> trisort_format::Hash {
        let bytes = postcard::to_stdvec(&(&self.frames, self.fps)).expect("frames serialize");
        trisort_format::hash_bytes(&bytes)
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether there are no frames (never the case for a timeline from this crate).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }
}

/// Options of [`load`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathOptions {
    /// Sampling rate of the `gltf` path and the fps recorded for generated paths (a TOML file
    /// sets its own). Default 30.
    pub fps: f64,
}

impl Default for PathOptions {
    fn default() -> Self {
        PathOptions { fps: 30.0 }
    }
}

/// Builds the timeline of a path spec over a scene (see the [crate documentation](crate) for
/// the specs and formats). The scene supplies node names, animations, cameras and the
/// bounding box that generators and derived clip planes use.
///
/// Errors: [`PathError::Read`] and [`PathError::Syntax`] for TOML files that cannot be read or
/// parsed, [`PathError::Invalid`] for everything else, located at the file (with line and
/// column where one value is at fault), the generator spec, or the scene.
pub fn load(spec: &str, scene: &Scene, opts: &PathOptions) -> Result<Timeline, PathError> {
    let invalid = |problem| PathError::Invalid {
        at: Location::whole(spec),
        problem,
    };
    if spec == "gltf" {
        return gltf_anim::sample(scene, opts.fps, &Default::default());
    }
    if let Some(params) = spec.strip_prefix("gltf:") {
        if !Path::new(spec).exists() {
            let select = gltf_anim::parse_selection(params).map_err(invalid)?;
            return gltf_anim::sample(scene, opts.fps, &select);
        }
    }
    let (word, params) = spec.split_once(':').unwrap_or((spec, ""));
    let is_generator_word = word.len() >= 2 && word.bytes().all(|b| b.is_ascii_lowercase());
    let generator =
        matches!(word, "orbit" | "dolly") && (spec.contains(':') || !Path::new(spec).exists());
    if generator {
        gltf_anim::check_fps(opts.fps).map_err(invalid)?;
        let bounds = view::Bounds::of_scene(scene).map_err(invalid)?;
        let frames = if word == "orbit" {
            generators::parse_orbit(params).and_then(|o| o.frames(&bounds))
        } else {
            generators::parse_dolly(params).and_then(|d| d.frames(&bounds))
        }
        .map_err(invalid)?;
        return Ok(Timeline {
            fps: opts.fps,
            frames,
        });
    }
    if is_generator_word && spec.contains(':') && !Path::new(spec).exists() {
        return Err(invalid(Problem::UnknownGenerator { name: word.into() }));
    }
    keyframes::load_file(Path::new(spec), scene)
}

/// Parses TOML keyframe text (the [TOML format](#the-toml-keyframe-format)) as if read from a
/// file at `name`, which errors use for their location. [`load`] reads a file and does the
/// same; this entry point serves callers that hold the text (and the fuzzer).
pub fn load_toml_str(text: &str, name: &Path, scene: &Scene) -> Result<Timeline, PathError> {
    keyframes::parse(text, name, scene)
}

/// The demo car's default path: 48 frames at 30 fps orbiting the scene once at 15°
/// elevation (2.75 bounding radii from the centre), while the node named `DriverDoor`, if
/// there is one, opens about its local +Y axis through its origin (its hinge) to 60° and
/// closes again (frames 8–20 opening, eased; open until 28; closing until 40). The rotation's
/// sign is chosen so that the door swings away from the scene's centre, and the orbit is
/// placed so that the camera faces the door's side while it is open. Without a `DriverDoor`
/// it is just the orbit. A scene without triangles orbits a unit box at the origin.
pub fn demo_default(scene: &Scene) -> Timeline {
    demo::demo_default(scene, 30.0)
}
