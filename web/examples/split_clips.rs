//! Rewrites a baked file as a bundle of clips over its frames, for the web player's browser
//! test (a file of several clips without baking several paths):
//!
//! ```sh
//! cargo run -p trisort-web --example split_clips -- IN.baked OUT.baked NAME:COUNT[@FPS]... NAME[@FPS]
//! ```
//!
//! Each `NAME:COUNT` takes the next COUNT frames; the last clip, given without a count, takes
//! the rest. A clip without `@FPS` keeps the file's rate. The frames, index buffer and all
//! else stay as they were. Native only (files are not written from wasm): for
//! `wasm32-unknown-unknown` it builds as an empty program.

#[cfg(not(target_arch = "wasm32"))]
use std::path::Path;
use std::process::ExitCode;

#[cfg(not(target_arch = "wasm32"))]
use trisort_format::{Baked, Clip, FileKind};

#[cfg(not(target_arch = "wasm32"))]
/// The clips `specs` make of a file of `frames` frames at `fps`, each sampled from `path_hash`.
fn clips(
    specs: &[String],
    frames: u32,
    fps: Option<f64>,
    path_hash: trisort_format::Hash,
) -> Result<Vec<Clip>, String> {
    let mut out = Vec::new();
    let mut first = 0u32;
    for (k, spec) in specs.iter().enumerate() {
        let (spec, rate) = match spec.split_once('@') {
            Some((s, r)) => (
                s,
                Some(r.parse::<f64>().map_err(|e| format!("{spec}: {e}"))?),
            ),
            None => (spec.as_str(), fps),
        };
        let last = k + 1 == specs.len();
        let (name, count) = match spec.split_once(':') {
            Some((n, c)) => (n, c.parse::<u32>().map_err(|e| format!("{spec}: {e}"))?),
            None if last => (spec, frames.saturating_sub(first)),
            None => {
                return Err(format!(
                    "{spec}: only the last clip may leave out its count"
                ))
            }
        };
        out.push(Clip {
            name: name.to_string(),
            first,
            count,
            fps: rate,
            path_hash,
            path_first: first,
        });
        first += count;
    }
    Ok(out)
}

#[cfg(not(target_arch = "wasm32"))]
fn run(args: &[String]) -> Result<(), String> {
    let [input, output, specs @ ..] = args else {
        return Err("usage: split_clips IN.baked OUT.baked NAME:COUNT[@FPS]... NAME[@FPS]".into());
    };
    if specs.is_empty() {
        return Err("give at least one clip".into());
    }
    let mut baked: Baked =
        trisort_format::read_file(FileKind::Baked, Path::new(input)).map_err(|e| e.to_string())?;
    baked.clips = clips(specs, baked.frames.len() as u32, baked.fps, baked.path_hash)?;
    baked
        .check_structure()
        .map_err(|e| format!("{input}: {e}"))?;
    trisort_format::write_file_atomic(FileKind::Baked, Path::new(output), &baked)
        .map_err(|e| e.to_string())
}

#[cfg(target_arch = "wasm32")]
fn main() -> ExitCode {
    ExitCode::FAILURE
}

#[cfg(not(target_arch = "wasm32"))]
fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("split_clips: {e}");
            ExitCode::FAILURE
        }
    }
}
