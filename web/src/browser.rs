//! The wasm side: [`WebPlayer`], exported to the page with wasm-bindgen.

use std::cell::{Cell, RefCell};
use std::path::Path;
use std::rc::Rc;

use trisort_format::{Baked, DeviceLimits, Mode};
use trisort_gpu::present::{configure_surface, Blit};
use trisort_gpu::{Gpu, UncapturedError};
use trisort_player::{OnScreen, OnScreenSettings};
use wasm_bindgen::prelude::*;

use crate::{clip_figures, BrowserBackend, ErrorKind, FrameFigures};

/// Reports a Rust panic on the browser console instead of an opaque "unreachable".
#[wasm_bindgen(start)]
fn start() {
    std::panic::set_hook(Box::new(|info| {
        web_sys::console::error_1(&format!("trisort: {info}").into());
    }));
}

/// A baked file playing on a canvas: the device, the canvas's surface, and the player
/// drawing into its off-screen frame, copied to the canvas each [`WebPlayer::render`].
#[wasm_bindgen]
pub struct WebPlayer {
    gpu: Gpu,
    surface: wgpu::Surface<'static>,
    surface_config: wgpu::SurfaceConfiguration,
    view_format: wgpu::TextureFormat,
    blit: Blit,
    on_screen: OnScreen,
    backend: &'static str,
    fps: Option<f64>,
    /// The selected clip, an index into the player's clips ([`WebPlayer::set_clip`]).
    clip: usize,
    robust: trisort_format::Robust,
    warnings: Vec<String>,
    uncaptured: UncapturedError,
    /// The buffer [`WebPlayer::read_frame`] maps, made on its first call.
    readback: Option<wgpu::Buffer>,
    /// Whether a [`WebPlayer::read_frame`] is waiting for its mapping.
    reading: Rc<Cell<bool>>,
}

/// Longest a [`WebPlayer::read_frame`] waits for its mapping, in milliseconds.
const READ_TIMEOUT_MS: f64 = 60_000.0;

/// Resolves on the browser's next timer tick (`setTimeout(…, 1)`; at once where there is no
/// `setTimeout`).
async fn timer_tick() {
    let tick = js_sys::Promise::new(&mut |resolve, _| {
        let global = js_sys::global();
        let set_timeout = js_sys::Reflect::get(&global, &JsValue::from_str("setTimeout"))
            .ok()
            .and_then(|f| f.dyn_into::<js_sys::Function>().ok());
        match set_timeout {
            Some(f) => drop(f.call2(&global, &resolve, &JsValue::from(1))),
            None => drop(resolve.call0(&JsValue::NULL)),
        }
    });
    let _ = wasm_bindgen_futures::JsFuture::from(tick).await;
}

/// A JavaScript `Error` with `message` and a `kind` property naming `kind` ([`ErrorKind`]):
/// what the npm package's wrapper maps to its error classes without reading the message.
fn js_error(kind: ErrorKind, message: impl std::fmt::Display) -> JsValue {
    let e = js_sys::Error::new(&message.to_string());
    // Setting a property on a fresh Error object cannot fail.
    let _ = js_sys::Reflect::set(&e, &JsValue::from_str("kind"), &kind.name().into());
    e.into()
}

fn format_error(e: impl std::fmt::Display) -> JsValue {
    js_error(ErrorKind::Format, e)
}

fn device_error(e: impl std::fmt::Display) -> JsValue {
    js_error(ErrorKind::Device, e)
}

fn option_error(e: impl std::fmt::Display) -> JsValue {
    js_error(ErrorKind::Option, e)
}

