//! `trisort play BAKED --window`: a winit viewer that plays a baked file through the real
//! [`Player`] into a window.
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
//! Escape or Q quit. Playback loops over the frame range at `--fps` (baked files store no
//! frame rate; 30 by default). The title shows the frame index.

use std::collections::HashSet;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use serde_json::json;
use trisort_format::Baked;
use trisort_player::headless::{COLOR_FORMAT, DEPTH_FORMAT};
use trisort_player::{clear_colour, FrameTarget, Mode, Player, PlayerConfig, BACKGROUND};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use crate::common::{print_json, FrameRange};

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
    /// Playback rate in frames per second.
    pub fps: f64,
    /// For tests and automation: quit after presenting this many frames.
    pub exit_after: Option<u64>,
    /// Print the summary as JSON.
    pub json: bool,
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
    if !(a.fps.is_finite() && a.fps > 0.0) {
        bail!("--fps must be a positive number, not {}", a.fps);
    }
    let baked = trisort_player::open_baked(a.baked)?;
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
        period: Duration::from_secs_f64(1.0 / a.fps),
        exit_after: a.exit_after,
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
        .map_or_else(String::new, |g| g.adapter_name.clone());
    if a.json {
        print_json(&json!({
            "device": device,
            "mode": viewer.mode.name(),
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
    period: Duration,
    exit_after: Option<u64>,
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

/// The window, its surface and device, the copy-to-surface pipeline and the player's targets.
struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    adapter: wgpu::Adapter,
    adapter_name: String,
    device: wgpu::Device,
    queue: wgpu::Queue,
    surface_config: wgpu::SurfaceConfiguration,
    /// Format the blit writes through (the surface format without its sRGB suffix).
    view_format: wgpu::TextureFormat,
    blit_layout: wgpu::BindGroupLayout,
    blit_pipeline: wgpu::RenderPipeline,
    /// The first wgpu error no error scope caught.
    uncaptured: Arc<Mutex<Option<String>>>,
    targets: Targets,
}

/// A player and the offscreen targets it draws into, at one size.
struct Targets {
    size: (u32, u32),
    player: Player,
    frame: FrameTarget,
    blit_group: wgpu::BindGroup,
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
                        g.surface_config.width = size.width;
                        g.surface_config.height = size.height;
                        g.surface.configure(&g.device, &g.surface_config);
                        if (size.width, size.height) != g.targets.size {
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
        let targets_size = g.targets.size;
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
        let mut desc = wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
            event_loop.owned_display_handle(),
        ));
        desc.flags = wgpu::InstanceFlags::from_build_config().with_env();
        let instance = wgpu::Instance::new(desc);
        let surface = instance
            .create_surface(window.clone())
            .context("creating a wgpu surface for the window")?;
        let adapter =
            pollster::block_on(
                instance.request_adapter(&wgpu::RequestAdapterOptions {
                    power_preference: wgpu::PowerPreference::from_env()
                        .unwrap_or(wgpu::PowerPreference::HighPerformance),
                    force_fallback_adapter: false,
                    compatible_surface: Some(&surface),
                    apply_limit_buckets: false,
                }),
            )
            .map_err(|e| {
                anyhow!(
                    "no GPU adapter can present to this window ({e}); on a machine without a GPU \
                 install Mesa's lavapipe: apt-get install mesa-vulkan-drivers"
                )
            })?;
        let info = adapter.get_info();
        let adapter_name = info.name.clone();
        let features = adapter.features() & trisort_gpu::wanted_features();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("trisort window"),
            required_features: features,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .with_context(|| format!("creating a GPU device on {adapter_name}"))?;
        let uncaptured = Arc::new(Mutex::new(None::<String>));
        {
            let slot = uncaptured.clone();
            device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
                let mut slot = slot.lock().unwrap_or_else(|p| p.into_inner());
                slot.get_or_insert_with(|| e.to_string());
            }));
        }

        let caps = surface.get_capabilities(&adapter);
        let inner = window.inner_size();
        let (width, height) = (inner.width.max(1), inner.height.max(1));
        let mut surface_config = surface
            .get_default_config(&adapter, width, height)
            .ok_or_else(|| anyhow!("{adapter_name} cannot present to this window"))?;
        // The blit writes sRGB-encoded values through a linear (non-sRGB) view, so the
        // encoding and the rounding are the ones `play --out-dir` applies on the CPU, not the
        // hardware's approximation (lavapipe's sRGB stores differ from the exact transfer
        // function by one step on most pixels).
        let mut view_format = surface_config.format.remove_srgb_suffix();
        if view_format != surface_config.format {
            surface_config.view_formats = vec![view_format];
        }
        if caps.present_modes.contains(&wgpu::PresentMode::Fifo) {
            surface_config.present_mode = wgpu::PresentMode::Fifo;
        }
        if caps.alpha_modes.contains(&wgpu::CompositeAlphaMode::Opaque) {
            surface_config.alpha_mode = wgpu::CompositeAlphaMode::Opaque;
        }
        let configure = |config: &wgpu::SurfaceConfiguration| {
            let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
            surface.configure(&device, config);
            pollster::block_on(scope.pop())
        };
        if let Some(e) = configure(&surface_config) {
            if surface_config.view_formats.is_empty() {
                bail!("configuring the window's surface: {e}");
            }
            // Some backends (GL) offer no other view of the surface: write through its own
            // sRGB format and let the hardware encode.
            surface_config.view_formats.clear();
            view_format = surface_config.format;
            if let Some(e) = configure(&surface_config) {
                bail!("configuring the window's surface: {e}");
            }
        }

        let (blit_layout, blit_pipeline) = blit_pipeline(&device, view_format, self.mode);
        let targets = Targets::new(
            &adapter,
            &device,
            &queue,
            &self.baked,
            &blit_layout,
            (width, height),
            self.samples,
            self.mode,
            self.glass_opacity,
        )
        .with_context(|| format!("playing {}", self.path.display()))?;
        eprintln!(
            "trisort: window {width}x{height} on {} ({:?}), surface {:?} written as {view_format:?}, \
             {} sample(s), {} mode",
            adapter_name, info.backend, surface_config.format, self.samples, self.mode
        );
        let gfx = Gfx {
            window,
            surface,
            adapter,
            adapter_name,
            device,
            queue,
            surface_config,
            view_format,
            blit_layout,
            blit_pipeline,
            uncaptured,
            targets,
        };
        self.print_warnings(gfx.targets.player.warnings());
        Ok(gfx)
    }

    /// Rebuilds the player and its targets at `size` (after a resize).
    fn rebuild(&mut self, size: (u32, u32)) -> Result<()> {
        let g = self.gfx.as_mut().expect("rebuild after open");
        // Free the old targets before allocating new ones.
        g.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| anyhow!("waiting for the GPU: {e}"))?;
        g.targets = Targets::new(
            &g.adapter,
            &g.device,
            &g.queue,
            &self.baked,
            &g.blit_layout,
            size,
            self.samples,
            self.mode,
            self.glass_opacity,
        )?;
        let warnings = g.targets.player.warnings().to_vec();
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
        if g.window.inner_size().width == 0 || g.window.inner_size().height == 0 {
            return Ok(()); // minimized
        }
        let surface_texture = match g.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) => t,
            wgpu::CurrentSurfaceTexture::Suboptimal(t) => {
                // Present this one; reconfigure for the next.
                g.surface.configure(&g.device, &g.surface_config);
                t
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Outdated => {
                g.surface.configure(&g.device, &g.surface_config);
                g.window.request_redraw();
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Lost => bail!("the window's surface was lost"),
            wgpu::CurrentSurfaceTexture::Validation => {
                bail!("wgpu: {}", g.take_uncaptured().unwrap_or_default())
            }
        };
        let surface_view = surface_texture
            .texture
            .create_view(&wgpu::TextureViewDescriptor {
                format: Some(g.view_format),
                ..Default::default()
            });
        let t = &g.targets;
        let mut enc = g
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("trisort window frame"),
            });
        {
            // In saturate mode the background goes under the accumulated colour in the blit.
            let mut pass = t.frame.begin_pass(&mut enc, clear_colour(self.mode), None);
            t.player.draw(&mut pass, self.frame)?;
        }
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("trisort window blit"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &surface_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            });
            pass.set_pipeline(&g.blit_pipeline);
            pass.set_bind_group(0, &t.blit_group, &[]);
            pass.draw(0..3, 0..1);
        }
        g.queue.submit([enc.finish()]);
        if let Some(e) = g.take_uncaptured() {
            bail!("wgpu: {e}");
        }
        g.window.pre_present_notify();
        g.queue.present(surface_texture);
        self.presented += 1;
        if self.exit_after.is_some_and(|n| self.presented >= n) {
            event_loop.exit();
        }
        Ok(())
    }
}

