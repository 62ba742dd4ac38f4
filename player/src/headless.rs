//! Headless rendering for the CLI (`trisort play`) and the tests: frames drawn by a [`Player`]
//! into an `Rgba16Float` target (MSAA resolved to one sample), read back and quantized once to
//! 8-bit sRGB, the way the exact reference renders (DESIGN § Frame accuracy).

use std::sync::mpsc;

use trisort_format::Baked;
use trisort_gpu::Gpu;

use crate::config::{DrawPath, Mode, PlayerConfig};
use crate::error::PlayerError;
use crate::player::{block_on_ready, Player};
use crate::target::{clear_colour, FrameTarget};
use crate::timer::GpuTimer;

/// The background every headless frame is drawn over: a dark grey, linear RGB.
pub const BACKGROUND: [f32; 3] = [0.03, 0.03, 0.03];

/// Format of the headless colour target.
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the headless depth target (`depth` mode only).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

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
        draw_path: None,
        force_u32: false,
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
            (w, h),
            samples,
            COLOR_FORMAT,
            config.mode == Mode::Depth,
            true,
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
                .unwrap_or_else(|| DrawPath::for_adapter(&gpu.adapter)),
            device: Some(gpu.device_info()),
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
            let _ = block_on_ready(scope.pop());
            return Err(e);
        }
        if let Some(t) = &self.timer {
            t.resolve(&mut enc);
        }
        self.target.copy_to_staging(&mut enc);
        self.gpu.queue.submit([enc.finish()]);
        if let Some(Some(e)) = block_on_ready(scope.pop()) {
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

/// Maps `MAP_READ` buffers after the queue is done with them and returns their bytes.
fn map_read_all(
    device: &wgpu::Device,
    buffers: &[&wgpu::Buffer],
) -> Result<Vec<Vec<u8>>, PlayerError> {
    let (tx, rx) = mpsc::channel();
    for (k, b) in buffers.iter().enumerate() {
        let tx = tx.clone();
        b.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send((k, r));
        });
    }
    drop(tx);
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| PlayerError::Readback(e.to_string()))?;
    for (_, r) in rx.iter() {
        r.map_err(|e| PlayerError::Readback(e.to_string()))?;
    }
    let mut out = Vec::with_capacity(buffers.len());
    for b in buffers {
        let bytes = b
            .slice(..)
            .get_mapped_range()
            .map_err(|e| PlayerError::Readback(e.to_string()))?
            .to_vec();
        b.unmap();
        out.push(bytes);
    }
    Ok(out)
}

/// An IEEE 754 half (binary16) as f32.
pub fn f16_to_f32(h: u16) -> f32 {
    let negative = h & 0x8000 != 0;
    let exp = ((h >> 10) & 0x1f) as u32;
    let man = (h & 0x3ff) as u32;
    let magnitude = match exp {
        0 => man as f32 * (1.0 / 16_777_216.0), // subnormal: man × 2⁻²⁴
        31 => f32::from_bits(0x7f80_0000 | (man << 13)),
        _ => f32::from_bits(((exp + 112) << 23) | (man << 13)),
    };
    if negative {
        -magnitude
    } else {
        magnitude
    }
}

/// Linear to sRGB transfer function (IEC 61966-2-1) on [0, 1].
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Converts linear `Rgba16Float` texels (4 halves each) to 8-bit sRGB RGBA with alpha 255,
/// quantizing once: the one conversion the player and the exact reference share.
///
/// With `under = None` the texels are final colours (`blend`, `depth`: already composited over
/// an opaque background). With `Some(background)` they hold premultiplied colour and coverage
/// alpha (`saturate`'s accumulation) and the background goes under them first:
/// `rgb + (1 − a)·background`.
pub fn quantize_rgba16f(halves: &[u16], under: Option<[f32; 3]>) -> Vec<u8> {
    debug_assert!(halves.len().is_multiple_of(4));
    let mut out = Vec::with_capacity(halves.len());
    for px in halves.chunks_exact(4) {
        let a = f16_to_f32(px[3]).clamp(0.0, 1.0);
        for (c, &h) in px[..3].iter().enumerate() {
            let mut v = f16_to_f32(h);
            if let Some(bg) = under {
                v += (1.0 - a) * bg[c];
            }
            out.push((linear_to_srgb(v) * 255.0).round() as u8);
        }
        out.push(255);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halves_decode() {
        assert_eq!(f16_to_f32(0x0000), 0.0);
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x3800), 0.5);
        assert_eq!(f16_to_f32(0x7bff), 65504.0);
        assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
        assert_eq!(f16_to_f32(0x7c00), f32::INFINITY);
        assert!(f16_to_f32(0x7e00).is_nan());
    }

    #[test]
    fn quantize_once_with_and_without_background() {
        // 1.0 and 0.5 linear; alpha 1.
        let px = [0x3c00, 0x3800, 0x0000, 0x3c00];
        assert_eq!(quantize_rgba16f(&px, None), vec![255, 188, 0, 255]);
        // Premultiplied nothing (alpha 0) over a background of 0.5 gives the background.
        let empty = [0, 0, 0, 0];
        assert_eq!(
            quantize_rgba16f(&empty, Some([0.5, 0.5, 1.0])),
            vec![188, 188, 255, 255]
        );
        // Alpha 1 hides the background entirely.
        assert_eq!(
            quantize_rgba16f(&px, Some([1.0; 3])),
            vec![255, 188, 0, 255]
        );
    }
}
