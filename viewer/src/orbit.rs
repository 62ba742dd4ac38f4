//! The free-viewpoint window: a presorted file ([`trisort_format::Presorted`], paper 000)
//! drawn by [`trisort_reference::PresortedRenderer`] from a camera the user orbits.
//!
//! The camera circles the polyhedron's centre: drag with the left mouse button to turn it
//! (yaw and pitch), the mouse wheel or +/− to move in and out, the arrow keys to turn by 5°.
//! It starts as a turntable (a slow turn every presented frame); Space stops or restarts the
//! turn, Escape or Q quits. The distance stays outside the polyhedron and inside its reach, so
//! every position the user can reach is one the file draws sorted. The title shows the
//! camera's angles, its partition and the copies drawn.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DMat4, DVec3};
use trisort_format::{Camera, FrameState, Mode, Presorted};
use trisort_gpu::present::{configure_surface, Blit};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::{FrameTarget, Gpu, Lighting, Shading, TargetConfig, ToneMap, COLOR_FORMAT};
use trisort_reference::PresortedRenderer;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use crate::ViewerError;

type Result<T> = std::result::Result<T, ViewerError>;

/// The controls, told to the user once the window opens.
pub const ORBIT_CONTROLS: &str = "window controls: drag to orbit, wheel or +/- to zoom, \
                                  arrows turn 5 degrees, Space turntable on/off, Escape/Q quit";

/// How to show a presorted file.
#[derive(Clone, Debug)]
pub struct OrbitOptions {
    /// Window size.
    pub size: (u32, u32),
    /// MSAA samples.
    pub samples: u32,
    /// Compositing mode.
    pub mode: Mode,
    /// Glass opacity (`None`: the file's).
    pub glass_opacity: Option<f32>,
    /// Surface model.
    pub shading: Shading,
    /// Tone map.
    pub tone_map: ToneMap,
    /// Degrees the turntable turns per presented frame.
    pub turntable_degrees: f64,
    /// For tests and automation: quit after presenting this many frames.
    pub exit_after: Option<u64>,
    /// Where the half-space test runs.
    pub stage: trisort_reference::presorted::TestStage,
}

/// What an orbit session showed.
#[derive(Clone, Debug, Default)]
pub struct Orbited {
    /// The window's GPU.
    pub device: String,
    /// Frames presented.
    pub presented: u64,
    /// Partitions the camera passed through, ascending.
    pub partitions: Vec<usize>,
    /// The camera's last yaw and pitch in degrees and distance (world units).
    pub last_camera: [f64; 3],
}

/// The orbit camera.
#[derive(Clone, Copy, Debug)]
struct Orbit {
    yaw: f64,
    pitch: f64,
    distance: f64,
}

impl Orbit {
    fn eye(&self, centre: DVec3) -> DVec3 {
        let (y, p) = (self.yaw.to_radians(), self.pitch.to_radians());
        centre + DVec3::new(p.cos() * y.sin(), p.sin(), p.cos() * y.cos()) * self.distance
    }

    fn state(&self, centre: DVec3, radius: f64) -> FrameState {
        let eye = self.eye(centre);
        FrameState {
            camera: Camera {
                view: DMat4::look_at_rh(eye, centre, DVec3::Y).to_cols_array(),
                yfov: 2.0 * (radius / self.distance).clamp(0.05, 0.95).asin(),
                znear: (self.distance - radius).max(self.distance * 0.01),
                zfar: None,
            },
            poses: Vec::new(),
        }
    }
}

/// The smallest distance from the centre at which a camera in every direction is outside the
/// polyhedron (found by growing until all of 512 directions are outside), times 1.05.
fn least_distance(file: &Presorted) -> f64 {
    let centre = DVec3::from(file.polyhedron.centre);
    let mut d = file
        .polyhedron
        .faces
        .iter()
        .map(|f| f[3])
        .fold(0.0, f64::max);
    let outside_everywhere = |d: f64| {
        (0..512).all(|k| {
            let y = 1.0 - 2.0 * (k as f64 + 0.5) / 512.0;
            let r = (1.0 - y * y).sqrt();
            let phi = std::f64::consts::PI * (3.0 - 5f64.sqrt()) * k as f64;
            let dir = DVec3::new(r * phi.cos(), y, r * phi.sin());
            file.polyhedron
                .partition_of((centre + dir * d).to_array())
                .is_ok()
        })
    };
    for _ in 0..64 {
        if outside_everywhere(d) {
            break;
        }
        d *= 1.05;
    }
    d * 1.05
}

