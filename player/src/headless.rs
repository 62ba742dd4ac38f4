//! Headless rendering for the CLI (`trisort play`) and the tests: frames drawn by a [`Player`]
//! into an `Rgba16Float` target (MSAA resolved to one sample), read back and quantized once to
//! 8-bit sRGB, the way the exact reference renders: one rounding, at the end, so the player's
//! frames and the reference's are quantized alike and differ only where their colours do.

use trisort_format::Baked;
use trisort_gpu::{Gpu, Shading, ToneMap};

use crate::config::{DrawPath, PlayerConfig};
use crate::error::PlayerError;
use crate::player::Player;
use trisort_format::Mode;
use trisort_gpu::{
    clear_colour, map_read_all, poll_ready, FrameTarget, GpuTimer, TargetConfig, COLOR_FORMAT,
    DEPTH_FORMAT,
};

/// One rendered frame.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderedFrame {
    /// Frame index.
    pub frame: u32,
    /// `width × height` pixels, RGBA8, sRGB-encoded, rows top to bottom, alpha 255.
    pub rgba8: Vec<u8>,
    /// GPU time of the frame's render pass in milliseconds, where the device has
    /// `Features::TIMESTAMP_QUERY`.
    pub gpu_ms: Option<f64>,
}

/// How headless frames are rendered.
#[derive(Clone, Debug, PartialEq)]
pub struct HeadlessConfig {
    /// Image size (width, height).
    pub size: (u32, u32),
    /// MSAA samples.
    pub samples: u32,
    /// Compositing mode.
    pub mode: Mode,
    /// Glass opacity; `None` plays the recorded one.
    pub glass_opacity: Option<f32>,
    /// Draw path; `None` picks it from the adapter ([`DrawPath::for_adapter`]).
    pub draw_path: Option<DrawPath>,
    /// Use 32-bit indices even where 16 bits fit.
    pub force_u32: bool,
    /// Surface model ([`PlayerConfig::shading`]).
    pub shading: Shading,
    /// Tone map ([`PlayerConfig::tone_map`]).
    pub tone_map: ToneMap,
    /// Upload block-compressed textures decoded ([`PlayerConfig::decode_textures`]).
    pub decode_textures: bool,
}

impl HeadlessConfig {
    /// The recorded size and sample count, `blend` mode, recorded glass opacity.
    pub fn recorded(baked: &Baked) -> HeadlessConfig {
        HeadlessConfig {
            size: (baked.settings.width, baked.settings.height),
            samples: baked.settings.samples.max(1),
            mode: Mode::Blend,
            glass_opacity: None,
            draw_path: None,
            force_u32: false,
            shading: Shading::Pbr,
            tone_map: ToneMap::Neutral,
            decode_textures: false,
        }
    }
}

/// Renders `frames` of `baked` headless at `size` with `samples` MSAA samples in `mode`
/// (`glass_opacity` `None`: as recorded). See [`HeadlessRenderer`].
pub fn render_frames(
    gpu: &Gpu,
    baked: &Baked,
    frames: &[u32],
    size: (u32, u32),
    samples: u32,
    mode: Mode,
    glass_opacity: Option<f32>,
) -> Result<Vec<RenderedFrame>, PlayerError> {
    let config = HeadlessConfig {
        size,
        samples,
        mode,
        glass_opacity,
        ..HeadlessConfig::recorded(baked)
    };
    let renderer = HeadlessRenderer::new(gpu, baked, &config)?;
    frames.iter().map(|&f| renderer.render(f)).collect()
}

/// A [`Player`] with its own offscreen targets: renders one frame per call, each with a single
/// command encoder (render pass, MSAA resolve, timestamp resolve, copy to a staging buffer).
pub struct HeadlessRenderer<'g> {
    gpu: &'g Gpu,
    player: Player,
    mode: Mode,
    target: FrameTarget,
    timer: Option<GpuTimer>,
}

impl<'g> HeadlessRenderer<'g> {
    /// Creates the player and the targets. Errors where the adapter cannot multisample the
    /// targets at `config.samples`, or as [`Player::new`].
    pub fn new(
        gpu: &'g Gpu,
        baked: &Baked,
        config: &HeadlessConfig,
    ) -> Result<HeadlessRenderer<'g>, PlayerError> {
        let (w, h) = (config.size.0.max(1), config.size.1.max(1));
        let samples = config.samples.max(1);
        // Before the player: a sample count the adapter lacks is the clearer error.
        let target = FrameTarget::new(
            &gpu.adapter,
            &gpu.device,
            TargetConfig::readback((w, h), samples, config.mode),
        )?;
        let player_config = PlayerConfig {
            color_format: COLOR_FORMAT,
            depth_format: (config.mode == Mode::Depth).then_some(DEPTH_FORMAT),
            sample_count: samples,
            size: (w, h),
            mode: config.mode,
            glass_opacity: config.glass_opacity,
            draw_path: config
                .draw_path
                .unwrap_or_else(|| DrawPath::for_device(&gpu.adapter, &gpu.device)),
            device: Some(gpu.device_info()),
            shading: config.shading,
            tone_map: config.tone_map,
            decode_textures: config.decode_textures,
        };
        let player = if config.force_u32 {
            Player::new_u32(&gpu.device, &gpu.queue, baked, player_config)?
        } else {
            Player::new(&gpu.device, &gpu.queue, baked, player_config)?
        };

        let timer = GpuTimer::new(&gpu.device, &gpu.queue, false);
        Ok(HeadlessRenderer {
            gpu,
            player,
            mode: config.mode,
            target,
            timer,
        })
    }

    /// Shifts every frame's projection by `offset` pixels ([`Player::set_subpixel_offset`]).
    pub fn set_subpixel_offset(&self, offset: [f64; 2]) {
        self.player.set_subpixel_offset(&self.gpu.queue, offset);
    }

    /// Plays material variant `name` (`None`: the default materials); see
    /// [`Player::set_variant`].
    pub fn set_variant(&self, name: Option<&str>) -> Result<(), PlayerError> {
        self.player.set_variant(&self.gpu.queue, name)
    }

    /// The player.
    pub fn player(&self) -> &Player {
        &self.player
    }

    /// Renders frame `frame` and reads it back as 8-bit sRGB.
    pub fn render(&self, frame: u32) -> Result<RenderedFrame, PlayerError> {
        let device = &self.gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("trisort frame"),
        });
        let drawn = {
            let timestamps = self.timer.as_ref().map(GpuTimer::pass_writes);
            let mut pass = self
                .target
                .begin_pass(&mut enc, clear_colour(self.mode), timestamps);
            self.player.draw(&mut pass, frame)
        };
        if let Err(e) = drawn {
            drop(enc);
            let _ = poll_ready(scope.pop());
            return Err(e);
        }
        if let Some(t) = &self.timer {
            t.resolve(&mut enc);
        }
        self.target.copy_to_staging(&mut enc);
        self.gpu.queue.submit([enc.finish()]);
        if let Some(Some(e)) = poll_ready(scope.pop()) {
            return Err(PlayerError::Wgpu(e.to_string()));
        }

        let mut buffers = vec![self.target.staging().expect("created with readback")];
        if let Some(t) = &self.timer {
            buffers.push(t.staging());
        }
        let bytes = map_read_all(device, &buffers)?;
        let rgba8 = self.target.rgba8(&bytes[0], self.mode);
        let gpu_ms = self.timer.as_ref().and_then(|t| t.ms(&bytes[1]));
        Ok(RenderedFrame {
            frame,
            rgba8,
            gpu_ms,
        })
    }
}
