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
            eprintln!("trisort: error: {}", error_chain(&e));
            ExitCode::from(1)
        }
    }
}

/// The error and its causes joined by `: `, like anyhow's `{:#}`, but without a cause whose
/// text the message before it already ends with: the crates' errors name their cause in their
/// own message (`{path}: {source}`, so a host printing only `Display` sees it) and also expose
/// it as `source()`, which `{:#}` would print a second time.
fn error_chain(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if out.is_empty() {
            out = text;
        } else if !out.ends_with(&text) {
            out.push_str(": ");
            out.push_str(&text);
        }
    }
    out
}