#[wasm_bindgen]
impl WebPlayer {
    /// Decodes `bytes` (a baked file; `name` names it in errors), sizes `canvas` to the
    /// recorded size, and opens a device on `backend` (`auto`, `webgpu`, `webgl2`) that draws
    /// into it in `mode` (`blend`, `depth`, `saturate`) at the recorded sample count.
    ///
    /// With `zbuffer`, it plays the file's z-buffer twin instead
    /// ([`trisort_player::self_check::zbuffer_baked`]: each frame's window, then every
    /// triangle of the file): in `depth` mode the twin's frame equals the file's frame
    /// wherever no triangle the frame leaves out is nearest, so the page's self-check counts
    /// the pixels where the two differ: the holes on this browser's rasterizer.
    ///
    /// `shading` (`pbr`, the default, or `basic`) and `tonemap` (`neutral`, the default, or
    /// `aces`) light it as `trisort play --shading --tonemap` does.
    ///
    /// Every error this type throws is a JavaScript `Error` with a `kind` property
    /// ([`ErrorKind`]): `format` for bytes that are not a readable baked file, `device` for
    /// the browser's graphics, `option` for an unknown option value, clip or variant.
    #[allow(
        clippy::too_many_arguments,
        reason = "the signature is the page's JavaScript API (`WebPlayer.open`)"
    )]
    pub async fn open(
        canvas: web_sys::HtmlCanvasElement,
        bytes: Vec<u8>,
        name: String,
        backend: String,
        mode: String,
        zbuffer: bool,
        shading: Option<String>,
        tonemap: Option<String>,
    ) -> Result<WebPlayer, JsValue> {
        let backend: BrowserBackend = backend.parse().map_err(option_error)?;
        let shading: trisort_gpu::Shading =
            (shading.as_deref().unwrap_or("pbr").parse()).map_err(option_error)?;
        let tone_map: trisort_gpu::ToneMap =
            (tonemap.as_deref().unwrap_or("neutral").parse()).map_err(option_error)?;
        let mode: Mode = mode.parse().map_err(option_error)?;
        let mut baked: Baked =
            trisort_player::baked_from_bytes(&bytes, Path::new(&name)).map_err(format_error)?;
        drop(bytes);
        if zbuffer {
            baked = trisort_player::self_check::zbuffer_baked(&baked);
        }
        let (width, height) = (baked.settings.width.max(1), baked.settings.height.max(1));
        canvas.set_width(width);
        canvas.set_height(height);

        let (instance, backend_name) = instance_for(backend).await?;
        let surface = instance
            .create_surface(wgpu::SurfaceTarget::Canvas(canvas))
            .map_err(|e| device_error(format!("{backend_name} surface for the canvas: {e}")))?;
        let gpu = Gpu::open_async(
            &instance,
            Some(&surface),
            "trisort web",
            DeviceLimits::Adapter,
        )
        .await
        .map_err(device_error)?;
        let uncaptured = UncapturedError::install(&gpu.device);
        let setup = configure_surface(&gpu, &surface, (width, height)).map_err(device_error)?;
        let blit = Blit::new(&gpu.device, setup.view_format, mode);
        let settings = OnScreenSettings {
            shading,
            tone_map,
            ..OnScreenSettings::recorded(&baked, mode)
        };
        let on_screen =
            OnScreen::new(&gpu, &baked, &blit, (width, height), settings).map_err(device_error)?;
        let warnings = on_screen.player().warnings().to_vec();
        let fps = baked.fps;
        let robust = baked.settings.robust;
        Ok(WebPlayer {
            gpu,
            surface,
            surface_config: setup.config,
            view_format: setup.view_format,
            blit,
            on_screen,
            backend: backend_name,
            fps,
            clip: 0,
            robust,
            warnings,
            uncaptured,
            readback: None,
            reading: Rc::new(Cell::new(false)),
        })
    }

    /// Draws frame `frame` and presents it on the canvas. The canvas holds the frame until the
    /// page's task ends, so a caller can copy it (`drawImage`) right after this returns.
    pub fn render(&mut self, frame: u32) -> Result<(), JsValue> {
        let texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface
                    .configure(&self.gpu.device, &self.surface_config);
                match self.surface.get_current_texture() {
                    wgpu::CurrentSurfaceTexture::Success(t)
                    | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
                    _ => return Err(device_error("the canvas's surface is unavailable")),
                }
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                return Err(device_error(format!(
                    "wgpu: {}",
                    self.uncaptured.take().unwrap_or_default()
                )))
            }
        };
        self.on_screen
            .submit(&self.gpu, &self.blit, &texture, self.view_format, frame)
            .map_err(device_error)?;
        if let Some(e) = self.uncaptured.take() {
            return Err(device_error(format!("wgpu: {e}")));
        }
        self.gpu.queue.present(texture);
        Ok(())
    }

    /// Draws frame `frame` off-screen and resolves to its pixels, read back through a mapped
    /// buffer: a `Uint8Array` of `width × height` RGBA texels, rows top to bottom, 8-bit sRGB
    /// with alpha 255, converted from the frame as the native player converts it for its PNGs
    /// (`trisort play`). The canvas is untouched, so this works where a canvas cannot be read
    /// back (a WebGPU canvas after its frame was presented, or a headless browser that lost
    /// the canvas's device), on both backends. One read at a time: a second call before the
    /// first settles is refused.
    pub fn read_frame(&mut self, frame: u32) -> Result<js_sys::Promise, JsValue> {
        if self.reading.get() {
            return Err(option_error(
                "read_frame: the previous read_frame has not settled yet (await it first)",
            ));
        }
        let target = self.on_screen.target();
        let (layout, size, mode) = (
            target.layout(),
            target.staging_size(),
            self.on_screen.mode(),
        );
        let buffer = self
            .readback
            .get_or_insert_with(|| {
                self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("trisort web readback"),
                    size,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            })
            .clone();
        let mut enc = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("trisort web readback"),
            });
        self.on_screen
            .encode_readback(&mut enc, &buffer, frame)
            .map_err(device_error)?;
        self.gpu.queue.submit([enc.finish()]);
        if let Some(e) = self.uncaptured.take() {
            return Err(device_error(format!("wgpu: {e}")));
        }
        self.reading.set(true);
        let reading = self.reading.clone();
        let uncaptured = self.uncaptured.clone();
        // The mapping's outcome, set by its callback: WebGPU's mapAsync settles after control
        // returns to the browser, WebGL2's (emulated) one on a poll that finds the GPU done.
        let outcome = Rc::new(RefCell::new(None));
        let slot = outcome.clone();
        buffer
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |r| *slot.borrow_mut() = Some(r));
        let device = self.gpu.device.clone();
        Ok(wasm_bindgen_futures::future_to_promise(async move {
            // WebGL2 cannot block, so poll between timer ticks until the mapping settles.
            let deadline = js_sys::Date::now() + READ_TIMEOUT_MS;
            while outcome.borrow().is_none() && js_sys::Date::now() < deadline {
                let _ = device.poll(wgpu::PollType::Poll);
                if outcome.borrow().is_none() {
                    timer_tick().await;
                }
            }
            let settled = outcome.borrow_mut().take();
            reading.set(false);
            match settled {
                None => Err(device_error(
                    "read_frame: the frame's mapping did not settle within a minute",
                )),
                Some(Err(e)) => Err(device_error(match uncaptured.take() {
                    // WebGPU reports a bad copy later, on the device: name it.
                    Some(first) => format!("read_frame: wgpu: {first}"),
                    None => format!("read_frame: mapping the frame failed: {e}"),
                })),
                Some(Ok(())) => {
                    let bytes = buffer
                        .slice(..)
                        .get_mapped_range()
                        .map_err(|e| device_error(format!("read_frame: {e}")))?
                        .to_vec();
                    buffer.unmap();
                    Ok(js_sys::Uint8Array::from(&layout.rgba8(&bytes, mode)[..]).into())
                }
            }
        }))
    }

    /// Frames in the file.
    pub fn frame_count(&self) -> u32 {
        self.on_screen.player().frame_count()
    }

    /// The canvas width (the recorded width).
    pub fn width(&self) -> u32 {
        self.on_screen.size().0
    }

    /// The canvas height (the recorded height).
    pub fn height(&self) -> u32 {
        self.on_screen.size().1
    }

    /// Triangles frame `frame` draws (0 beyond the last frame).
    pub fn frame_triangles(&self, frame: u32) -> f64 {
        if frame >= self.frame_count() {
            return 0.0;
        }
        self.on_screen.player().frame_triangles(frame) as f64
    }

    /// Draw calls frame `frame` issues on this path (ranges of its window).
    pub fn frame_draws(&self, frame: u32) -> u32 {
        if frame >= self.frame_count() {
            return 0;
        }
        self.on_screen.player().frame_commands(frame).len() as u32
    }

    /// The figures line the page shows for `frame`, drawn in `ms` milliseconds (with the
    /// clip and the frame's place in it when the file has several clips).
    pub fn figures(&self, frame: u32, ms: f64) -> String {
        let mut line = FrameFigures {
            frame,
            frames: self.frame_count(),
            triangles: self.frame_triangles(frame) as u64,
            draws: self.frame_draws(frame),
            ms,
        }
        .to_string();
        if self.clips_of().len() > 1 {
            let c = self.selected();
            line += &clip_figures(&c.name, frame, c.first, c.count);
        }
        line
    }

    /// The names of the file's clips (its camera paths), in frame order: at least one
    /// (`main` for a file of one unnamed path).
    pub fn clips(&self) -> Vec<String> {
        self.clips_of().iter().map(|c| c.name.clone()).collect()
    }

    /// The file's frames clip `name` spans, `[first, count]`: frames `first .. first +
    /// count` (frame numbers are the file's everywhere). An unknown name is an error listing
    /// the clips.
    pub fn clip_range(&self, name: &str) -> Result<Vec<u32>, JsValue> {
        let c = self.named(name)?;
        Ok(vec![c.first, c.count])
    }

    /// The frame rate clip `name` was baked at (`undefined` where the file does not say).
    pub fn clip_fps(&self, name: &str) -> Result<Option<f64>, JsValue> {
        Ok(self.named(name)?.fps)
    }

    /// Selects the clip named `name`: the page then plays, scrubs and steps within its
    /// frames ([`WebPlayer::clip_first`], [`WebPlayer::clip_length`]) at its rate. An unknown
    /// name is an error listing the clips, and the selection stays.
    pub fn set_clip(&mut self, name: &str) -> Result<(), JsValue> {
        self.clip = trisort_player::clip_index(self.clips_of(), name).map_err(option_error)?;
        Ok(())
    }

    /// The selected clip's name (the first clip until [`WebPlayer::set_clip`]).
    pub fn clip(&self) -> String {
        self.selected().name.clone()
    }

    /// The selected clip's first frame, among the file's frames.
    pub fn clip_first(&self) -> u32 {
        self.selected().first
    }

    /// The selected clip's number of frames.
    pub fn clip_length(&self) -> u32 {
        self.selected().count
    }

    /// The frame after (`step` 1) or before (`step` −1) `frame` in the selected clip, looping
    /// within it ([`crate::step_in_clip`]).
    pub fn step_frame(&self, frame: u32, step: i32) -> u32 {
        let c = self.selected();
        crate::step_in_clip(frame, c.first, c.count, step)
    }

    /// The path's frame rate as baked (`undefined` for files that do not say); a clip's own is
    /// [`WebPlayer::clip_fps`].
    pub fn fps(&self) -> Option<f64> {
        self.fps
    }

    /// The material variants of the file (KHR_materials_variants), including those this bake
    /// refuses ([`WebPlayer::set_variant`] says why).
    pub fn variants(&self) -> Vec<String> {
        self.on_screen.player().variant_names()
    }

    /// Plays the materials of variant `name` from the next frame on (an empty name: the
    /// default materials). Refused, with the reason, for a variant that would change what is
    /// visible (alpha mode, opacity, transmission, sidedness); the materials stay as they were.
    pub fn set_variant(&self, name: &str) -> Result<(), JsValue> {
        let name = (!name.is_empty()).then_some(name);
        self.on_screen
            .player()
            .set_variant(&self.gpu.queue, name)
            .map_err(option_error)
    }

    /// The raster profile the file was baked for (`exact`, `conformant`, `snap4`, `browser`):
    /// what it assumes about the rasterizer that plays it. A browser without a GPU
    /// (SwiftShader) needs `browser`, which `web/build.sh` bakes with.
    pub fn raster_profile(&self) -> String {
        self.robust.profile.name.to_string()
    }

    /// The profile's tolerance in pixels (besides the snapping of corners).
    pub fn raster_tolerance(&self) -> f32 {
        self.robust.tolerance
    }

    /// The profile's sub-pixel bits, `[least, most]`.
    pub fn raster_subpixel_bits(&self) -> Vec<u32> {
        let p = &self.robust.profile;
        vec![p.subpixel_bits_min, p.subpixel_bits_max]
    }

    /// Where the profile's rasterizer takes a sample's depth: `sample` or `pixel`.
    pub fn raster_depth_at(&self) -> String {
        self.robust.profile.depth_at.to_string()
    }

    /// `WebGPU` or `WebGL2`.
    pub fn backend(&self) -> String {
        self.backend.to_string()
    }

    /// The adapter, as the browser names it.
    pub fn adapter(&self) -> String {
        self.gpu.describe()
    }

    /// How draws are issued: `multi-draw-indirect` or `direct` (one `draw_indexed` per range).
    pub fn draw_path(&self) -> String {
        self.on_screen
            .player()
            .config()
            .draw_path
            .name()
            .to_string()
    }

    /// How node matrices and materials are bound: `storage` or `textures`.
    pub fn bindings(&self) -> String {
        self.on_screen.player().bindings().name().to_string()
    }

    /// What makes this playback inexact (another device than the recording's, …).
    pub fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }
}

