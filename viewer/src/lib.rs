//! The interactive viewer: a winit window that plays a baked file through the real
//! [`trisort_player::Player`].
//!
//! Each frame, the player draws into an offscreen `Rgba16Float` target (multisampled at the
//! chosen sample count and resolved, with a depth buffer in `depth` mode), exactly as headless
//! playback renders; a full-screen pass then copies that target to the window's surface,
//! composites the background under it in `saturate` mode and applies the sRGB transfer
//! function, quantized once by the store. The window therefore shows the pixels of the PNG
//! frames (within rounding of the GPU's `pow`), whatever format the surface has.
//!
//! The window opens at the recorded size (or [`ViewerOptions::size`]) and can be resized: the
//! player is then rebuilt at the new size (its projection follows the window's aspect ratio)
//! once the size has settled, and its warnings say that the sorted order is exact only at the
//! recorded size.
//!
//! Controls: Space play/pause; Right/Left step one frame; Home/End first/last frame; drag with
//! the left mouse button, or the keys 0–9, to scrub (0–9 jump to tenths of the range);
//! Escape or Q quit. Playback loops over the frame range at [`ViewerOptions::fps`], by default
//! the path's rate stored in the baked file (30 for a file that stores none). A material
//! variant ([`ViewerOptions::variant`]) is applied again whenever the player is rebuilt. The
//! title shows the frame index.
//!
//! Clips (the camera paths of a bundle, [`trisort_format::Clip`]): Tab or C selects the next
//! clip, Shift+Tab or Shift+C the previous one, F1–F9 clip 1–9. Playback then loops over the
//! clip's frames at its rate ([`ViewerOptions::fps`] where given), and the title shows the
//! clip's name and the frame within it. [`ViewerOptions::clip`] starts at a clip; without
//! it the viewer plays the file's frames in order, the title naming the clip of the frame
//! shown when the file has several.
//!
//! Use: [`Session::open`] checks the display and reads the file, [`Session::play`] runs the
//! event loop until the window is closed and returns what was [`Played`]. The library prints
//! nothing: what the user should read (the controls, the device, the player's warnings) goes
//! to the caller's [`ViewerHost`], which also decides whether the window's device may play the
//! bake.
#![warn(missing_docs)]

mod app;
mod error;
mod gfx;
mod orbit;

use std::ops::Range;
use std::path::{Path, PathBuf};

pub use error::{BoxError, ViewerError};
pub use orbit::{orbit, OrbitOptions, Orbited, ORBIT_CONTROLS};
use trisort_format::{Baked, Mode};
use trisort_gpu::{Gpu, Shading, ToneMap};

/// How to play: window size, sample count, mode, shading, rate and material variant.
#[derive(Clone, Debug)]
pub struct ViewerOptions {
    /// Initial window size (`None`: the recorded size).
    pub size: Option<(u32, u32)>,
    /// MSAA samples (`None`: the recorded count).
    pub samples: Option<u32>,
    /// Compositing mode.
    pub mode: Mode,
    /// Glass opacity (`None`: the recorded one).
    pub glass_opacity: Option<f32>,
    /// Surface model.
    pub shading: Shading,
    /// Tone map of the `pbr` surface model.
    pub tone_map: ToneMap,
    /// Playback rate in frames per second (`None`: the file's, else 30); must be positive.
    pub fps: Option<f64>,
    /// Material variant to play (`None`: the file's default materials).
    pub variant: Option<String>,
    /// Clip to start at (`None`: the file's frames, in order); the frame range given to
    /// [`Session::play`] must then lie inside it ([`Session::clip_frames`]).
    pub clip: Option<String>,
    /// For tests and automation: quit after presenting this many frames.
    pub exit_after: Option<u64>,
    /// Upload block-compressed textures decoded, as a device without their compression
    /// feature does (`play --decode-textures`).
    pub decode_textures: bool,
}

/// What the caller of [`Session::play`] provides: the check of the window's device, and where
/// the lines for the user go.
pub trait ViewerHost {
    /// Checks the window's device against the bake's raster profile before anything plays; an
    /// error refuses to play (and is returned as [`ViewerError::Device`]).
    fn check_device(&mut self, gpu: &Gpu, baked: &Baked, samples: u32) -> Result<(), BoxError>;
    /// A line for the user: the controls, once the event loop exists, then the window's size,
    /// device and surface format.
    fn note(&mut self, line: &str);
    /// A warning of the player (each distinct text once per session), e.g. that the window's
    /// size differs from the recorded one.
    fn warning(&mut self, warning: &str);
}

