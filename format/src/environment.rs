//! The light a baked file is shaded with: a prefiltered environment (image-based light) and an
//! optional directional light, stored in the file so every player shades alike.

use serde::{Deserialize, Serialize};

/// A directional light.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sun {
    /// World-space unit direction *towards* the light.
    pub direction: [f32; 3],
    /// Linear RGB radiance (colour × intensity).
    pub color: [f32; 3],
}

/// Image-based light: specular radiance prefiltered for GGX roughness, and diffuse irradiance
/// as spherical harmonics, both in world space (+Y up, glTF's convention).
///
/// The radiance is an equirectangular image: texel (x, y) of level 0 looks along direction
/// `(sin θ cos φ, cos θ, sin θ sin φ)` with `φ = 2π (x + 0.5) / width` and
/// `θ = π (y + 0.5) / height` (row 0 at the zenith). Level k has `max(1, width >> k)` ×
/// `max(1, height >> k)` texels and holds the radiance prefiltered for perceptual roughness
/// `k / (levels - 1)` (level 0: the mirror image). Texels are RGBA binary16 (`half` bits), alpha 1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Environment {
    /// What it is (`studio`, or the HDR file's name).
    pub name: String,
    /// Width of level 0 in texels.
    pub width: u32,
    /// Height of level 0 in texels.
    pub height: u32,
    /// The prefiltered levels, RGBA binary16 each.
    pub levels: Vec<Vec<u16>>,
    /// Irradiance / π as order-2 spherical harmonics (9 RGB coefficients, in the order
    /// Y00, Y1-1, Y10, Y11, Y2-2, Y2-1, Y20, Y21, Y22): a Lambertian surface of albedo ρ with
    /// normal n reflects `ρ · Σ sh[i] · Y_i(n)`.
    pub sh: [[f32; 3]; 9],
    /// Optional directional light added to the environment.
    pub sun: Option<Sun>,
    /// Exposure: a multiplier on all light before tone mapping.
    pub exposure: f32,
}

/// binary16 bits of 1.0.
const HALF_ONE: u16 = 0x3c00;

impl Environment {
    /// A uniform environment of radiance `value` in every direction, no sun.
    pub fn uniform(value: f32) -> Environment {
        let bits = half_bits(value);
        let mut sh = [[0.0; 3]; 9];
        // Y00 = 0.2820948: a constant radiance L gives irradiance / π = L = c00 · Y00.
        sh[0] = [value / 0.282_094_8; 3];
        Environment {
            name: format!("uniform {value}"),
            width: 1,
            height: 1,
            levels: vec![vec![bits, bits, bits, HALF_ONE]],
            sh,
            sun: None,
            exposure: 1.0,
        }
    }

    /// Size of level `k`.
    pub fn level_size(&self, k: usize) -> (u32, u32) {
        ((self.width >> k).max(1), (self.height >> k).max(1))
    }

    /// Checks what a reader relies on: at least one level, each of its size, finite values.
    pub fn check_structure(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 || self.levels.is_empty() {
            return Err("the environment has no texels".into());
        }
        if self.levels.len() > 16 {
            return Err(format!("the environment has {} levels", self.levels.len()));
        }
        for (k, level) in self.levels.iter().enumerate() {
            let (w, h) = self.level_size(k);
            if level.len() as u64 != w as u64 * h as u64 * 4 {
                return Err(format!(
                    "environment level {k} has the wrong number of texels"
                ));
            }
        }
        let sun = self
            .sun
            .iter()
            .flat_map(|s| s.direction.iter().chain(&s.color));
        if !self
            .sh
            .iter()
            .flatten()
            .chain(sun)
            .chain([&self.exposure])
            .all(|x| x.is_finite())
        {
            return Err("the environment has a non-finite value".into());
        }
        Ok(())
    }
}

/// binary16 bits of `v` (round to nearest even; overflow to infinity).
fn half_bits(v: f32) -> u16 {
    half::f16::from_f32(v).to_bits()
}
