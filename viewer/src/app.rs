//! The viewer's event loop: playback state, input and timing. What to show is decided here;
//! [`crate::gfx`] draws it.

use std::collections::HashSet;
use std::ops::Range;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use trisort_format::{Baked, Clip};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, Modifiers, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use crate::gfx::{Gfx, PlaySettings};
use crate::{Played, Session, ViewerError, ViewerHost};

type Result<T> = std::result::Result<T, ViewerError>;

/// How long a new window size must stay unchanged before the player is rebuilt at it (a
/// resize by dragging sends many sizes; in between, the last frame is stretched).
const RESIZE_SETTLE: Duration = Duration::from_millis(150);

/// The controls, told to the user once the event loop exists.
const CONTROLS: &str = "window controls: Space play/pause, Right/Left step, Home/End \
                        first/last, drag or 0-9 to scrub, Tab/C next clip (Shift: previous), \
                        F1-F9 clip 1-9, Escape/Q quit";

/// The rate a clip plays at: the one asked for, else the clip's, else the file's, else 30
/// (`clip` `None`: the file's frames in order).
pub(crate) fn rate(asked: Option<f64>, clip: Option<&Clip>, baked: &Baked) -> f64 {
    asked
        .or(clip.and_then(|c| c.fps))
        .or(baked.fps)
        .unwrap_or(30.0)
}

/// Runs the event loop of `session` over `range` until the window closes.
pub(crate) fn run(
    session: Session,
    range: Range<u32>,
    host: &mut dyn ViewerHost,
) -> Result<Played> {
    let event_loop = EventLoop::new().map_err(|e| ViewerError::NoDisplay {
        detail: Some(e.to_string()),
    })?;
    let Session {
        path,
        baked,
        options,
        fps,
        clip,
    } = session;
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let mut viewer = Viewer {
        size: options
            .size
            .unwrap_or((baked.settings.width.max(1), baked.settings.height.max(1))),
        play: PlaySettings {
            samples: options.samples.unwrap_or(baked.settings.samples).max(1),
            mode: options.mode,
            glass_opacity: options.glass_opacity,
            shading: options.shading,
            tone_map: options.tone_map,
            decode_textures: options.decode_textures,
        },
        period: Duration::from_secs_f64(1.0 / fps),
        fps,
        asked_fps: options.fps,
        clip,
        shift: false,
        variant: options.variant,
        exit_after: options.exit_after,
        path,
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
        host,
    };
    viewer.host.note(CONTROLS);
    let run = event_loop.run_app(&mut viewer);
    if let Some(e) = viewer.error.take() {
        return Err(e);
    }
    run.map_err(ViewerError::EventLoop)?;
    Ok(Played {
        device: viewer
            .gfx
            .as_ref()
            .map_or_else(String::new, |g| g.gpu.info.name.clone()),
        mode: viewer.play.mode,
        clip: viewer.clip.map(|k| viewer.baked.clips[k].name.clone()),
        last_frame: viewer.frame - viewer.clip.map_or(0, |k| viewer.baked.clips[k].first),
        variant: viewer.variant,
        fps: viewer.fps,
        presented: viewer.presented,
        texture_upload: viewer.gfx.as_ref().map_or_else(Default::default, |g| {
            (g.targets.player().texture_uploads())
                .each_ref()
                .map(|u| u.name())
        }),
    })
}

/// Playback state and, once the window exists, its GPU objects.
struct Viewer<'h> {
    /// Initial window size.
    size: (u32, u32),
    /// Samples, mode, glass opacity and shading of every player built.
    play: PlaySettings,
    period: Duration,
    /// The rate playback runs at (`1 / period`).
    fps: f64,
    /// The rate asked for (`None`: each clip's).
    asked_fps: Option<f64>,
    /// The clip selected (an index into the file's clips; `None`: the file's frames).
    clip: Option<usize>,
    /// Whether a Shift key is held (Shift+Tab selects the previous clip).
    shift: bool,
    /// Material variant, applied to every player built.
    variant: Option<String>,
    exit_after: Option<u64>,
    path: PathBuf,
    name: String,
    baked: Baked,
    /// The frame shown (an index into the file's frames, inside `range`, which is inside the
    /// selected clip's frames).
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
    error: Option<ViewerError>,
    /// Checks the device and hears the lines for the user.
    host: &'h mut dyn ViewerHost,
}

impl ApplicationHandler for Viewer<'_> {
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
            WindowEvent::ModifiersChanged(m) => self.shift = modifiers_shift(&m),
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

