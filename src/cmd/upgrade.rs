//! `trisort upgrade OLD -o NEW`: a baked file of an earlier format version rewritten in the
//! current one (docs/FORMAT.md § Compatibility policy).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;
use trisort_format::{Baked, FileKind, FORMAT_VERSION};

use crate::common::print_json;

/// Arguments of `upgrade`.
#[derive(Args, Debug)]
pub struct UpgradeArgs {
    /// The baked file to upgrade (this format version or one this trisort migrates).
    baked: PathBuf,
    /// Where to write it in the current format version (may be the input itself: it is read
    /// whole first and replaced atomically).
    #[arg(short, long)]
    output: PathBuf,
    /// Print the figures as JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(a: UpgradeArgs) -> Result<ExitCode> {
    let bytes =
        std::fs::read(&a.baked).with_context(|| format!("reading {}", a.baked.display()))?;
    let from = trisort_format::container::version_of(FileKind::Baked, &bytes);
    let baked: Baked = trisort_format::container::decode(FileKind::Baked, &bytes, &a.baked)?;
    baked
        .check_structure()
        .map_err(|e| anyhow::anyhow!("{}: malformed baked file: {e}", a.baked.display()))?;
    trisort_format::write_file_atomic(FileKind::Baked, &a.output, &baked)?;
    let from = from.unwrap_or(FORMAT_VERSION);
    if a.json {
        print_json(&serde_json::json!({
            "from_version": from,
            "to_version": FORMAT_VERSION,
            "frames": baked.frames.len(),
            "index_triangles": baked.copies.len(),
            "clips": baked.clips.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(),
        }));
    } else {
        let what = if from == FORMAT_VERSION {
            "already the current version; rewrote"
        } else {
            "migrated"
        };
        println!(
            "{}: format {from} → {FORMAT_VERSION} ({what}): {} frames, {} index triangles, \
             raster profile {}; wrote {}",
            a.baked.display(),
            baked.frames.len(),
            baked.copies.len(),
            baked.settings.robust.profile.name,
            a.output.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
