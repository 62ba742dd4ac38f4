//! The built-in light: a procedural photo studio.

use std::f32::consts::PI;
use std::sync::OnceLock;

use trisort_format::environment::texel_direction;
use trisort_format::{Environment, Sun};

use crate::{dot, normalize, WORKING_HEIGHT, WORKING_WIDTH};

/// The built-in studio: a soft grey floor, a darker horizon, a bright overhead soft box,
/// two tall strip lights 55° either side of +Z (the side a glTF model faces) and a warm
/// key light towards +X, which give car paint and chrome their highlights; plus a modest
/// sun from above, in front and towards −X. Irradiance / π: about 1.08 facing up,
/// 0.33–0.58 facing sideways, 0.29 facing down (sun not included; `cargo run -p
/// trisort-merger --example environment_cost`). Computed once per process.
pub fn studio() -> Environment {
    static STUDIO: OnceLock<Environment> = OnceLock::new();
    STUDIO
        .get_or_init(|| {
            let (w, h) = (2 * WORKING_WIDTH, 2 * WORKING_HEIGHT);
            let mut rgb = Vec::with_capacity((w * h * 3) as usize);
            for y in 0..h {
                for x in 0..w {
                    rgb.extend_from_slice(&studio_radiance(texel_direction(x, y, w, h)));
                }
            }
            let mut env = crate::from_equirect("studio", w, h, &rgb)
                .expect("the studio's radiance is finite and non-negative");
            env.sun = Some(Sun {
                direction: normalize([-0.45, 0.75, 0.5]),
                color: [1.6, 1.52, 1.4],
            });
            env
        })
        .clone()
}

/// `0` below `e0`, `1` above `e1`, smooth between.
fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A soft-edged window `|v| < half` with edges `soft` wide.
fn window(v: f32, half: f32, soft: f32) -> f32 {
    1.0 - smoothstep(half - soft, half + soft, v.abs())
}

/// The studio's radiance along unit direction `d` (+Y up; the front of a glTF model faces +Z).
pub(crate) fn studio_radiance(d: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = d;
    // Floor: soft grey, lighter beneath; walls: dark near the horizon, lighter towards the
    // ceiling; the horizon itself a darker band.
    let mut grey = if y < 0.0 {
        0.10 + 0.22 * (-y).sqrt()
    } else {
        0.07 + 0.15 * y
    };
    grey *= 0.35 + 0.65 * smoothstep(0.0, 0.12, y.abs());
    let mut c = [grey; 3];
    let mut add = |rgb: [f32; 3], m: f32| {
        for i in 0..3 {
            c[i] += rgb[i] * m;
        }
    };
    // The overhead soft box: a rectangle on the ceiling, longer along the car (z).
    if y > 0.05 {
        let (px, pz) = (x / y, z / y);
        add([4.0; 3], window(px, 0.3, 0.1) * window(pz, 0.6, 0.12));
    }
    // Two strip lights, tall and narrow, at 55° left and right of the front.
    let azimuth = x.atan2(z);
    let elevation = y.clamp(-1.0, 1.0).asin();
    let height = smoothstep(0.05, 0.15, elevation) * (1.0 - smoothstep(0.85, 1.0, elevation));
    for centre in [55f32.to_radians(), -55f32.to_radians()] {
        let mut off = azimuth - centre;
        if off > PI {
            off -= 2.0 * PI;
        } else if off < -PI {
            off += 2.0 * PI;
        }
        add([4.5, 4.7, 5.0], window(off, 0.05, 0.02) * height);
    }
    // The warm key: a large soft disc to the right, a little above the horizon.
    let key = normalize([1.0, 0.45, -0.2]);
    add(
        [3.0, 2.4, 1.7],
        smoothstep(
            22f32.to_radians().cos(),
            12f32.to_radians().cos(),
            dot(d, key),
        ),
    );
    c
}