impl Gfx {
    fn take_uncaptured(&self) -> Option<String> {
        self.uncaptured
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .take()
    }
}

impl Targets {
    /// A player for `size` and its targets: `Rgba16Float` (multisampled and resolved when
    /// `samples > 1`), `Depth32Float` in `depth` mode.
    #[allow(clippy::too_many_arguments)]
    fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        baked: &Baked,
        blit_layout: &wgpu::BindGroupLayout,
        size: (u32, u32),
        samples: u32,
        mode: Mode,
        glass_opacity: Option<f32>,
    ) -> Result<Targets> {
        let depth_format = (mode == Mode::Depth).then_some(DEPTH_FORMAT);
        let frame = FrameTarget::new(
            adapter,
            device,
            size,
            samples,
            COLOR_FORMAT,
            depth_format.is_some(),
            false,
        )
        .map_err(|e| anyhow::anyhow!("{e} (--samples)"))?;
        let config = PlayerConfig {
            depth_format,
            sample_count: samples,
            size,
            mode,
            glass_opacity,
            ..PlayerConfig::for_adapter(baked, adapter, COLOR_FORMAT)
        };
        let player = Player::new(device, queue, baked, config)?;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let blit_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("trisort window blit"),
            layout: blit_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(frame.resolved_view()),
            }],
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            bail!("wgpu: {e}");
        }
        Ok(Targets {
            size,
            player,
            frame,
            blit_group,
        })
    }
}

