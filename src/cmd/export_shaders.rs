//! `trisort export-shaders --lang glsl-es-300|spirv|wgsl -o DIR`: the player's vertex and
//! fragment stages for hosts, with their binding layout (`trisort_gpu::export_shaders`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{anyhow, Result};
use clap::Args;
use serde_json::json;
use trisort_gpu::export_shaders::{export_player_shaders, write_export, ShaderLang};

use crate::common::print_json;

/// Arguments of `export-shaders`.
#[derive(Args, Debug)]
pub struct ExportShadersArgs {
    /// Shader language: glsl-es-300 (the data-texture tier, for GLES 3.0 / WebGL2), spirv or
    /// wgsl (the storage tier).
    #[arg(long, value_parser = parse_lang)]
    lang: ShaderLang,
    /// Output folder (written whole through a temporary folder; an existing one is replaced).
    #[arg(short, long)]
    output: PathBuf,
    /// Print the files written as JSON.
    #[arg(long)]
    json: bool,
}

fn parse_lang(s: &str) -> Result<ShaderLang, String> {
    ShaderLang::parse(s).ok_or_else(|| {
        let names: Vec<&str> = ShaderLang::ALL.iter().map(|l| l.name()).collect();
        format!(
            "unknown shader language `{s}` (one of {})",
            names.join(", ")
        )
    })
}

pub fn run(a: ExportShadersArgs) -> Result<ExitCode> {
    let files = export_player_shaders(a.lang).map_err(|e| anyhow!("export-shaders: {e}"))?;
    write_export(&a.output, &files).map_err(|e| anyhow!("export-shaders: {e}"))?;
    let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
    if a.json {
        print_json(&json!({
            "lang": a.lang.name(),
            "output": a.output,
            "files": names,
        }));
    } else {
        println!(
            "{}: {} files ({}) in {}",
            a.lang.name(),
            names.len(),
            names.join(", "),
            a.output.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