impl Viewer<'_> {
    /// Records the first error and stops the event loop.
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: ViewerError) {
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
            Key::Named(NamedKey::Tab) => self.step_clip(!self.shift),
            Key::Named(NamedKey::Home) => self.show(self.range.start),
            Key::Named(NamedKey::End) => self.show(self.range.end - 1),
            Key::Named(f) => {
                let clips = self.baked.clips.len();
                if let Some(k) = function_key(f).filter(|&k| k < clips) {
                    self.select_clip(k);
                }
            }
            Key::Character(c) => match c.as_str() {
                "q" | "Q" => event_loop.exit(),
                "c" => self.step_clip(true),
                "C" => self.step_clip(false),
                d => {
                    if let Some(k) = d.parse::<u32>().ok().filter(|&k| k <= 9) {
                        self.show(self.frame_at(k as f64 / 10.0));
                    }
                }
            },
            _ => {}
        }
    }

    /// Selects the next clip (`forward`) or the previous one, wrapping around; from the
    /// file's frames (no clip selected), the first or the last.
    fn step_clip(&mut self, forward: bool) {
        let n = self.baked.clips.len();
        let k = match (self.clip, forward) {
            (None, true) => 0,
            (None, false) => n - 1,
            (Some(k), true) => (k + 1) % n,
            (Some(k), false) => (k + n - 1) % n,
        };
        self.select_clip(k);
    }

    /// Plays clip `k` from its first frame, looping over its frames at its rate (or the one
    /// asked for).
    fn select_clip(&mut self, k: usize) {
        let clip = &self.baked.clips[k];
        self.clip = Some(k);
        self.range = clip.frames();
        self.fps = rate(self.asked_fps, Some(clip), &self.baked);
        self.period = Duration::from_secs_f64(1.0 / self.fps);
        self.next_tick = Instant::now() + self.period;
        self.frame = self.range.start;
        self.request_redraw();
        self.update_title();
    }

    fn update_title(&mut self) {
        let Some(g) = &self.gfx else { return };
        let clips = &self.baked.clips;
        // Within a clip, its name and the frame counted from its first; otherwise the file's
        // frame, and the clip it belongs to where the file has several.
        let (clip, base) = match self.clip {
            Some(k) => (
                format!(" · clip {} ({} of {})", clips[k].name, k + 1, clips.len()),
                clips[k].first,
            ),
            None if clips.len() > 1 => {
                let name = (self.baked.clip_of_frame(self.frame)).map_or("?", |(_, c)| &c.name);
                (format!(" · clip {name}"), 0)
            }
            None => (String::new(), 0),
        };
        let title = format!(
            "{}{clip} · frame {} of {}..{} · {} · {} · trisort",
            self.name,
            self.frame - base,
            self.range.start - base,
            self.range.end - 1 - base,
            if self.playing { "playing" } else { "paused" },
            self.play.mode.name(),
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
        let window =
            Arc::new(
                event_loop
                    .create_window(attributes)
                    .map_err(|e| ViewerError::NoDisplay {
                        detail: Some(format!("opening a window: {e}")),
                    })?,
            );
        let gfx = Gfx::open(
            window,
            event_loop.owned_display_handle(),
            &self.baked,
            self.play,
        )
        .map_err(|e| ViewerError::Open {
            file: self.path.clone(),
            source: Box::new(e),
        })?;
        self.host.note(&gfx.describe());
        // The window's device against the bake's raster profile: a warning, or a refusal.
        (self.host)
            .check_device(&gfx.gpu, &self.baked, self.play.samples)
            .map_err(ViewerError::Device)?;
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

    /// Passes on the player's warnings that were not passed on before.
    fn print_warnings(&mut self, warnings: &[String]) {
        for w in warnings {
            if self.printed_warnings.insert(w.clone()) {
                self.host.warning(w);
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

/// The function keys F1–F9, which select clips 1–9.
const CLIP_KEYS: [NamedKey; 9] = [
    NamedKey::F1,
    NamedKey::F2,
    NamedKey::F3,
    NamedKey::F4,
    NamedKey::F5,
    NamedKey::F6,
    NamedKey::F7,
    NamedKey::F8,
    NamedKey::F9,
];

/// The clip (counted from 0) a function key F1–F9 selects.
fn function_key(key: &NamedKey) -> Option<usize> {
    CLIP_KEYS.iter().position(|k| k == key)
}

/// Whether `m` holds a Shift key.
fn modifiers_shift(m: &Modifiers) -> bool {
    m.state().shift_key()
}
