//! The viewer's GPU side: the window's surface and device, the player and its offscreen
//! target ([`trisort_player::OnScreen`]), and the blit that presents the target
//! ([`trisort_gpu::present`]). The event loop (`app.rs`) decides what to show; this draws it.

use std::sync::Arc;

use trisort_format::Baked;
use trisort_gpu::present::{configure_surface, Blit};
use trisort_gpu::{Gpu, UncapturedError};
use trisort_player::{OnScreen, OnScreenSettings};
use winit::event_loop::OwnedDisplayHandle;
use winit::window::Window;

use crate::ViewerError;

type Result<T> = std::result::Result<T, ViewerError>;

/// How the viewer plays: sample count, mode and glass opacity (`None`: as recorded).
pub(crate) type PlaySettings = OnScreenSettings;

/// The window, its surface and device, the copy-to-surface pipeline and the player's targets.
pub(crate) struct Gfx {
    pub window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    pub gpu: Gpu,
    pub surface_config: wgpu::SurfaceConfiguration,
    /// Format the blit writes through (the surface format without its sRGB suffix).
    view_format: wgpu::TextureFormat,
    blit: Blit,
    play: PlaySettings,
    /// The first wgpu error no error scope caught.
    uncaptured: UncapturedError,
    pub targets: OnScreen,
}

impl Gfx {
    /// A surface for `window`, a device that can present to it, the blit and the player at the
    /// window's size.
    pub fn open(
        window: Arc<Window>,
        display: OwnedDisplayHandle,
        baked: &Baked,
        play: PlaySettings,
    ) -> Result<Gfx> {
        let mut desc =
            wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(display));
        desc.flags = wgpu::InstanceFlags::from_build_config().with_env();
        let instance = wgpu::Instance::new(desc);
        let surface = instance
            .create_surface(window.clone())
            .map_err(ViewerError::Surface)?;
        let gpu = Gpu::for_surface(&instance, &surface).map_err(ViewerError::Adapter)?;
        let uncaptured = UncapturedError::install(&gpu.device);
        let inner = window.inner_size();
        let (width, height) = (inner.width.max(1), inner.height.max(1));
        let setup = configure_surface(&gpu, &surface, (width, height))?;
        let blit = Blit::new(&gpu.device, setup.view_format, play.mode);
        let targets = OnScreen::new(&gpu, baked, &blit, (width, height), play)?;
        Ok(Gfx {
            window,
            surface,
            gpu,
            surface_config: setup.config,
            view_format: setup.view_format,
            blit,
            play,
            uncaptured,
            targets,
        })
    }

    /// Reconfigures the surface at `size`; whether the player's targets now differ in size
    /// (the caller rebuilds them once the size has settled).
    pub fn resize_surface(&mut self, size: (u32, u32)) -> bool {
        self.surface_config.width = size.0;
        self.surface_config.height = size.1;
        self.surface
            .configure(&self.gpu.device, &self.surface_config);
        size != self.targets.size()
    }

    /// Rebuilds the player and its targets at `size`.
    pub fn rebuild(&mut self, baked: &Baked, size: (u32, u32)) -> Result<()> {
        // Free the old targets before allocating new ones.
        self.gpu
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(ViewerError::Poll)?;
        self.targets = OnScreen::new(&self.gpu, baked, &self.blit, size, self.play)?;
        Ok(())
    }

    /// Draws `frame` and presents it; `false` when nothing was presented (minimized,
    /// occluded, or the surface must be reconfigured first).
    pub fn present(&mut self, frame: u32) -> Result<bool> {
        if self.window.inner_size().width == 0 || self.window.inner_size().height == 0 {
            return Ok(false); // minimized
        }
        let surface_texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) => t,
            wgpu::CurrentSurfaceTexture::Suboptimal(t) => {
                // Present this one; reconfigure for the next.
                self.surface
                    .configure(&self.gpu.device, &self.surface_config);
                t
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Outdated => {
                self.surface
                    .configure(&self.gpu.device, &self.surface_config);
                self.window.request_redraw();
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Lost => return Err(ViewerError::SurfaceLost),
            wgpu::CurrentSurfaceTexture::Validation => {
                let e = self.uncaptured.take().unwrap_or_default();
                return Err(ViewerError::Wgpu(e));
            }
        };
        self.targets.submit(
            &self.gpu,
            &self.blit,
            &surface_texture,
            self.view_format,
            frame,
        )?;
        if let Some(e) = self.uncaptured.take() {
            return Err(ViewerError::Wgpu(e));
        }
        self.window.pre_present_notify();
        self.gpu.queue.present(surface_texture);
        Ok(true)
    }

    /// The line that tells the user what the window plays on: size, device and backend,
    /// surface format and the format written through, samples and mode.
    pub fn describe(&self) -> String {
        format!(
            "window {}x{} on {} ({:?}), surface {:?} written as {:?}, {} sample(s), {} mode",
            self.surface_config.width,
            self.surface_config.height,
            self.gpu.info.name,
            self.gpu.info.backend,
            self.surface_config.format,
            self.view_format,
            self.play.samples,
            self.play.mode
        )
    }
}
