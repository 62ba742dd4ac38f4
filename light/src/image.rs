//! The working image of [`crate::from_equirect`]: an equirectangular linear-RGB image in f32,
//! its resampling, halving and mip chain, and its projection onto spherical harmonics.

use trisort_format::environment::{row_solid_angle, sh_basis, texel_direction};

use crate::sh::BAND_SCALE;
use crate::{half_bits, HALF_MAX, HALF_ONE};

/// An equirectangular linear-RGB image in f32.
#[derive(Clone)]
pub(crate) struct Image {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) rgb: Vec<f32>,
}

impl Image {
    /// Box-filters `rgb` (`w` × `h`) to `tw` × `th`: each target texel averages the source
    /// area it covers (partial texels by the fraction covered), rows then columns.
    pub(crate) fn resample(w: u32, h: u32, rgb: &[f32], tw: u32, th: u32) -> Image {
        let cols = box_weights(w, tw);
        let rows = box_weights(h, th);
        // Horizontal pass: h rows of tw texels.
        let mut horiz = vec![0.0f32; (h * tw * 3) as usize];
        for y in 0..h as usize {
            let src = &rgb[y * w as usize * 3..(y + 1) * w as usize * 3];
            for (x, taps) in cols.iter().enumerate() {
                let out = &mut horiz[(y * tw as usize + x) * 3..][..3];
                for &(i, wt) in taps {
                    for c in 0..3 {
                        out[c] += src[i * 3 + c] * wt;
                    }
                }
            }
        }
        let mut out = vec![0.0f32; (tw * th * 3) as usize];
        for (y, taps) in rows.iter().enumerate() {
            for x in 0..tw as usize {
                let o = &mut out[(y * tw as usize + x) * 3..][..3];
                for &(i, wt) in taps {
                    for c in 0..3 {
                        o[c] += horiz[(i * tw as usize + x) * 3 + c] * wt;
                    }
                }
            }
        }
        Image {
            width: tw,
            height: th,
            rgb: out,
        }
    }

    /// Halves the image (width and height, each at least 1), averaging texels by solid angle.
    pub(crate) fn half(&self) -> Image {
        let (w, h) = (self.width, self.height);
        let (hw, hh) = ((w / 2).max(1), (h / 2).max(1));
        let mut rgb = vec![0.0f32; (hw * hh * 3) as usize];
        for y in 0..hh {
            let rows: Vec<u32> = if h > 1 {
                vec![2 * y, 2 * y + 1]
            } else {
                vec![0]
            };
            for x in 0..hw {
                let xs: Vec<u32> = if w > 1 {
                    vec![2 * x, 2 * x + 1]
                } else {
                    vec![0]
                };
                let mut sum = [0.0f32; 3];
                let mut total = 0.0f32;
                for &sy in &rows {
                    let omega = row_solid_angle(sy, w, h);
                    for &sx in &xs {
                        let t = self.at(sx, sy);
                        for c in 0..3 {
                            sum[c] += t[c] * omega;
                        }
                        total += omega;
                    }
                }
                let o = ((y * hw + x) * 3) as usize;
                for c in 0..3 {
                    rgb[o + c] = sum[c] / total;
                }
            }
        }
        Image {
            width: hw,
            height: hh,
            rgb,
        }
    }

    /// This image and its halvings down to 1 × 1.
    pub(crate) fn mip_chain(&self) -> Vec<Image> {
        let mut chain = vec![self.clone()];
        while chain.last().map(|m| m.width > 1 || m.height > 1) == Some(true) {
            let next = chain.last().expect("non-empty").half();
            chain.push(next);
        }
        chain
    }

    /// The texel at (x, y).
    pub(crate) fn at(&self, x: u32, y: u32) -> [f32; 3] {
        let i = ((y * self.width + x) * 3) as usize;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// Bilinear radiance at equirectangular coordinates `(u, v)` = `(φ / 2π, θ / π)` (wrapping
    /// around in φ, clamped at the poles).
    pub(crate) fn bilinear(&self, (u, v): (f32, f32)) -> [f32; 3] {
        let (w, h) = (self.width as f32, self.height as f32);
        let fx = u * w - 0.5;
        let fy = (v * h - 0.5).clamp(0.0, h - 1.0);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let wrap = |x: f32| (x as i64).rem_euclid(self.width as i64) as u32;
        let (xa, xb) = (wrap(x0), wrap(x0 + 1.0));
        let ya = y0 as u32;
        let yb = (ya + 1).min(self.height - 1);
        let (a, b, c, e) = (
            self.at(xa, ya),
            self.at(xb, ya),
            self.at(xa, yb),
            self.at(xb, yb),
        );
        [0, 1, 2].map(|i| {
            let top = a[i] + (b[i] - a[i]) * tx;
            let bottom = c[i] + (e[i] - c[i]) * tx;
            top + (bottom - top) * ty
        })
    }

    /// RGBA binary16 texels (alpha 1), clamped to binary16's finite range.
    pub(crate) fn to_half(&self) -> Vec<u16> {
        let mut out = Vec::with_capacity(self.rgb.len() / 3 * 4);
        for t in self.rgb.chunks_exact(3) {
            out.extend(t.iter().map(|&v| half_bits(v.clamp(0.0, HALF_MAX))));
            out.push(HALF_ONE);
        }
        out
    }

    /// Irradiance / π as SH9 ([`Environment::sh`]).
    pub(crate) fn irradiance_sh(&self) -> [[f32; 3]; 9] {
        let mut sh = [[0.0f64; 3]; 9];
        for y in 0..self.height {
            let omega = row_solid_angle(y, self.width, self.height) as f64;
            for x in 0..self.width {
                let basis = sh_basis(texel_direction(x, y, self.width, self.height));
                let t = self.at(x, y);
                for (coef, yi) in sh.iter_mut().zip(basis) {
                    for c in 0..3 {
                        coef[c] += t[c] as f64 * yi as f64 * omega;
                    }
                }
            }
        }
        let mut out = [[0.0f32; 3]; 9];
        for i in 0..9 {
            out[i] = sh[i].map(|v| (v * BAND_SCALE[i] as f64) as f32);
        }
        out
    }
}

impl Image {
    /// The darkest value of each channel.
    pub(crate) fn min_radiance(&self) -> [f32; 3] {
        let mut min = [f32::MAX; 3];
        for t in self.rgb.chunks_exact(3) {
            for c in 0..3 {
                min[c] = min[c].min(t[c]);
            }
        }
        min
    }
}

/// Per target index: the source indices it covers and their weights (summing to 1).
fn box_weights(src: u32, dst: u32) -> Vec<Vec<(usize, f32)>> {
    let scale = src as f64 / dst as f64;
    (0..dst)
        .map(|i| {
            let (a, b) = (i as f64 * scale, (i + 1) as f64 * scale);
            let mut taps = Vec::new();
            let mut s = a.floor() as u32;
            while (s as f64) < b && s < src {
                let overlap = (b.min(s as f64 + 1.0) - a.max(s as f64)) / scale;
                if overlap > 0.0 {
                    taps.push((s as usize, overlap as f32));
                }
                s += 1;
            }
            taps
        })
        .collect()
}
