//! The light a baked file is shaded with: a prefiltered environment (image-based light) and an
//! optional directional light, stored in the file so every player shades alike.
//!
//! This module holds what a reader needs: the stored data, its structure check, and the
//! evaluation a renderer does (texel lookups, the irradiance of the spherical harmonics, the
//! layout of the equirectangular levels). Making an environment (prefiltering an HDR image,
//! the built-in studio) is the `trisort-light` crate's job.

use std::f32::consts::PI;

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
    ///
    /// `Y_i` are the real spherical harmonics of the world-space unit vector `n = (x, y, z)`
    /// as [`sh_basis`] evaluates them: `0.282095`, `0.488603·y`, `0.488603·z`, `0.488603·x`,
    /// `1.092548·xy`, `1.092548·yz`, `0.315392·(3z² − 1)`, `1.092548·xz`,
    /// `0.546274·(x² − y²)` (the usual Cartesian formulas, applied to glTF's axes as they are;
    /// +Y up does not make `Y10` the vertical one). [`Environment::irradiance`] sums them.
    pub sh: [[f32; 3]; 9],
    /// Optional directional light added to the environment.
    pub sun: Option<Sun>,
    /// Exposure: a multiplier on all light before tone mapping.
    pub exposure: f32,
}

/// binary16 bits of 1.0.
const HALF_ONE: u16 = 0x3c00;
/// The real spherical harmonics Y00 … Y22 of a unit direction, in [`Environment::sh`]'s
/// order and convention.
pub fn sh_basis(n: [f32; 3]) -> [f32; 9] {
    let [x, y, z] = n;
    [
        0.282_094_8,
        0.488_602_5 * y,
        0.488_602_5 * z,
        0.488_602_5 * x,
        1.092_548_4 * x * y,
        1.092_548_4 * y * z,
        0.315_391_57 * (3.0 * z * z - 1.0),
        1.092_548_4 * x * z,
        0.546_274_2 * (x * x - y * y),
    ]
}

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

    /// Bytes of the stored texels (all levels; 8 per texel).
    pub fn texel_bytes(&self) -> u64 {
        self.levels.iter().map(|l| l.len() as u64 * 2).sum()
    }

    /// What differs between this environment and `expected` (made anew from the same source),
    /// or `None`: name, sizes, exposure and sun exactly (bit for bit), the spherical harmonics
    /// and every texel within 1 % relative (plus 10⁻³ absolute) — the prefilter's float
    /// arithmetic may round differently on another machine, a forged light differs by far
    /// more. What a validator checks a file's claimed light by.
    pub fn difference(&self, expected: &Environment) -> Option<String> {
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-3 + 0.01 * a.abs().max(b.abs());
        if self.name != expected.name {
            return Some(format!("named {:?}, not {:?}", self.name, expected.name));
        }
        if (self.width, self.height, self.levels.len())
            != (expected.width, expected.height, expected.levels.len())
        {
            return Some(format!(
                "{}x{} with {} levels, not {}x{} with {}",
                self.width,
                self.height,
                self.levels.len(),
                expected.width,
                expected.height,
                expected.levels.len()
            ));
        }
        let bits =
            |s: Option<Sun>| s.map(|s| (s.direction.map(f32::to_bits), s.color.map(f32::to_bits)));
        if bits(self.sun) != bits(expected.sun) {
            return Some(format!("sun {:?}, not {:?}", self.sun, expected.sun));
        }
        if self.exposure.to_bits() != expected.exposure.to_bits() {
            return Some(format!(
                "exposure {}, not {}",
                self.exposure, expected.exposure
            ));
        }
        let sh = self.sh.iter().flatten().zip(expected.sh.iter().flatten());
        if sh.clone().any(|(&a, &b)| !close(a, b)) {
            return Some("irradiance (spherical harmonics) differs".into());
        }
        for (k, (a, b)) in self.levels.iter().zip(&expected.levels).enumerate() {
            let f = |x: &u16| half::f16::from_bits(*x).to_f32();
            if a.len() != b.len() || a.iter().zip(b).any(|(x, y)| !close(f(x), f(y))) {
                return Some(format!("radiance level {k} differs"));
            }
        }
        None
    }

    /// The RGB radiance stored at texel (x, y) of level `k` (panics outside the level).
    pub fn texel(&self, k: usize, x: u32, y: u32) -> [f32; 3] {
        let (w, _) = self.level_size(k);
        let i = (y as usize * w as usize + x as usize) * 4;
        let l = &self.levels[k];
        [0, 1, 2].map(|c| half::f16::from_bits(l[i + c]).to_f32())
    }

    /// The solid-angle-weighted mean radiance of level `k` (what the level's light adds up
    /// to; prefiltering keeps it).
    pub fn level_mean(&self, k: usize) -> [f32; 3] {
        let (w, h) = self.level_size(k);
        let mut sum = [0.0f64; 3];
        for y in 0..h {
            let omega = row_solid_angle(y, w, h) as f64;
            for x in 0..w {
                let t = self.texel(k, x, y);
                for c in 0..3 {
                    sum[c] += t[c] as f64 * omega;
                }
            }
        }
        sum.map(|s| (s / (4.0 * std::f64::consts::PI)) as f32)
    }

    /// Irradiance / π for a surface with unit normal `n` (world space), from
    /// [`Environment::sh`]: what a white Lambertian surface reflects, sun not included.
    pub fn irradiance(&self, n: [f32; 3]) -> [f32; 3] {
        sh_irradiance(&self.sh, n)
    }

    /// Checks what a reader relies on: at least one level, each of its size, finite values, no
    /// negative light (texels, sun colour, exposure).
    pub fn check_structure(&self) -> Result<(), crate::StructureError> {
        if self.width == 0 || self.height == 0 || self.levels.is_empty() {
            return Err(crate::Part::Environment.error("the environment has no texels"));
        }
        if self.levels.len() > 16 {
            return Err(crate::Part::Environment
                .error(format!("the environment has {} levels", self.levels.len())));
        }
        for (k, level) in self.levels.iter().enumerate() {
            let (w, h) = self.level_size(k);
            if level.len() as u64 != w as u64 * h as u64 * 4 {
                return Err(crate::Part::Environment.error(format!(
                    "environment level {k} has the wrong number of texels"
                )));
            }
            // binary16 exponent all ones: infinity or NaN.
            if level.iter().any(|&b| b & 0x7c00 == 0x7c00) {
                return Err(crate::Part::Environment
                    .error(format!("environment level {k} has a non-finite texel")));
            }
            // Sign bit on anything but −0: negative radiance.
            if level.iter().any(|&b| b > 0x8000) {
                return Err(crate::Part::Environment
                    .error(format!("environment level {k} has a negative texel")));
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
            return Err(crate::Part::Environment.error("the environment has a non-finite value"));
        }
        // Negative light would darken what it shines on; shading has no meaning for it.
        if self.exposure < 0.0 {
            return Err(crate::Part::Environment.error(format!(
                "the environment's exposure is negative ({})",
                self.exposure
            )));
        }
        if let Some(sun) = self.sun.filter(|s| s.color.iter().any(|&c| c < 0.0)) {
            return Err(crate::Part::Environment.error(format!(
                "the environment's sun has a negative colour {:?}",
                sun.color
            )));
        }
        Ok(())
    }
}

