//! `trisort`: bake fixed camera paths over a glTF scene into one depth-sorted index buffer with
//! a sliding window per frame, play it, verify it and measure it. See README.md.

mod cmd;
mod common;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = cmd::Cli::parse();
    match cmd::run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("trisort: error: {e:#}");
            ExitCode::from(1)
        }
    }
}
