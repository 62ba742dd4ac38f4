//! Measurement (not a test): what the environment light costs a baked file.
//!
//! `cargo run -p trisort-merger --example environment_cost`
//!
//! Prints the time to build the built-in studio (its first call in the process prefilters it:
//! resampling, 5 GGX levels, SH9), the bytes of its texels, its irradiance / π along the axes, and what
//! it adds to a baked file after zstd (a small synthetic bake encoded with the studio and with
//! the one-texel `Environment::uniform(1.0)`).

use std::time::Instant;

use trisort_format::{container, Environment, FileKind};
use trisort_merger::synth::{turntable, Turntable};
use trisort_merger::{merge, MergeOptions};

fn main() {
    let t = Instant::now();
    let studio = trisort_light::studio();
    let seconds = t.elapsed().as_secs_f64();
    let rec = turntable(&Turntable {
        objects: 2,
        sides: 6,
        frames: 3,
        ..Turntable::default()
    });
    let merged = merge(std::slice::from_ref(&rec), &MergeOptions::default()).expect("merge");
    let with_studio = container::encode(FileKind::Baked, &merged.clone().lit(studio.clone())).len();
    let with_uniform =
        container::encode(FileKind::Baked, &merged.lit(Environment::uniform(1.0))).len();
    println!("studio prefilter: {seconds:.3} s (first call in the process)");
    println!(
        "studio: {} levels, {}x{} .. {:?}; texels {} bytes raw",
        studio.levels.len(),
        studio.width,
        studio.height,
        studio.level_size(studio.levels.len() - 1),
        studio.texel_bytes()
    );
    let e = |n: [f32; 3]| studio.irradiance(n).map(|v| (v * 1000.0).round() / 1000.0);
    println!(
        "studio irradiance / π: up {:?}, front {:?}, left {:?}, right {:?}, down {:?}; sun {:?}",
        e([0.0, 1.0, 0.0]),
        e([0.0, 0.0, 1.0]),
        e([-1.0, 0.0, 0.0]),
        e([1.0, 0.0, 0.0]),
        e([0.0, -1.0, 0.0]),
        studio.sun
    );
    println!(
        "baked file (zstd): {with_studio} bytes with the studio, {with_uniform} with a uniform \
         light: the studio adds {} bytes",
        with_studio as i64 - with_uniform as i64
    );
}