/// Opens a window on `file` (read from `path`) and lets the user orbit it until the window is
/// closed or [`OrbitOptions::exit_after`] frames were presented; `note` hears the lines for
/// the user (the controls, the device).
pub fn orbit(
    path: &Path,
    file: Presorted,
    options: OrbitOptions,
    note: &mut dyn FnMut(&str),
) -> Result<Orbited> {
    if !crate::display_named() {
        return Err(ViewerError::NoDisplay { detail: None });
    }
    let event_loop = EventLoop::new().map_err(|e| ViewerError::NoDisplay {
        detail: Some(e.to_string()),
    })?;
    let least = least_distance(&file);
    let most = file.polyhedron.reach * 0.9;
    let mut app = OrbitApp {
        path: path.to_path_buf(),
        radius: file
            .polyhedron
            .faces
            .iter()
            .map(|f| f[3])
            .fold(0.0, f64::max),
        centre: DVec3::from(file.polyhedron.centre),
        file,
        options,
        camera: Orbit {
            yaw: 30.0,
            pitch: 20.0,
            distance: (least * 1.6).min(most),
        },
        limits: (least, most.max(least)),
        turning: true,
        dragging: None,
        cursor: (0.0, 0.0),
        gfx: None,
        orbited: Orbited::default(),
        title: String::new(),
        error: None,
        note,
    };
    (app.note)(ORBIT_CONTROLS);
    let run = event_loop.run_app(&mut app);
    if let Some(e) = app.error.take() {
        return Err(e);
    }
    run.map_err(ViewerError::EventLoop)?;
    let mut out = app.orbited;
    out.partitions.sort_unstable();
    out.partitions.dedup();
    out.last_camera = [app.camera.yaw, app.camera.pitch, app.camera.distance];
    Ok(out)
}

struct OrbitGfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    view_format: wgpu::TextureFormat,
    gpu: &'static Gpu,
    blit: Blit,
    target: FrameTarget,
    blit_group: wgpu::BindGroup,
    renderer: PresortedRenderer<'static>,
}

struct OrbitApp<'n> {
    path: PathBuf,
    file: Presorted,
    options: OrbitOptions,
    centre: DVec3,
    radius: f64,
    camera: Orbit,
    /// Least and largest distance.
    limits: (f64, f64),
    turning: bool,
    /// Where a drag started and the camera then.
    dragging: Option<((f64, f64), Orbit)>,
    cursor: (f64, f64),
    gfx: Option<OrbitGfx>,
    orbited: Orbited,
    /// The window's title as last set.
    title: String,
    error: Option<ViewerError>,
    note: &'n mut dyn FnMut(&str),
}

