//! GGX prefiltering of the working image: importance samples read from the mip whose texels
//! match their solid angle.

use std::f32::consts::PI;

use trisort_format::environment::texel_direction;

use crate::image::Image;
use crate::{WORKING_HEIGHT, WORKING_WIDTH};

/// GGX samples per prefiltered level (1 and up), spread over its filtered texels: rough levels
/// have few texels and take more samples each, which keeps the mips they read fine (coarse
/// mips leak a bright source's light into the lobe's edge).
const SAMPLE_BUDGET: u32 = 1 << 20;
/// Fewest and most samples per texel.
const SAMPLES_PER_TEXEL: (u32, u32) = (64, 4096);
/// Level k ≥ 1 is filtered at this many times its width and height (at most level 0's),
/// then averaged down, so that a coarse level keeps the light's mean.
const SUPERSAMPLE: u32 = 2;
/// Equirectangular coordinates `(φ / 2π, θ / π)` of unit direction `d`.
fn equirect_uv(d: [f32; 3]) -> (f32, f32) {
    let mut phi = d[2].atan2(d[0]);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    (phi / (2.0 * PI), d[1].clamp(-1.0, 1.0).acos() / PI)
}

/// Trilinear radiance along `d` at fractional mip `lod` of `mips`.
fn sample_mips(mips: &[Image], d: [f32; 3], lod: f32) -> [f32; 3] {
    let uv = equirect_uv(d);
    let lod = lod.clamp(0.0, (mips.len() - 1) as f32);
    let l0 = lod.floor() as usize;
    let a = mips[l0].bilinear(uv);
    if l0 + 1 >= mips.len() {
        return a;
    }
    let t = lod - l0 as f32;
    let b = mips[l0 + 1].bilinear(uv);
    [0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * t)
}

/// The `i`-th of `n` Hammersley points in [0, 1)².
fn hammersley(i: u32, n: u32) -> (f32, f32) {
    (
        i as f32 / n as f32,
        i.reverse_bits() as f32 * (1.0 / 4_294_967_296.0),
    )
}

/// Two unit vectors completing unit `n` to an orthonormal basis (Duff et al. 2017).
fn basis(n: [f32; 3]) -> ([f32; 3], [f32; 3]) {
    let s = 1.0f32.copysign(n[2]);
    let a = -1.0 / (s + n[2]);
    let b = n[0] * n[1] * a;
    (
        [1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]],
        [b, s + n[1] * n[1] * a, -n[1]],
    )
}

/// Level k's filtered size (before averaging down to its stored size) and samples per texel.
pub(crate) fn level_plan(k: usize) -> (u32, u32, u32) {
    let w = ((WORKING_WIDTH >> k).max(1) * SUPERSAMPLE).min(WORKING_WIDTH);
    let h = ((WORKING_HEIGHT >> k).max(1) * SUPERSAMPLE).min(WORKING_HEIGHT);
    let (lo, hi) = SAMPLES_PER_TEXEL;
    (w, h, (SAMPLE_BUDGET / (w * h)).clamp(lo, hi))
}

/// Radiance prefiltered for GGX at perceptual `roughness` (α = roughness²), `w` × `h` texels,
/// with normal = view = reflection: per texel, the N·L-weighted mean of `count` GGX
/// importance samples, each read from the mip whose texels are about the sample's solid angle.
pub(crate) fn prefilter(mips: &[Image], roughness: f32, w: u32, h: u32, count: u32) -> Image {
    let alpha = roughness * roughness;
    let a2 = alpha * alpha;
    let base = &mips[0];
    let texel_omega = 4.0 * PI / (base.width * base.height) as f32;
    // Per sample (the same for every texel): half-vector in the local frame, N·L and lod.
    let samples: Vec<([f32; 3], f32, f32)> = (0..count)
        .filter_map(|i| {
            let (u1, u2) = hammersley(i, count);
            let cos_h = ((1.0 - u1) / (1.0 + (a2 - 1.0) * u1)).sqrt();
            let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
            let phi = 2.0 * PI * u2;
            let n_dot_l = 2.0 * cos_h * cos_h - 1.0;
            if n_dot_l <= 0.0 {
                return None;
            }
            let denom = cos_h * cos_h * (a2 - 1.0) + 1.0;
            let d = a2 / (PI * denom * denom);
            // pdf of L = D · (N·H) / (4 V·H) = D / 4 with N = V.
            let sample_omega = 1.0 / (count as f32 * d / 4.0);
            let lod = 0.5 * (sample_omega / texel_omega).log2();
            Some(([sin_h * phi.cos(), sin_h * phi.sin(), cos_h], n_dot_l, lod))
        })
        .collect();
    let mut rgb = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            let n = texel_direction(x, y, w, h);
            let (t, b) = basis(n);
            let mut sum = [0.0f32; 3];
            let mut weight = 0.0f32;
            for &(hl, n_dot_l, lod) in &samples {
                let hv = [0, 1, 2].map(|i| t[i] * hl[0] + b[i] * hl[1] + n[i] * hl[2]);
                // L = 2 (V·H) H − V with V = N, V·H = cos θh (a unit vector).
                let l = [0, 1, 2].map(|i| 2.0 * hl[2] * hv[i] - n[i]);
                let c = sample_mips(mips, l, lod);
                for i in 0..3 {
                    sum[i] += c[i] * n_dot_l;
                }
                weight += n_dot_l;
            }
            rgb.extend(sum.map(|s| s / weight));
        }
    }
    Image {
        width: w,
        height: h,
        rgb,
    }
}
