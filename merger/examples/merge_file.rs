//! Benchmark (not a test): merges recording files (as `trisort record` writes them) with each
//! strategy × layout separately, optionally validates, and prints the figures and times.
//!
//! `cargo run --release -p trisort-merger --example merge_file -- REC... [--strategy S|all]
//! [--layout paper|compact|all] [--bridge hidden|ignored|visible] [--seeding interval|paper]
//! [--segment N (0: one matrix)] [--auto] [--verify]`
//!
//! Options not given take the merge's defaults ([`MergeOptions::default`]). `--auto` also
//! runs the library's own `auto` (every combination at once, as the CLI does). The last
//! column, `digest`, hashes everything a bake holds but its statistics (copies, draws,
//! windows, cells, removed edges): equal digests from two versions of the merger mean
//! identical bakes up to `stats`.

use std::path::PathBuf;
use std::str::FromStr;
use std::time::Instant;

use trisort_format::{Baked, FileKind, Recording};
use trisort_merger::{merge, Choice, Layout, MergeOptions, Strategy};

/// `all` (every value) or one value's name; exits with the parse error otherwise.
fn one_or_all<T: Copy + FromStr<Err = trisort_format::ParseOptionError>>(
    v: &str,
    all: &[T],
) -> Vec<T> {
    if v == "all" {
        return all.to_vec();
    }
    vec![parse(v)]
}

fn parse<T: FromStr<Err = trisort_format::ParseOptionError>>(v: &str) -> T {
    v.parse().unwrap_or_else(|e| {
        eprintln!("merge_file: {e}");
        std::process::exit(2)
    })
}

fn main() {
    let mut files = Vec::new();
    let mut strategies: Vec<Strategy> = Strategy::ALL.to_vec();
    let mut layouts: Vec<Layout> = Layout::ALL.to_vec();
    let mut base = MergeOptions::default();
    let (mut auto, mut verify) = (false, false);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().expect("option needs a value");
        match a.as_str() {
            "--strategy" => strategies = one_or_all(&value(), &Strategy::ALL),
            "--layout" => layouts = one_or_all(&value(), &Layout::ALL),
            "--bridge" => base.bridge = parse(&value()),
            "--seeding" => base.seeding = parse(&value()),
            "--segment" => {
                let n: u32 = value().parse().expect("segment");
                base.segment = (n > 0).then_some(n);
            }
            "--auto" => auto = true,
            "--verify" => verify = true,
            _ => files.push(PathBuf::from(a)),
        }
    }
    let t0 = Instant::now();
    let recs: Vec<Recording> = files
        .iter()
        .map(|f| trisort_format::read_file(FileKind::Recording, f).expect("read recording"))
        .collect();
    println!(
        "read {} recording(s) in {:.2} s",
        recs.len(),
        t0.elapsed().as_secs_f64()
    );
    println!("seeding  bridge  strategy layout  | index/|G| index  draws mean  max | drawn-not-vis unordered | seconds | valid | digest");
    let mut runs: Vec<MergeOptions> = Vec::new();
    for &s in &strategies {
        for &l in &layouts {
            runs.push(MergeOptions {
                strategy: Choice::Only(s),
                layout: Choice::Only(l),
                ..base
            });
        }
    }
    if auto {
        runs.push(MergeOptions {
            strategy: Choice::Auto,
            layout: Choice::Auto,
            ..base
        });
    }
    for opts in runs {
        let t = Instant::now();
        let b = merge(&recs, &opts)
            .expect("merge")
            .lit(trisort_format::Environment::uniform(1.0));
        let secs = t.elapsed().as_secs_f64();
        let valid = if verify {
            let r = trisort_verify::check_graph(&recs, &b);
            if r.ok {
                "ok".to_string()
            } else {
                format!("FAIL {:?}", r.problems.first())
            }
        } else {
            "-".to_string()
        };
        let s = &b.stats;
        println!(
            "{:8} {:7} {:8} {:7} | {:9.3} {:6} {:10.1} {:4} | {:13.1} {:9} | {:7.2} | {}{} | {}",
            b.merge.seeding,
            b.merge.bridge,
            b.merge.strategy,
            b.merge.layout,
            s.index_triangles as f64 / s.unique_visible as f64,
            s.index_triangles,
            s.draws_per_frame_mean,
            s.draws_per_frame_max,
            s.drawn_not_visible_mean,
            s.unordered_samples,
            secs,
            valid,
            if opts.strategy == Choice::Auto {
                " (auto)"
            } else {
                ""
            },
            digest(&b)
        );
    }
}

/// The first 16 hex digits of the hash of a bake's content without its statistics.
fn digest(b: &Baked) -> String {
    let content = format!(
        "{:?}{:?}{:?}{:?}{:?}",
        b.copies, b.draws, b.frames, b.merge, b.removed_edges
    );
    let hash = trisort_format::hash_bytes(content.as_bytes());
    hash.iter().take(8).map(|x| format!("{x:02x}")).collect()
}
