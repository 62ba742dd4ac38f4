//! The irradiance's spherical harmonics: the cosine lobe per band and the deringing of a
//! concentrated source.

use trisort_format::environment::{sh_irradiance, texel_direction};

/// Cosine-lobe convolution per SH band divided by π: irradiance / π = Σ A_l / π · L_lm · Y_lm.
pub(crate) const BAND_SCALE: [f32; 9] = [
    1.0,
    2.0 / 3.0,
    2.0 / 3.0,
    2.0 / 3.0,
    0.25,
    0.25,
    0.25,
    0.25,
    0.25,
];

/// Removes the ringing of order-2 harmonics where the light is concentrated (a sun): true
/// irradiance / π is a weighted mean of the radiance, so it is never below the darkest texel
/// (`floor`, per channel), but SH9 of a small bright source dips far below it, even below 0,
/// facing away from the source. When the harmonics dip below `floor` by more than 1 % of the
/// mean radiance, bands 1 and 2 are scaled by `exp(−t·l(l+1))` with the smallest `t` (found by
/// bisection, one `t` for all channels so colours do not shift) that lifts them to `floor`
/// everywhere; band 0, the mean, is kept. Lights without such dips are returned unchanged.
pub(crate) fn dering(sh: [[f32; 3]; 9], floor: [f32; 3]) -> [[f32; 3]; 9] {
    // Directions to check: a 64 × 32 grid and the poles.
    let mut directions: Vec<[f32; 3]> = (0..32 * 64)
        .map(|i| texel_direction(i % 64, i / 64, 64, 32))
        .collect();
    directions.extend([[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]]);
    let windowed = |t: f32| {
        let mut out = sh;
        for (i, coef) in out.iter_mut().enumerate() {
            let l = match i {
                0 => 0.0,
                1..=3 => 1.0,
                _ => 2.0,
            };
            let w = (-t * l * (l + 1.0)).exp();
            *coef = coef.map(|v| v * w);
        }
        out
    };
    let slack: [f32; 3] = sh[0].map(|c| 0.01 * c * 0.282_094_8);
    let dips = |sh: &[[f32; 3]; 9]| {
        directions.iter().any(|&d| {
            let e = sh_irradiance(sh, d);
            (0..3).any(|c| e[c] < floor[c] - slack[c])
        })
    };
    if !dips(&sh) {
        return sh;
    }
    // exp(−16·2) leaves bands 1 and 2 at ~1e-7: the mean alone, which never dips.
    let (mut lo, mut hi) = (0.0f32, 16.0f32);
    for _ in 0..32 {
        let mid = 0.5 * (lo + hi);
        if dips(&windowed(mid)) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    windowed(hi)
}
