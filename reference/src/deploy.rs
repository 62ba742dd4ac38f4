//! The player on an 8-bit sRGB deployment target (`Rgba8UnormSrgb`), which rounds to 8 bits
//! after every blend. Its error against the exact reference is reported separately and never
//! gated on: the rounding is the target's, not the order's.

use trisort_format::Baked;
use trisort_gpu::Gpu;
use trisort_gpu::{clear_colour, linear_to_srgb, Shading, ToneMap, BACKGROUND};
use trisort_player::{Mode, Player, PlayerConfig};

use crate::target::{Target, DEPTH_FORMAT};
use crate::ReferenceError;

/// Format of the deployment target.
pub const SRGB8_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// A [`Player`] drawing into an `Rgba8UnormSrgb` MSAA target, resolved to one sample.
pub struct Srgb8Player<'g> {
    gpu: &'g Gpu,
    player: Player,
    mode: Mode,
    target: Target,
}

impl<'g> Srgb8Player<'g> {
    /// Uploads `baked` for playing at `size` with `samples` in `mode`, glass as recorded,
    /// with the default shading ([`Shading::Pbr`], [`ToneMap::Neutral`]).
    pub fn new(
        gpu: &'g Gpu,
        baked: &Baked,
        size: (u32, u32),
        samples: u32,
        mode: Mode,
    ) -> Result<Srgb8Player<'g>, ReferenceError> {
        Srgb8Player::with_shading(
            gpu,
            baked,
            size,
            samples,
            mode,
            (Shading::Pbr, ToneMap::Neutral),
        )
    }

    /// [`Srgb8Player::new`] with a surface model and tone map.
    pub fn with_shading(
        gpu: &'g Gpu,
        baked: &Baked,
        size: (u32, u32),
        samples: u32,
        mode: Mode,
        (shading, tone_map): (Shading, ToneMap),
    ) -> Result<Srgb8Player<'g>, ReferenceError> {
        let target = Target::new(gpu, size, samples, SRGB8_FORMAT, mode == Mode::Depth)?;
        let config = PlayerConfig {
            depth_format: (mode == Mode::Depth).then_some(DEPTH_FORMAT),
            sample_count: samples,
            size,
            mode,
            shading,
            tone_map,
            ..PlayerConfig::for_adapter(baked, &gpu.adapter, SRGB8_FORMAT)
        };
        let player = Player::new(&gpu.device, &gpu.queue, baked, config)?;
        Ok(Srgb8Player {
            gpu,
            player,
            mode,
            target,
        })
    }

    /// Shifts every frame's projection by `offset` pixels ([`Player::set_subpixel_offset`]).
    pub fn set_subpixel_offset(&self, offset: [f64; 2]) {
        self.player.set_subpixel_offset(&self.gpu.queue, offset);
    }

    /// Renders frame `frame`: 8-bit sRGB RGBA with alpha 255. In `saturate` mode the target
    /// holds premultiplied colour and coverage; the background goes under it on the CPU
    /// (decoded, `rgb + (1 − a)·background`, encoded and rounded once more).
    pub fn render(&self, frame: u32) -> Result<Vec<u8>, ReferenceError> {
        let mut bytes = self
            .target
            .render(self.gpu, clear_colour(self.mode), |pass| {
                self.player.draw(pass, frame)?;
                Ok(())
            })?;
        for px in bytes.chunks_exact_mut(4) {
            if self.mode == Mode::Saturate {
                let a = px[3] as f32 / 255.0;
                for c in 0..3 {
                    let v = srgb_to_linear(px[c] as f32 / 255.0) + (1.0 - a) * BACKGROUND[c];
                    px[c] = (linear_to_srgb(v) * 255.0).round() as u8;
                }
            }
            px[3] = 255;
        }
        Ok(bytes)
    }
}

/// sRGB transfer function to linear (IEC 61966-2-1) on [0, 1].
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}
