//! `trisort play BAKED --window`: a winit viewer that plays a baked file through the real
//! [`trisort_player::Player`] into a window.
//!
//! Each frame, the player draws into an offscreen `Rgba16Float` target (multisampled at the
//! chosen sample count and resolved, with a depth buffer in `depth` mode), exactly as the
//! headless `play --out-dir` renders; a full-screen pass then copies that target to the
//! window's surface, composites the background under it in `saturate` mode and applies the
//! sRGB transfer function, quantized once by the store. The window therefore shows the pixels
//! of the PNG frames (within rounding of the GPU's `pow`), whatever format the surface has.
//!
//! The window opens at the recorded size (or `--size`) and can be resized: the player is then
//! rebuilt at the new size (its projection follows the window's aspect ratio) once the size
//! has settled, and its warnings say that the sorted order is exact only at the recorded size.
//!
//! Controls: Space play/pause; Right/Left step one frame; Home/End first/last frame; drag with
//! the left mouse button, or the keys 0–9, to scrub (0–9 jump to tenths of the range);
//! Escape or Q quit. Playback loops over the frame range at `--fps`, by default the path's
//! rate stored in the baked file (30 for a file that stores none). `--variant` plays a
//! material variant, applied again whenever the player is rebuilt. The title shows the frame
//! index.

use std::collections::HashSet;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use serde_json::json;
use trisort_format::Baked;
use trisort_player::Mode;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use crate::common::{print_json, FrameRange};

mod gfx;
use gfx::{Gfx, PlaySettings};

use super::play::ShadingArgs;

/// The error when no window can be opened.
pub const NO_DISPLAY: &str =
    "no display: --window needs X11 or Wayland; use --out-dir for PNG frames";

/// How long a new window size must stay unchanged before the player is rebuilt at it (a
/// resize by dragging sends many sizes; in between, the last frame is stretched).
const RESIZE_SETTLE: Duration = Duration::from_millis(150);

/// What `play --window` was asked for.
pub struct WindowArgs<'a> {
    /// The baked file.
    pub baked: &'a Path,
    /// Frames to play (default: all); playback loops over them.
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
    /// Surface model and tone map.
    pub shading: ShadingArgs,
    /// For tests and automation: quit after presenting this many frames.
    pub exit_after: Option<u64>,
    /// Print the summary as JSON.
    pub json: bool,
    /// Refuse a device outside the bake's raster profile (`play --strict-profile`); without
    /// it, warn.
    pub strict_profile: bool,
}