/// The copy from the player's linear `Rgba16Float` frame to the surface: one triangle over the
/// viewport, each pixel reading the texel under it (nearest; stretched while a resize
/// settles). `saturate` mode composites the background under the accumulated colour
/// (`rgb + (1 − a)·background`, as the headless player does); the output is opaque and
/// sRGB-encoded here (written through a non-sRGB view), except on float surfaces.
const BLIT_WGSL: &str = r"
@group(0) @binding(0) var frame: texture_2d<f32>;

struct VsOut {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs_blit(@builtin(vertex_index) i: u32) -> VsOut {
    // (0, 0), (2, 0), (0, 2) in uv: a triangle covering the viewport, uv (0, 0) top left.
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var out: VsOut;
    out.position = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    out.uv = uv;
    return out;
}

fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

@fragment
fn fs_blit(in: VsOut) -> @location(0) vec4<f32> {
    let dims = textureDimensions(frame);
    let texel = min(vec2<u32>(in.uv * vec2<f32>(dims)), dims - vec2<u32>(1u));
    let c = textureLoad(frame, texel, 0);
    var rgb = c.rgb;
    if UNDER {
        rgb = rgb + (1.0 - c.a) * BACKGROUND;
    }
    rgb = clamp(rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    if ENCODE_SRGB {
        rgb = srgb_encode(rgb);
    }
    return vec4<f32>(rgb, 1.0);
}
";

fn blit_pipeline(
    device: &wgpu::Device,
    view_format: wgpu::TextureFormat,
    mode: Mode,
) -> (wgpu::BindGroupLayout, wgpu::RenderPipeline) {
    // Float surfaces (scRGB) take linear values; the others get sRGB-encoded values.
    let encode = !view_format.is_srgb()
        && !matches!(
            view_format,
            wgpu::TextureFormat::Rgba16Float | wgpu::TextureFormat::Rgba32Float
        );
    let source = format!(
        "const UNDER: bool = {};\nconst ENCODE_SRGB: bool = {encode};\n\
         const BACKGROUND: vec3<f32> = vec3<f32>({:?}, {:?}, {:?});\n{BLIT_WGSL}",
        mode == Mode::Saturate,
        BACKGROUND[0],
        BACKGROUND[1],
        BACKGROUND[2],
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("trisort window blit"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("trisort window blit"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        }],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("trisort window blit"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("trisort window blit"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_blit"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_blit"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format: view_format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    });
    (layout, pipeline)
}
