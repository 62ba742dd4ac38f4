//! `trisort play BAKED --window`: the arguments of the viewer ([`trisort_viewer`], which
//! documents the controls) and the printing of what it played.

use std::path::Path;
use std::process::ExitCode;

use anyhow::{anyhow, Result};
use serde_json::json;
use trisort_format::Baked;
use trisort_gpu::Gpu;
use trisort_player::Mode;
use trisort_viewer::{BoxError, Session, ViewerError, ViewerHost, ViewerOptions};

use super::play::ShadingArgs;
use crate::common::{print_json, FrameRange};

/// The error when no window can be opened.
pub const NO_DISPLAY: &str =
    "no display: --window needs X11 or Wayland; use --out-dir for PNG frames";

/// What `play --window` was asked for.
pub struct WindowArgs<'a> {
    /// The baked file.
    pub baked: &'a Path,
    /// Frames to play (default: all; with `clip`, counted from the clip's first frame);
    /// playback loops over them.
    pub frames: Option<FrameRange>,
    /// Initial window size (default: the recorded size).
    pub size: Option<(u32, u32)>,
    /// MSAA samples (default: the recorded count).
    pub samples: Option<u32>,
    /// Compositing mode.
    pub mode: Mode,
    /// Glass opacity (default: the recorded one).
    pub glass_opacity: Option<f32>,
    /// Playback rate in frames per second (default: the file's, else 30).
    pub fps: Option<f64>,
    /// Material variant to play (default: the file's default materials).
    pub variant: Option<String>,
    /// Clip to start at (default: the file's frames in order).
    pub clip: Option<String>,
    /// Surface model and tone map.
    pub shading: ShadingArgs,
    /// For tests and automation: quit after presenting this many frames.
    pub exit_after: Option<u64>,
    /// Print the summary as JSON.
    pub json: bool,
    /// Refuse a device outside the bake's raster profile (`play --strict-profile`); without
    /// it, warn.
    pub strict_profile: bool,
    /// Upload block-compressed textures decoded (`play --decode-textures`).
    pub decode_textures: bool,
}

/// The viewer's lines go to stderr; its device is checked against the bake's raster profile
/// as headless `play` checks its own.
struct Host<'a> {
    baked: &'a Path,
    strict_profile: bool,
}

impl ViewerHost for Host<'_> {
    fn check_device(&mut self, gpu: &Gpu, baked: &Baked, samples: u32) -> Result<(), BoxError> {
        let (file, strict) = (self.baked, self.strict_profile);
        super::play::check_profile(gpu, baked, samples, [0.0, 0.0], file, strict)?;
        Ok(())
    }

    fn note(&mut self, line: &str) {
        eprintln!("trisort: {line}");
    }

    fn warning(&mut self, warning: &str) {
        eprintln!("trisort: warning: {warning}");
    }
}

/// The viewer's error in the CLI's words (the flags to use instead).
pub fn cli_error(e: ViewerError) -> anyhow::Error {
    match e {
        ViewerError::NoDisplay { detail: None } => anyhow!("{NO_DISPLAY}"),
        ViewerError::NoDisplay { detail: Some(d) } => anyhow!("{NO_DISPLAY} ({d})"),
        ViewerError::Fps(fps) => anyhow!("--fps must be a positive number, not {fps}"),
        e => e.into(),
    }
}

/// Opens the viewer and plays until the window is closed (or `exit_after` frames were
/// presented). Errors with [`NO_DISPLAY`] when there is no display, before reading the file.
pub fn run(a: WindowArgs<'_>) -> Result<ExitCode> {
    let options = ViewerOptions {
        size: a.size,
        samples: a.samples,
        mode: a.mode,
        glass_opacity: a.glass_opacity,
        shading: a.shading.shading,
        tone_map: a.shading.tonemap,
        fps: a.fps,
        variant: a.variant,
        clip: a.clip,
        exit_after: a.exit_after,
        decode_textures: a.decode_textures,
    };
    let session = Session::open(a.baked, options).map_err(cli_error)?;
    // --frames counts from the first frame of the clip started at (of the file without one).
    let within = session.clip_frames();
    let frames = a.frames.map(|r| {
        r.resolve(within.len() as u32)
            .map(|r| r.start + within.start..r.end + within.start)
    });
    let mut host = Host {
        baked: a.baked,
        strict_profile: a.strict_profile,
    };
    let played = session
        .play(frames.transpose()?, &mut host)
        .map_err(cli_error)?;
    if a.json {
        print_json(&json!({
            "device": played.device,
            "mode": played.mode.name(),
            "variant": played.variant,
            "fps": played.fps,
            "clip": played.clip,
            "presented_frames": played.presented,
            "last_frame": played.last_frame,
            "texture_upload": {
                "srgb": played.texture_upload[0],
                "linear": played.texture_upload[1],
            },
        }));
    } else {
        println!(
            "presented {} frames ({} mode) on {}; last frame {}{}",
            played.presented,
            played.mode.name(),
            played.device,
            played.last_frame,
            played
                .clip
                .map_or(String::new(), |c| format!(" of clip {c}"))
        );
    }
    Ok(ExitCode::SUCCESS)
}