impl WebPlayer {
    fn clips_of(&self) -> &[trisort_format::Clip] {
        self.on_screen.player().clips()
    }

    fn selected(&self) -> &trisort_format::Clip {
        &self.clips_of()[self.clip]
    }

    fn named(&self, name: &str) -> Result<&trisort_format::Clip, JsValue> {
        let k = trisort_player::clip_index(self.clips_of(), name).map_err(option_error)?;
        Ok(&self.clips_of()[k])
    }
}

/// The instance for `backend`, and the API's name. `Auto` asks the browser for a WebGPU
/// adapter first and falls back to WebGL2 without touching the canvas.
async fn instance_for(backend: BrowserBackend) -> Result<(wgpu::Instance, &'static str), JsValue> {
    let webgl2 = || {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::GL;
        (wgpu::Instance::new(desc), "WebGL2")
    };
    let webgpu = || {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::BROWSER_WEBGPU;
        (wgpu::Instance::new(desc), "WebGPU")
    };
    match backend {
        BrowserBackend::WebGl2 => Ok(webgl2()),
        BrowserBackend::WebGpu if wgpu::util::is_browser_webgpu_supported().await => Ok(webgpu()),
        BrowserBackend::WebGpu => Err(device_error(
            "this browser offers no WebGPU adapter (backend webgl2 needs none)",
        )),
        BrowserBackend::Auto if wgpu::util::is_browser_webgpu_supported().await => Ok(webgpu()),
        BrowserBackend::Auto => Ok(webgl2()),
    }
}