/// Whether the environment names a display server. Only Linux and the BSDs need one named;
/// elsewhere the platform always has a window system.
fn display_named() -> bool {
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

/// Opens the viewer and plays until the window is closed (or `exit_after` frames were
/// presented). Errors with [`NO_DISPLAY`] when there is no display, before reading the file.
pub fn run(a: WindowArgs<'_>) -> Result<ExitCode> {
    if !display_named() {
        bail!("{NO_DISPLAY}");
    }
    if let Some(fps) = a.fps.filter(|f| !(f.is_finite() && *f > 0.0)) {
        bail!("--fps must be a positive number, not {fps}");
    }
    let baked = trisort_player::open_baked(a.baked)?;
    // Checked once here (the file's structure check holds its fps finite and positive).
    let fps = a.fps.or(baked.fps).unwrap_or(30.0);
    baked
        .geometry
        .variant_materials(a.variant.as_deref())
        .with_context(|| format!("playing {}", a.baked.display()))?;
    let n = baked.frames.len() as u32;
    let range = match &a.frames {
        Some(r) => r.resolve(n)?,
        None if n == 0 => bail!("{}: the baked file has no frames", a.baked.display()),
        None => 0..n,
    };
    let event_loop = EventLoop::new().map_err(|e| anyhow!("{NO_DISPLAY} ({e})"))?;
    let name = a.baked.file_name().map_or_else(
        || a.baked.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let mut viewer = Viewer {
        size: a
            .size
            .unwrap_or((baked.settings.width.max(1), baked.settings.height.max(1))),
        samples: a.samples.unwrap_or(baked.settings.samples).max(1),
        mode: a.mode,
        glass_opacity: a.glass_opacity,
        shading: a.shading,
        period: Duration::from_secs_f64(1.0 / fps),
        variant: a.variant,
        exit_after: a.exit_after,
        strict_profile: a.strict_profile,
        path: a.baked.to_path_buf(),
        name,
        baked,
        frame: range.start,
        range,
        playing: true,
        next_tick: Instant::now(),
        cursor_x: 0.0,
        dragging: false,
        resized_at: None,
        presented: 0,
        title: String::new(),
        printed_warnings: HashSet::new(),
        gfx: None,
        error: None,
    };
    eprintln!(
        "trisort: window controls: Space play/pause, Right/Left step, Home/End first/last, \
         drag or 0-9 to scrub, Escape/Q quit"
    );
    let run = event_loop.run_app(&mut viewer);
    if let Some(e) = viewer.error.take() {
        return Err(e);
    }
    run.context("window event loop")?;
    let device = viewer
        .gfx
        .as_ref()
        .map_or_else(String::new, |g| g.gpu.info.name.clone());
    if a.json {
        print_json(&json!({
            "device": device,
            "mode": viewer.mode.name(),
            "variant": viewer.variant,
            "fps": fps,
            "presented_frames": viewer.presented,
            "last_frame": viewer.frame,
        }));
    } else {
        println!(
            "presented {} frames ({} mode) on {device}; last frame {}",
            viewer.presented,
            viewer.mode.name(),
            viewer.frame
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// Playback state and, once the window exists, its GPU objects.
struct Viewer {
    /// Initial window size.
    size: (u32, u32),
    samples: u32,
    mode: Mode,
    glass_opacity: Option<f32>,
    shading: ShadingArgs,
    period: Duration,
    /// Material variant, applied to every player built.
    variant: Option<String>,
    exit_after: Option<u64>,
    strict_profile: bool,
    path: PathBuf,
    name: String,
    baked: Baked,
    /// The frame shown (an index into the file's frames, inside `range`).
    frame: u32,
    range: Range<u32>,
    playing: bool,
    /// When playback next advances.
    next_tick: Instant,
    cursor_x: f64,
    dragging: bool,
    /// When the window was last resized, until the player is rebuilt at the new size.
    resized_at: Option<Instant>,
    presented: u64,
    title: String,
    printed_warnings: HashSet<String>,
    gfx: Option<Gfx>,
    error: Option<anyhow::Error>,
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(gfx) => {
                gfx.window.request_redraw();
                self.gfx = Some(gfx);
                self.next_tick = Instant::now() + self.period;
                self.update_title();
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(g) = &mut self.gfx {
                    if size.width > 0 && size.height > 0 {
                        if g.resize_surface((size.width, size.height)) {
                            self.resized_at = Some(Instant::now());
                        }
                        g.window.request_redraw();
                    }
                }
            }
            WindowEvent::KeyboardInput {
                event:
                    KeyEvent {
                        logical_key,
                        state: ElementState::Pressed,
                        ..
                    },
                ..
            } => self.key(event_loop, &logical_key),
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor_x = position.x;
                if self.dragging {
                    self.scrub_to_cursor();
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = state == ElementState::Pressed;
                if self.dragging {
                    self.scrub_to_cursor();
                } else {
                    self.next_tick = Instant::now() + self.period;
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw(event_loop) {
                    self.fail(event_loop, e);
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(g) = &self.gfx else { return };
        let surface_size = (g.surface_config.width, g.surface_config.height);
        let targets_size = g.targets.size();
        let now = Instant::now();
        let mut wake: Option<Instant> = None;
        if let Some(t) = self.resized_at {
            if now >= t + RESIZE_SETTLE {
                self.resized_at = None;
                let size = surface_size;
                if size != targets_size {
                    if let Err(e) = self.rebuild(size) {
                        return self.fail(event_loop, e);
                    }
                }
                self.request_redraw();
            } else {
                wake = Some(t + RESIZE_SETTLE);
            }
        }
        if self.playing && !self.dragging {
            if now >= self.next_tick {
                self.frame = if self.frame + 1 >= self.range.end {
                    self.range.start
                } else {
                    self.frame + 1
                };
                self.next_tick += self.period;
                if self.next_tick <= now {
                    // Drawing is slower than the frame rate: do not try to catch up.
                    self.next_tick = now + self.period;
                }
                self.update_title();
                self.request_redraw();
            }
            wake = Some(wake.map_or(self.next_tick, |w| w.min(self.next_tick)));
        }
        event_loop.set_control_flow(match wake {
            Some(t) => ControlFlow::WaitUntil(t),
            None => ControlFlow::Wait,
        });
    }
}

impl Viewer {
    /// Records the first error and stops the event loop.
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        event_loop.exit();
    }

    fn request_redraw(&self) {
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }

    /// Shows `frame` (clamped to the range) and redraws.
    fn show(&mut self, frame: u32) {
        let frame = frame.clamp(self.range.start, self.range.end - 1);
        if frame != self.frame {
            self.frame = frame;
            self.request_redraw();
        }
        self.update_title();
    }

    /// The frame at a fraction `t` ∈ [0, 1] of the range.
    fn frame_at(&self, t: f64) -> u32 {
        let len = self.range.len() as f64;
        let k = (t.clamp(0.0, 1.0) * len).floor().min(len - 1.0);
        self.range.start + k as u32
    }

    fn scrub_to_cursor(&mut self) {
        let width = self
            .gfx
            .as_ref()
            .map_or(1, |g| g.surface_config.width.max(1)) as f64;
        self.show(self.frame_at(self.cursor_x / width));
    }

    fn key(&mut self, event_loop: &ActiveEventLoop, key: &Key) {
        match key {
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Named(NamedKey::Space) => {
                self.playing = !self.playing;
                self.next_tick = Instant::now() + self.period;
                self.update_title();
            }
            Key::Named(NamedKey::ArrowRight) => {
                self.playing = false;
                self.show(self.frame.saturating_add(1));
            }
            Key::Named(NamedKey::ArrowLeft) => {
                self.playing = false;
                self.show(self.frame.saturating_sub(1));
            }
            Key::Named(NamedKey::Home) => self.show(self.range.start),
            Key::Named(NamedKey::End) => self.show(self.range.end - 1),
            Key::Character(c) => match c.as_str() {
                "q" | "Q" => event_loop.exit(),
                d => {
                    if let Some(k) = d.parse::<u32>().ok().filter(|&k| k <= 9) {
                        self.show(self.frame_at(k as f64 / 10.0));
                    }
                }
            },
            _ => {}
        }
    }

    fn update_title(&mut self) {
        let Some(g) = &self.gfx else { return };
        let title = format!(
            "{} · frame {} of {}..{} · {} · {} · trisort",
            self.name,
            self.frame,
            self.range.start,
            self.range.end - 1,
            if self.playing { "playing" } else { "paused" },
            self.mode.name(),
        );
        if title != self.title {
            g.window.set_title(&title);
            self.title = title;
        }
    }

    /// Creates the window, a surface-compatible device, the blit pipeline and the player.
    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<Gfx> {
        let attributes = Window::default_attributes()
            .with_title(format!("{} · trisort", self.name))
            .with_inner_size(PhysicalSize::new(self.size.0, self.size.1))
            .with_resizable(true);
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| anyhow!("{NO_DISPLAY} (opening a window: {e})"))?,
        );
        let play = PlaySettings {
            samples: self.samples,
            mode: self.mode,
            glass_opacity: self.glass_opacity,
            shading: self.shading.shading,
            tone_map: self.shading.tonemap,
        };
        let gfx = Gfx::open(window, event_loop.owned_display_handle(), &self.baked, play)
            .with_context(|| format!("playing {}", self.path.display()))?;
        // The window's device against the bake's raster profile: a warning, or a refusal.
        crate::cmd::play::check_profile(
            &gfx.gpu,
            &self.baked,
            self.samples,
            [0.0, 0.0],
            &self.path,
            self.strict_profile,
        )?;
        (gfx.targets.player()).set_variant(&gfx.gpu.queue, self.variant.as_deref())?;
        self.print_warnings(gfx.targets.player().warnings());
        Ok(gfx)
    }

    /// Rebuilds the player and its targets at `size` (after a resize).
    fn rebuild(&mut self, size: (u32, u32)) -> Result<()> {
        let g = self.gfx.as_mut().expect("rebuild after open");
        g.rebuild(&self.baked, size)?;
        (g.targets.player()).set_variant(&g.gpu.queue, self.variant.as_deref())?;
        let warnings = g.targets.player().warnings().to_vec();
        self.print_warnings(&warnings);
        Ok(())
    }

    /// Prints the player's warnings that were not printed before.
    fn print_warnings(&mut self, warnings: &[String]) {
        for w in warnings {
            if self.printed_warnings.insert(w.clone()) {
                eprintln!("trisort: warning: {w}");
            }
        }
    }

    /// Draws the current frame and presents it.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let Some(g) = &mut self.gfx else {
            return Ok(());
        };
        if g.present(self.frame)? {
            self.presented += 1;
            if self.exit_after.is_some_and(|n| self.presented >= n) {
                event_loop.exit();
            }
        }
        Ok(())
    }
}