/// What a session played, once the window closed.
#[derive(Clone, Debug)]
pub struct Played {
    /// The window's GPU (empty if the window never opened).
    pub device: String,
    /// Compositing mode.
    pub mode: Mode,
    /// The material variant played.
    pub variant: Option<String>,
    /// Playback rate in frames per second (the last one played at, which follows the clip
    /// where [`ViewerOptions::fps`] was not given).
    pub fps: f64,
    /// Frames presented to the window.
    pub presented: u64,
    /// The clip selected last (`None`: none was; the file's frames were played in order).
    pub clip: Option<String>,
    /// The frame shown last: counted from the first frame of [`Played::clip`], or the file's
    /// frame where no clip was selected.
    pub last_frame: u32,
    /// How the sRGB and the linear material texture arrays were uploaded, as `play --json`
    /// names them (`ArrayUpload::name` of trisort-gpu; empty if the window never opened).
    pub texture_upload: [String; 2],
}

/// A baked file opened for the viewer, with its options checked; not yet a window.
pub struct Session {
    path: PathBuf,
    baked: Baked,
    options: ViewerOptions,
    fps: f64,
    /// The clip to start at (its index in the file's clips).
    clip: Option<usize>,
}

/// Whether the environment names a display server. Only Linux and the BSDs need one named;
/// elsewhere the platform always has a window system.
pub fn display_named() -> bool {
    if cfg!(all(
        unix,
        not(any(
            target_os = "macos",
            target_os = "ios",
            target_os = "android"
        ))
    )) {
        ["DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"]
            .iter()
            .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
    } else {
        true
    }
}

impl Session {
    /// Checks that a display is named ([`ViewerError::NoDisplay`], before reading the file, so
    /// a headless machine gets that error first) and that the rate is positive, then reads
    /// `path` and checks that it has the material variant and the clip asked for.
    pub fn open(path: &Path, options: ViewerOptions) -> Result<Session, ViewerError> {
        if !display_named() {
            return Err(ViewerError::NoDisplay { detail: None });
        }
        if let Some(fps) = options.fps.filter(|f| !(f.is_finite() && *f > 0.0)) {
            return Err(ViewerError::Fps(fps));
        }
        let baked = trisort_player::open_baked(path)?;
        let clip = (options.clip.as_deref())
            .map(|name| trisort_player::clip_index(&baked.clips, name))
            .transpose()
            .map_err(|source| ViewerError::Clip {
                file: path.to_path_buf(),
                source,
            })?;
        // Checked once here (the file's structure check holds its fps finite and positive).
        let fps = app::rate(options.fps, clip.map(|k| &baked.clips[k]), &baked);
        baked
            .geometry
            .variant_materials(options.variant.as_deref())
            .map_err(|source| ViewerError::Variant {
                file: path.to_path_buf(),
                source,
            })?;
        Ok(Session {
            path: path.to_path_buf(),
            baked,
            options,
            fps,
            clip,
        })
    }

    /// Frames in the file (for resolving the range to play).
    pub fn frame_count(&self) -> u32 {
        self.baked.frames.len() as u32
    }

    /// The file's frames playback starts in: those of [`ViewerOptions::clip`], or all of
    /// them. A frame range for [`Session::play`] must lie inside.
    pub fn clip_frames(&self) -> Range<u32> {
        match self.clip {
            Some(k) => self.baked.clips[k].frames(),
            None => 0..self.frame_count(),
        }
    }

    /// Opens the window and plays `frames` (the file's frame indices, inside
    /// [`Session::clip_frames`]; `None`: all of those; playback loops over them) until the
    /// window is closed or [`ViewerOptions::exit_after`] frames were presented.
    pub fn play(
        self,
        frames: Option<Range<u32>>,
        host: &mut dyn ViewerHost,
    ) -> Result<Played, ViewerError> {
        let n = self.frame_count();
        let within = self.clip_frames();
        let range = match frames {
            Some(r) if r.start >= r.end || r.start < within.start || r.end > within.end => {
                return Err(ViewerError::FrameRange {
                    start: r.start,
                    end: r.end,
                    frames: n,
                })
            }
            Some(r) => r,
            None if n == 0 => return Err(ViewerError::NoFrames { file: self.path }),
            None => within,
        };
        app::run(self, range, host)
    }
}
