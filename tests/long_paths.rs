//! Long paths through the real binary: a synthetic 10,000-frame recording (the merger's
//! turntable simulation: objects orbited ten times, with transparency, occlusion and
//! interpenetration) cut into four frame ranges as four machines would record them, merged by
//! `trisort merge --segment 100`, and checked by `trisort verify`. Structural bounds are
//! asserted; time and memory are measured in BENCHMARKS.md § Long paths, never here.

use trisort_format::{Baked, FileKind};
use trisort_merger::synth::{split_frames, turntable, Turntable};

use crate::support::*;

const FRAMES: u32 = 10_000;

/// Runs the binary with `args`, under `/usr/bin/time -v` where it exists, and returns its
/// JSON output and a note of wall time and peak resident memory (for BENCHMARKS.md; never
/// asserted).
fn run_measured(dir: &std::path::Path, args: &[&str]) -> (serde_json::Value, String) {
    let timed = std::path::Path::new("/usr/bin/time").exists();
    let mut cmd = if timed {
        let mut c = std::process::Command::new("/usr/bin/time");
        c.arg("-v").arg(bin());
        c
    } else {
        std::process::Command::new(bin())
    };
    let t0 = std::time::Instant::now();
    let out = cmd.args(args).current_dir(dir).output().unwrap();
    let wall = t0.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "trisort {}: {stderr}", args.join(" "));
    let rss = stderr
        .lines()
        .find_map(|l| {
            l.trim()
                .strip_prefix("Maximum resident set size (kbytes): ")
        })
        .map_or("peak RSS not measured".to_string(), |k| {
            format!("peak RSS {k} kB")
        });
    let v = serde_json::from_slice(&out.stdout).unwrap();
    (v, format!("{wall:.2} s wall, {rss}"))
}
const SEGMENT: u32 = 100;

#[test]
fn ten_thousand_frames_from_four_recordings_merge_in_segments() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let rec = turntable(&Turntable {
        objects: 24,
        sides: 16,
        frames: FRAMES,
        samples: 128,
        degrees: 3600.0,
        ..Turntable::default()
    });
    let source: u64 = rec.frames.iter().map(|f| f.visible.len() as u64).sum();
    // Ranges of unequal length whose boundaries do not fall on segment boundaries.
    let parts = split_frames(&rec, &[0, 2_345, 5_000, 7_777]);
    let names: Vec<String> = (0..parts.len()).map(|k| format!("r{k}.rec")).collect();
    // Given out of order: the merger sorts them by frame range.
    for (k, p) in parts.iter().enumerate().rev() {
        trisort_format::write_file_atomic(FileKind::Recording, &d.join(&names[k]), p).unwrap();
    }
    let mut args: Vec<&str> = vec!["merge"];
    args.extend(names.iter().rev().map(String::as_str));
    let seg = SEGMENT.to_string();
    args.extend_from_slice(&[
        "-o",
        "long.baked",
        "--segment",
        &seg,
        "--strategy",
        "ibl",
        "--layout",
        "compact",
    ]);
    args.push("--json");
    let (v, measured) = run_measured(d, &args);
    eprintln!("10,000 frames through trisort merge ({measured}): {v}");
    let baked: Baked = trisort_format::read_file(FileKind::Baked, &d.join("long.baked")).unwrap();
    baked.check_structure().unwrap();
    let s = &baked.stats;
    assert_eq!(baked.frames.len() as u32, FRAMES);
    assert_eq!(v["frames"], FRAMES);
    assert_eq!(s.source_triangles, source, "Σ|V_f|");
    assert_eq!(s.unique_visible as usize, rec.unique_visible.len(), "|G|");
    // Copies: at least one per triangle of G, never more than one per visible (frame,
    // triangle) pair — the diagonal, one copy per frame, is always a valid fixed point.
    assert!(s.unique_visible <= s.index_triangles && s.index_triangles <= s.source_triangles);
    // Segments: no cell crosses a segment boundary, every cell holds a copy, and a frame's
    // window is a set of cells of its own segment, merged into at most SEGMENT ranges.
    for c in &baked.merge.cells {
        assert_eq!(c.first_frame / SEGMENT, c.last_frame / SEGMENT, "{c:?}");
        assert!(c.triangles > 0, "{c:?}");
    }
    let max_draws = baked.frames.iter().map(|w| w.count).max().unwrap();
    assert_eq!(max_draws, s.draws_per_frame_max);
    assert!(max_draws <= SEGMENT, "draws per frame {max_draws}");
    // Sparse: far fewer cells than the 100 × 5,050 of full upper-triangular matrices.
    let full = (FRAMES / SEGMENT) as usize * (SEGMENT * (SEGMENT + 1) / 2) as usize;
    assert!(
        baked.merge.cells.len() * 20 < full,
        "{} cells of {full}",
        baked.merge.cells.len()
    );
    // Every frame passes the graph rules against the four recordings.
    let mut verify: Vec<&str> = vec!["verify", "long.baked", "--recording"];
    verify.extend(names.iter().map(String::as_str));
    let report = run_json(d, &verify);
    assert_eq!(report["ok"], true, "{}", report["problems"]);
    assert_eq!(report["frames"].as_array().unwrap().len() as u32, FRAMES);
}

/// `merge` cuts paths into segments of 64 frames by default, so a path that turns the scene
/// around several times still draws at most 64 commands per frame; `--segment 0` asks for one
/// matrix over the whole path.
#[test]
fn merge_bounds_draws_per_frame_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let rec = turntable(&Turntable {
        objects: 12,
        sides: 16,
        frames: 300,
        samples: 64,
        degrees: 1080.0,
        ..Turntable::default()
    });
    trisort_format::write_file_atomic(FileKind::Recording, &d.join("t.rec"), &rec).unwrap();
    let v = run_json(d, &["merge", "t.rec", "-o", "default.baked"]);
    assert_eq!(v["segment"], 64, "{v}");
    assert!(v["draws_per_frame_max"].as_u64().unwrap() <= 64, "{v}");
    let one = run_json(d, &["merge", "t.rec", "-o", "one.baked", "--segment", "0"]);
    assert!(one["segment"].is_null(), "{one}");
    // On this path one matrix needs no more copies than its segments (the price of the bound).
    assert!(one["index_triangles"].as_u64() <= v["index_triangles"].as_u64());
}
