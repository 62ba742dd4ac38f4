//! Helpers shared by the subcommands: loading scenes and paths with notes on stderr, the
//! value parsers, progress bars and JSON output.

use anyhow::Result;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use trisort_format::{Choice, Choosable, OptionValue, ParseOptionError};
use trisort_scene::Scene;

pub use trisort_bake::spec::{
    default_size, parse_bits, parse_range, parse_size, parse_subpixel_offset, FrameRange,
};

/// Loads a scene ([`trisort_bake::load_scene`]) and prints the importer's notes on stderr.
pub fn load_scene(spec: &str) -> Result<Scene> {
    let scene = trisort_bake::load_scene(spec)?;
    for note in &scene.notes {
        eprintln!("trisort: note: {note}");
    }
    Ok(scene)
}

/// The clap value parser of a typed option (`--bridge`, `--seeding`): its names are the
/// possible values, each with its help line, and the value is the type's own parse of the
/// name. A name outside the list is a usage error (exit status 2).
pub fn option_parser<T>() -> impl TypedValueParser<Value = T>
where
    T: OptionValue + std::str::FromStr<Err = ParseOptionError>,
{
    let values = T::ALL
        .iter()
        .map(|v| PossibleValue::new(v.name()).help(v.help()));
    PossibleValuesParser::new(values).map(|name| parse_listed::<T>(&name))
}

/// The clap value parser of an option that may be `auto` (`--strategy`, `--layout`): every
/// value, then `auto`, as for [`option_parser`].
pub fn choice_parser<T: Choosable>() -> impl TypedValueParser<Value = Choice<T>> {
    let values = Choice::<T>::all()
        .into_iter()
        .map(|c| PossibleValue::new(c.name()).help(c.help()));
    PossibleValuesParser::new(values).map(|name| parse_listed::<Choice<T>>(&name))
}

/// Parses a name clap has already checked against the type's own list.
fn parse_listed<T: std::str::FromStr<Err = ParseOptionError>>(name: &str) -> T {
    name.parse()
        .unwrap_or_else(|e| unreachable!("clap accepted an unlisted name: {e}"))
}

/// A progress bar on stderr (hidden when stderr is not a terminal).
pub fn progress_bar(total: u64, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(total);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{prefix:>10} [{bar:30}] {pos}/{len} {msg} ({elapsed}, eta {eta})",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar.set_prefix(what.to_string());
    bar
}

/// Prints a JSON value to stdout.
pub fn print_json(v: &serde_json::Value) {
    println!("{}", serde_json::to_string_pretty(v).expect("json"));
}

/// Opens the GPU for a command. wgpu reports validation errors, out-of-memory and a lost
/// device asynchronously, and its default handler panics; the CLI instead prints the error
/// and exits with status 1. Work already finished is safe: recordings keep their finished
/// frames in `OUT.partial/` (a rerun resumes) and every output file is written by rename.
pub fn open_gpu() -> Result<trisort_gpu::Gpu> {
    open_gpu_with(trisort_gpu::GpuOptions::default())
}

/// [`open_gpu`] on the backend and with the limits of `options` (`--backend`, `--limits`).
pub fn open_gpu_with(options: trisort_gpu::GpuOptions) -> Result<trisort_gpu::Gpu> {
    let gpu = trisort_gpu::Gpu::with_options(
        wgpu::InstanceFlags::from_build_config().with_env(),
        options,
    )?;
    let adapter = gpu.info.name.clone();
    gpu.device
        .on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            eprintln!("trisort: error: GPU error on {adapter}: {e}");
            eprintln!("trisort: finished frames are kept; rerun the command to resume");
            std::process::exit(1);
        }));
    gpu.device.set_device_lost_callback(|reason, message| {
        if reason != wgpu::DeviceLostReason::Destroyed {
            eprintln!("trisort: error: GPU device lost ({reason:?}): {message}");
            eprintln!("trisort: finished frames are kept; rerun the command to resume");
            std::process::exit(1);
        }
    });
    Ok(gpu)
}

/// The scene and path `settings` name, made the ones its recording is made of
/// ([`trisort_bake::Working::for_settings`]); prints the importer's notes and what was split
/// on stderr.
pub fn load_working(settings: &trisort_bake::Settings) -> Result<trisort_bake::Working> {
    let working = trisort_bake::Working::for_settings(settings)?;
    for note in &working.scene.notes {
        eprintln!("trisort: note: {note}");
    }
    if let Some(line) = working.split_summary() {
        eprintln!("trisort: {line}");
    }
    Ok(working)
}

/// The pipeline's [`trisort_bake::Events`] on the terminal: notes on stderr, recording
/// progress as a bar (hidden when stderr is not a terminal).
pub struct Console {
    bar: indicatif::ProgressBar,
}

impl Console {
    /// A console with its bar not yet shown.
    pub fn new() -> Console {
        Console {
            bar: progress_bar(0, "record"),
        }
    }
}

impl trisort_bake::Events for Console {
    fn note(&mut self, text: &str) {
        eprintln!("trisort: {text}");
    }

    fn progress(&mut self, p: &trisort_recorder::Progress) {
        let bar = &self.bar;
        if bar.length() != Some(p.total as u64) || bar.prefix() != format!("phase {}", p.phase) {
            bar.set_prefix(format!("phase {}", p.phase));
            bar.set_length(p.total as u64);
        }
        bar.set_position(p.done as u64);
        bar.set_message(format!("frame {} ({} layers)", p.frame, p.layers));
    }

    fn recorded(&mut self) {
        self.bar.finish_and_clear();
    }
}