/// `Σ sh[i] · Y_i(n)` per channel: [`Environment::irradiance`] of coefficients `sh` (in
/// [`Environment::sh`]'s order and convention).
pub fn sh_irradiance(sh: &[[f32; 3]; 9], n: [f32; 3]) -> [f32; 3] {
    let mut e = [0.0; 3];
    for (coef, yi) in sh.iter().zip(sh_basis(n)) {
        for c in 0..3 {
            e[c] += coef[c] * yi;
        }
    }
    e
}

/// binary16 bits of `v` (round to nearest even; overflow to infinity).
fn half_bits(v: f32) -> u16 {
    half::f16::from_f32(v).to_bits()
}

/// The direction of texel (x, y) of a `w` × `h` equirectangular image (the layout described
/// on [`Environment`]).
pub fn texel_direction(x: u32, y: u32, w: u32, h: u32) -> [f32; 3] {
    let phi = 2.0 * PI * (x as f32 + 0.5) / w as f32;
    let theta = PI * (y as f32 + 0.5) / h as f32;
    [
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    ]
}

/// The solid angle of one texel of row `y` of a `w` × `h` equirectangular image.
pub fn row_solid_angle(y: u32, w: u32, h: u32) -> f32 {
    let t0 = PI * y as f32 / h as f32;
    let t1 = PI * (y + 1) as f32 / h as f32;
    2.0 * PI / w as f32 * (t0.cos() - t1.cos())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uniform_environment_irradiates_its_value_everywhere() {
        let u = Environment::uniform(0.7);
        u.check_structure().unwrap();
        for n in [[0.0, 1.0, 0.0], [0.3, -0.8, 0.52], [-1.0, 0.0, 0.0]] {
            let e = u.irradiance(n)[0];
            assert!((e - 0.7).abs() <= 0.7e-5, "{n:?}: {e}");
        }
        assert_eq!(u.texel(0, 0, 0), [half::f16::from_f32(0.7).to_f32(); 3]);
        assert!((u.level_mean(0)[1] - u.texel(0, 0, 0)[1]).abs() < 1e-6);
    }

    #[test]
    fn check_structure_refuses_non_finite_texels() {
        let mut env = Environment::uniform(1.0);
        env.levels[0][1] = 0x7e00; // NaN
        assert!(env
            .check_structure()
            .unwrap_err()
            .problem
            .contains("non-finite texel"));
    }

    #[test]
    fn check_structure_refuses_negative_light() {
        let mut env = Environment::uniform(1.0);
        env.levels[0][1] = 0x8000; // −0 is zero light
        env.check_structure().unwrap();
        env.levels[0][1] = half_bits(-0.5);
        let e = env.check_structure().unwrap_err().problem;
        assert!(e.contains("level 0 has a negative texel"), "{e}");
        let mut env = Environment::uniform(1.0);
        env.exposure = 0.0;
        env.check_structure().unwrap();
        env.exposure = -1.0;
        let e = env.check_structure().unwrap_err().problem;
        assert!(e.contains("exposure is negative (-1)"), "{e}");
        let mut env = Environment::uniform(1.0);
        env.sun = Some(Sun {
            direction: [0.0, 1.0, 0.0],
            color: [1.0, -0.25, 1.0],
        });
        let e = env.check_structure().unwrap_err().problem;
        assert!(e.contains("sun has a negative colour"), "{e}");
    }
}