impl OrbitApp<'_> {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: ViewerError) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        event_loop.exit();
    }

    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<OrbitGfx> {
        let name = self.path.file_name().map_or_else(
            || self.path.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        let attributes = Window::default_attributes()
            .with_title(format!("{name} · trisort"))
            .with_inner_size(PhysicalSize::new(self.options.size.0, self.options.size.1))
            .with_resizable(false);
        let window =
            Arc::new(
                event_loop
                    .create_window(attributes)
                    .map_err(|e| ViewerError::NoDisplay {
                        detail: Some(format!("opening a window: {e}")),
                    })?,
            );
        let mut desc = wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
            event_loop.owned_display_handle(),
        ));
        desc.flags = wgpu::InstanceFlags::from_build_config().with_env();
        let instance = wgpu::Instance::new(desc);
        let surface = instance
            .create_surface(window.clone())
            .map_err(ViewerError::Surface)?;
        // The renderer borrows the device for as long as the window shows it; the window is the
        // session and the process's last work, so its one device is leaked rather than made
        // self-referential.
        let gpu: &'static Gpu = Box::leak(Box::new(
            Gpu::for_surface(&instance, &surface).map_err(ViewerError::Adapter)?,
        ));
        let inner = window.inner_size();
        let size = (inner.width.max(1), inner.height.max(1));
        let setup = configure_surface(gpu, &surface, size)?;
        let mode = self.options.mode;
        let blit = Blit::new(&gpu.device, setup.view_format, mode);
        let target = FrameTarget::new(
            &gpu.adapter,
            &gpu.device,
            TargetConfig {
                size,
                samples: self.options.samples,
                format: COLOR_FORMAT,
                depth: true,
                readback: false,
            },
        )?;
        let blit_group = blit.bind(&gpu.device, target.resolved_view())?;
        let view = View {
            width: size.0,
            height: size.1,
            samples: self.options.samples,
            glass_opacity: self
                .options
                .glass_opacity
                .unwrap_or(self.file.glass_opacity),
        };
        let state = self.camera.state(self.centre, self.radius);
        let renderer = PresortedRenderer::with_stage(
            gpu,
            &self.file,
            &[state],
            view,
            Lighting {
                shading: self.options.shading,
                tone_map: self.options.tone_map,
                environment: &self.file.environment,
            },
            mode,
            self.options.stage,
        )
        .map_err(|source| ViewerError::Presorted {
            file: self.path.clone(),
            source,
        })?;
        (self.note)(&format!(
            "window {}x{} on {} ({:?}), {} sample(s), {} mode",
            size.0, size.1, gpu.info.name, gpu.info.backend, self.options.samples, mode
        ));
        self.orbited.device = gpu.info.name.clone();
        Ok(OrbitGfx {
            window,
            surface,
            config: setup.config,
            view_format: setup.view_format,
            gpu,
            blit,
            target,
            blit_group,
            renderer,
        })
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let state = self.camera.state(self.centre, self.radius);
        let Some(g) = &mut self.gfx else {
            return Ok(());
        };
        let k = g
            .renderer
            .set_camera(&self.file.geometry, 0, &state)
            .map_err(|source| ViewerError::Presorted {
                file: self.path.clone(),
                source,
            })?;
        let texture = match g.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Lost => return Err(ViewerError::SurfaceLost),
            _ => {
                g.surface.configure(&g.gpu.device, &g.config);
                g.window.request_redraw();
                return Ok(());
            }
        };
        let view = texture.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(g.view_format),
            ..Default::default()
        });
        let mut enc = g
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("trisort orbit frame"),
            });
        {
            let mut pass =
                g.target
                    .begin_pass(&mut enc, trisort_gpu::clear_colour(self.options.mode), None);
            g.renderer.draw(&mut pass, 0);
        }
        g.blit.encode(&mut enc, &view, &g.blit_group);
        g.gpu.queue.submit([enc.finish()]);
        g.window.pre_present_notify();
        g.gpu.queue.present(texture);
        self.orbited.presented += 1;
        if !self.orbited.partitions.contains(&k) {
            self.orbited.partitions.push(k);
        }
        let title = format!(
            "{} · yaw {:.0}° pitch {:.0}° · partition {k} · {} copies · trisort",
            self.path.display(),
            self.camera.yaw,
            self.camera.pitch,
            g.renderer.triangles(0)
        );
        // Only when it changes (a turntable turns 1.5° a frame; the title shows whole degrees).
        if title != self.title {
            g.window.set_title(&title);
            self.title = title;
        }
        if self
            .options
            .exit_after
            .is_some_and(|n| self.orbited.presented >= n)
        {
            event_loop.exit();
            return Ok(());
        }
        if self.turning && self.dragging.is_none() {
            self.camera.yaw = (self.camera.yaw + self.options.turntable_degrees) % 360.0;
            g.window.request_redraw();
        }
        Ok(())
    }

    fn zoom(&mut self, factor: f64) {
        self.camera.distance = (self.camera.distance * factor).clamp(self.limits.0, self.limits.1);
    }

    fn turn(&mut self, yaw: f64, pitch: f64) {
        self.camera.yaw = (self.camera.yaw + yaw).rem_euclid(360.0);
        self.camera.pitch = (self.camera.pitch + pitch).clamp(-89.0, 89.0);
    }

    fn request_redraw(&self) {
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }
}

impl ApplicationHandler for OrbitApp<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(g) => {
                g.window.request_redraw();
                self.gfx = Some(g);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::KeyboardInput {
                event:
                    KeyEvent {
                        logical_key,
                        state: ElementState::Pressed,
                        ..
                    },
                ..
            } => {
                match logical_key.as_ref() {
                    Key::Named(NamedKey::Escape) => event_loop.exit(),
                    Key::Character("q") | Key::Character("Q") => event_loop.exit(),
                    Key::Named(NamedKey::Space) => self.turning = !self.turning,
                    Key::Named(NamedKey::ArrowLeft) => self.turn(-5.0, 0.0),
                    Key::Named(NamedKey::ArrowRight) => self.turn(5.0, 0.0),
                    Key::Named(NamedKey::ArrowUp) => self.turn(0.0, 5.0),
                    Key::Named(NamedKey::ArrowDown) => self.turn(0.0, -5.0),
                    Key::Character("+") | Key::Character("=") => self.zoom(1.0 / 1.1),
                    Key::Character("-") => self.zoom(1.1),
                    _ => return,
                }
                self.request_redraw();
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((start, camera)) = self.dragging {
                    self.camera = camera;
                    self.turn(
                        -(self.cursor.0 - start.0) * 0.4,
                        (self.cursor.1 - start.1) * 0.4,
                    );
                    self.request_redraw();
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging =
                    (state == ElementState::Pressed).then_some((self.cursor, self.camera));
                self.request_redraw();
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.zoom(1.1f64.powf(-lines));
                self.request_redraw();
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw(event_loop) {
                    self.fail(event_loop, e);
                }
            }
            _ => {}
        }
    }
}
