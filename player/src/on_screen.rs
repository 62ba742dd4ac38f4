//! [`OnScreen`]: the player drawing into its own off-screen frame, copied to a surface (a
//! window's or a browser canvas's) by [`trisort_gpu::present::Blit`]. The window viewer and
//! the web player both present through it, so a frame on screen is the headless player's
//! frame: the same `Rgba16Float` target, resolve and one sRGB encoding at the copy.

use trisort_format::{Baked, Mode};
use trisort_gpu::present::Blit;
use trisort_gpu::{clear_colour, FrameTarget, Gpu, TargetConfig, COLOR_FORMAT, DEPTH_FORMAT};

use crate::config::{DrawPath, PlayerConfig};
use crate::error::PlayerError;
use crate::player::Player;

/// How a surface plays a baked file: sample count, mode and glass opacity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OnScreenSettings {
    /// MSAA samples of the off-screen frame (the recorded count keeps the bake exact).
    pub samples: u32,
    /// Compositing mode.
    pub mode: Mode,
    /// Glass opacity; `None` plays the recorded one.
    pub glass_opacity: Option<f32>,
    /// Surface model ([`crate::PlayerConfig::shading`]).
    pub shading: trisort_gpu::Shading,
    /// Tone map ([`crate::PlayerConfig::tone_map`]).
    pub tone_map: trisort_gpu::ToneMap,
    /// Upload block-compressed textures decoded ([`crate::PlayerConfig::decode_textures`]):
    /// what a device without the format's compression feature shows.
    pub decode_textures: bool,
}

impl OnScreenSettings {
    /// The recorded sample count and glass opacity, in `mode`.
    pub fn recorded(baked: &Baked, mode: Mode) -> OnScreenSettings {
        OnScreenSettings {
            samples: baked.settings.samples.max(1),
            mode,
            glass_opacity: None,
            shading: trisort_gpu::Shading::Pbr,
            tone_map: trisort_gpu::ToneMap::Neutral,
            decode_textures: false,
        }
    }
}

/// A player and the off-screen frame it draws into at one size, with the bind group that
/// copies that frame to a surface.
pub struct OnScreen {
    size: (u32, u32),
    player: Player,
    frame: FrameTarget,
    blit_group: wgpu::BindGroup,
    mode: Mode,
}

impl OnScreen {
    /// A player for `size` and its target: `Rgba16Float` (multisampled and resolved when
    /// `samples > 1`), `Depth32Float` in `depth` mode; the draw path and bindings chosen from
    /// the device ([`DrawPath::for_device`]). `blit` must have been made for `settings.mode`.
    pub fn new(
        gpu: &Gpu,
        baked: &Baked,
        blit: &Blit,
        size: (u32, u32),
        settings: OnScreenSettings,
    ) -> Result<OnScreen, PlayerError> {
        let depth_format = (settings.mode == Mode::Depth).then_some(DEPTH_FORMAT);
        let target = TargetConfig {
            size,
            samples: settings.samples,
            format: COLOR_FORMAT,
            depth: depth_format.is_some(),
            readback: false,
        };
        let frame = FrameTarget::new(&gpu.adapter, &gpu.device, target)?;
        let config = PlayerConfig {
            depth_format,
            sample_count: settings.samples,
            size,
            mode: settings.mode,
            glass_opacity: settings.glass_opacity,
            draw_path: DrawPath::for_device(&gpu.adapter, &gpu.device),
            shading: settings.shading,
            tone_map: settings.tone_map,
            decode_textures: settings.decode_textures,
            ..PlayerConfig::for_adapter(baked, &gpu.adapter, COLOR_FORMAT)
        };
        let player = Player::new(&gpu.device, &gpu.queue, baked, config)?;
        let blit_group = blit.bind(&gpu.device, frame.resolved_view())?;
        Ok(OnScreen {
            size,
            player,
            frame,
            blit_group,
            mode: settings.mode,
        })
    }

    /// Records frame `frame` into the off-screen target and its copy to `surface_view`
    /// (a view of the surface texture in the format `blit` was made for).
    fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        blit: &Blit,
        surface_view: &wgpu::TextureView,
        frame: u32,
    ) -> Result<(), PlayerError> {
        self.draw(enc, frame)?;
        blit.encode(enc, surface_view, &self.blit_group);
        Ok(())
    }

    /// Records frame `frame` into the off-screen target.
    fn draw(&self, enc: &mut wgpu::CommandEncoder, frame: u32) -> Result<(), PlayerError> {
        // In saturate mode the background goes under the accumulated colour at the end (the
        // blit, or the readback's conversion).
        let mut pass = self.frame.begin_pass(enc, clear_colour(self.mode), None);
        self.player.draw(&mut pass, frame)
    }

    /// Draws frame `frame` into `surface`'s texture through a view in `view_format` (the format
    /// `blit` was made for) and submits it; the caller checks for errors and presents.
    pub fn submit(
        &self,
        gpu: &Gpu,
        blit: &Blit,
        surface: &wgpu::SurfaceTexture,
        view_format: wgpu::TextureFormat,
        frame: u32,
    ) -> Result<(), PlayerError> {
        let view = surface.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(view_format),
            ..Default::default()
        });
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("trisort on-screen frame"),
            });
        self.encode(&mut enc, blit, &view, frame)?;
        gpu.queue.submit([enc.finish()]);
        Ok(())
    }

    /// Records frame `frame` into the off-screen target and the copy of the resolved frame
    /// into `buffer` (`COPY_DST`, [`FrameTarget::staging_size`] bytes of [`OnScreen::target`]):
    /// the frame as the headless player reads it back, for a caller that maps `buffer` itself
    /// (the web player's `read_frame`, which cannot block on a mapping).
    pub fn encode_readback(
        &self,
        enc: &mut wgpu::CommandEncoder,
        buffer: &wgpu::Buffer,
        frame: u32,
    ) -> Result<(), PlayerError> {
        self.draw(enc, frame)?;
        self.frame.copy_to_buffer(enc, buffer);
        Ok(())
    }

    /// The off-screen frame target.
    pub fn target(&self) -> &FrameTarget {
        &self.frame
    }

    /// The mode it draws in.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The size of the off-screen frame.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The player.
    pub fn player(&self) -> &Player {
        &self.player
    }
}
