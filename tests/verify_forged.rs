//! Forged baked files: an honest bake of the demo car decoded, altered and
//! written back with the format's own writer (so its checksum is right), then given to the
//! real `trisort verify`. Each is rejected with exit code 3 and a message naming the frame and
//! the edge (or the figure) it forged; the recording alone decides what may be unordered.

use trisort_format::{Baked, DrawIndexedIndirectArgs, Edge, FileKind, Recording};

use crate::support::*;

const SCENE: &str = "demo:10000";

/// A test case of a JUnit file as a JUnit parser reads it.
#[derive(Debug)]
struct JunitCase {
    name: String,
    passed: bool,
    message: String,
}

/// The test cases of the JUnit XML at `path`, read by Python's junitparser (PyPI; CI installs
/// it: scripts/ensure-junitparser.sh), which checks the file is JUnit. `None` (a skip) when
/// junitparser is missing outside CI.
fn junit_cases(path: &std::path::Path) -> Option<Vec<JunitCase>> {
    let script = "import json, sys\n\
        from junitparser import JUnitXml\n\
        cases = []\n\
        for suite in JUnitXml.fromfile(sys.argv[1]):\n\
        \x20   for c in suite:\n\
        \x20       cases.append([c.name, c.is_passed, ' '.join(r.message or '' for r in c.result)])\n\
        print(json.dumps(cases))\n";
    let out = std::process::Command::new("python3")
        .args(["-c", script])
        .arg(path)
        .output()
        .expect("python3");
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        if err.contains("No module named 'junitparser'") && std::env::var_os("CI").is_none() {
            eprintln!("skipping the JUnit check: junitparser is missing (pip install junitparser)");
            return None;
        }
        panic!("junitparser could not read {}: {err}", path.display());
    }
    let cases: Vec<(String, bool, String)> = serde_json::from_slice(&out.stdout).unwrap();
    Some(
        cases
            .into_iter()
            .map(|(name, passed, message)| JunitCase {
                name,
                passed,
                message,
            })
            .collect(),
    )
}

/// An honest bake (the demo car, 3 frames, 64², 4×) in a temporary directory, as `car.baked`
/// with `car.baked.rec` beside it, decoded.
struct Honest {
    dir: tempfile::TempDir,
    baked: Baked,
    rec: Recording,
}

fn honest() -> Option<Honest> {
    let dir = gpu_tempdir()?;
    let bake = format!(
        "bake {SCENE} --path orbit:frames=3,degrees=60 --size 64x64 --samples 4 -o car.baked"
    );
    run(dir.path(), &args(&bake), true);
    run(
        dir.path(),
        &args("verify car.baked --recording car.baked.rec --junit honest.xml"),
        true,
    );
    // The JUnit report of the honest file: a passing case per frame and the whole file.
    if let Some(cases) = junit_cases(&dir.path().join("honest.xml")) {
        let names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            ["frame 0", "frame 1", "frame 2", "graph rules (whole file)"]
        );
        assert!(cases.iter().all(|c| c.passed), "{cases:?}");
    }
    let baked = trisort_format::read_file(FileKind::Baked, &dir.path().join("car.baked")).unwrap();
    let rec =
        trisort_format::read_file(FileKind::Recording, &dir.path().join("car.baked.rec")).unwrap();
    Some(Honest { dir, baked, rec })
}

impl Honest {
    /// Writes `forged` as `NAME.baked`, runs `verify NAME.baked --recording car.baked.rec`
    /// plus `extra`, and checks that it fails with exit code 3 and prints every one of
    /// `needles`. Returns stdout.
    fn rejected(&self, name: &str, forged: &Baked, extra: &[&str], needles: &[&str]) -> String {
        let file = format!("{name}.baked");
        trisort_format::write_file_atomic(FileKind::Baked, &self.dir.path().join(&file), forged)
            .unwrap();
        let mut cmd = vec!["verify", &file, "--recording", "car.baked.rec"];
        cmd.extend_from_slice(extra);
        let out = run(self.dir.path(), &cmd, false);
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        let ctx = format!(
            "{name}: {}\n{stdout}\n{}",
            cmd.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(out.status.code(), Some(3), "{ctx}");
        for needle in needles {
            assert!(stdout.contains(needle), "no {needle:?} in {ctx}");
        }
        eprintln!("{name}: {}", first_problem(&stdout));
        stdout
    }

    /// G-local id of scene triangle `t`.
    fn local(&self, t: u32) -> u32 {
        self.baked.scene_ids.binary_search(&t).unwrap() as u32
    }

    /// Frame f's edges of E_f the file keeps, in G-local ids.
    fn kept(&self, f: usize) -> Vec<Edge> {
        let removed = &self.baked.removed_edges[f];
        self.rec.frames[f]
            .edges
            .iter()
            .map(|e| Edge {
                from: self.local(e.from),
                to: self.local(e.to),
                weight: e.weight,
            })
            .filter(|e| !removed.iter().any(|r| (r.from, r.to) == (e.from, e.to)))
            .collect()
    }
}

/// The first problem verify printed under its graph verdict (for the log of what each
/// forgery produces).
fn first_problem(stdout: &str) -> &str {
    let mut lines = stdout
        .lines()
        .skip_while(|l| !l.starts_with("graph rules:"));
    lines.nth(1).unwrap_or("").trim()
}

/// Per frame, the positions in `copies` it draws, in draw order.
fn drawn(b: &Baked, f: usize) -> Vec<usize> {
    b.frame_draws(f)
        .iter()
        .flat_map(|d| (d.first_index / 3..(d.first_index + d.index_count) / 3).map(|p| p as usize))
        .collect()
}

/// Rebuilds the draw list from per-frame draws and sets the draw statistics to match.
fn set_draws(b: &mut Baked, per_frame: Vec<Vec<DrawIndexedIndirectArgs>>) {
    b.draws.clear();
    for (f, draws) in per_frame.into_iter().enumerate() {
        b.frames[f].first = b.draws.len() as u32;
        b.frames[f].count = draws.len() as u32;
        b.draws.extend(draws);
    }
    let counts: Vec<u32> = b.frames.iter().map(|w| w.count).collect();
    b.stats.draws_per_frame_max = counts.iter().copied().max().unwrap_or(0);
    b.stats.draws_per_frame_mean =
        counts.iter().map(|&c| c as f64).sum::<f64>() / counts.len().max(1) as f64;
}

fn range(first_copy: usize, count: usize) -> DrawIndexedIndirectArgs {
    DrawIndexedIndirectArgs {
        index_count: 3 * count as u32,
        instance_count: 1,
        first_index: 3 * first_copy as u32,
        base_vertex: 0,
        first_instance: 0,
    }
}

#[test]
fn an_edge_on_no_cycle_listed_as_removed_is_rejected() {
    let Some(h) = honest() else { return };
    // The heaviest kept edge of frame 1: nothing forced it out.
    let e = *h.kept(1).iter().max_by_key(|e| e.weight).unwrap();
    let mut forged = h.baked.clone();
    forged.removed_edges[1].push(e);
    forged.stats.unordered_samples += e.weight as u64;
    let (a, b) = (
        h.baked.scene_ids[e.from as usize],
        h.baked.scene_ids[e.to as usize],
    );
    let needle = format!(
        "frame 1: removed edge {a}→{b} (scene ids, weight {}) lies on no cycle of E_f",
        e.weight
    );
    h.rejected("acyclic", &forged, &[], &[&needle]);
}

/// The forgery of the issue: every edge of every frame listed as removed (with the right
/// weights and total) and the whole index buffer reversed, so every frame draws back to
/// front. The graph rules name the edges; the image check (its unordered pixels from the
/// recording) shows the wrong pixels; the image check alone excuses nothing either.
#[test]
fn every_edge_removed_and_the_cells_reversed_is_rejected() {
    let Some(h) = honest() else { return };
    let mut forged = h.baked.clone();
    for f in 0..forged.frames.len() {
        forged.removed_edges[f] = h.rec.frames[f]
            .edges
            .iter()
            .map(|e| Edge {
                from: h.local(e.from),
                to: h.local(e.to),
                weight: e.weight,
            })
            .collect();
    }
    forged.stats.unordered_samples = forged
        .removed_edges
        .iter()
        .flatten()
        .map(|e| e.weight as u64)
        .sum();
    let forged = cells_reversed(&forged);
    let out = h.rejected(
        "every-edge",
        &forged,
        &[],
        &["frame 0: removed edge", "lies on no cycle of E_f"],
    );
    assert!(out.contains("graph rules: FAILED"), "{out}");
    // Images with the recording: frame 0 is wrong where nothing excuses it.
    let images = [
        "--scene",
        SCENE,
        "--frames",
        "0..1",
        "--json",
        "--junit",
        "forged.xml",
    ];
    let out = h.rejected("every-edge", &forged, &images, &[]);
    if let Some(cases) = junit_cases(&h.dir.path().join("forged.xml")) {
        let frame0 = cases.iter().find(|c| c.name == "frame 0").expect("frame 0");
        assert!(!frame0.passed, "{cases:?}");
        assert!(
            frame0.message.contains("graph rules") && frame0.message.contains("images"),
            "{frame0:?}"
        );
        // Every frame lost its edges: each fails its graph rules (images: frame 0 only).
        assert!(
            cases
                .iter()
                .filter(|c| c.name.starts_with("frame "))
                .all(|c| !c.passed && c.message.contains("order violations")),
            "{cases:?}"
        );
    }
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let f = &v["frames"][0];
    assert_eq!(f["ok"], false, "{f}");
    assert!(f["pixels_differing_ordered"].as_u64().unwrap() > 0, "{f}");
    // Every triangle is drawn, in the wrong order: order errors, no hole.
    assert_eq!(f["hole_pixels"], 0, "{f}");
    assert!(f["order_error_pixels"].as_u64().unwrap() > 0, "{f}");
    eprintln!(
        "every-edge images: frame 0 {} pixels differ on ordered pixels, by up to {}/255; {} unordered samples",
        f["pixels_differing_ordered"], f["max_channel_diff_ordered"], f["unordered_samples"]
    );
    // The image check alone (no recording) excuses no pixel.
    let out = run(
        h.dir.path(),
        &[
            "verify",
            "every-edge.baked",
            "--scene",
            SCENE,
            "--frames",
            "0..1",
        ],
        false,
    );
    assert_eq!(out.status.code(), Some(3));
}

/// Two draw ranges of frame 0 in reverse order, so that a kept edge a → b has b drawn first.
#[test]
fn swapped_cells_are_rejected() {
    let Some(h) = honest() else { return };
    let order = drawn(&h.baked, 0);
    let position = |t: u32| order.iter().position(|&p| h.baked.copies[p] == t);
    let (e, pa, pb) = h
        .kept(0)
        .into_iter()
        .filter_map(|e| Some((e, position(e.from)?, position(e.to)?)))
        .max_by_key(|x| x.0.weight)
        .expect("frame 0 keeps an edge between drawn triangles");
    assert!(pa < pb, "front drawn before back");
    // Frame 0 as one run per draw; cut the run holding b at b, then swap the run holding a
    // with the run starting at b.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for d in h.baked.frame_draws(0) {
        let (s, c) = ((d.first_index / 3) as usize, (d.index_count / 3) as usize);
        let cut = order[pb];
        if (s..s + c).contains(&cut) && cut > s {
            runs.extend([(s, cut - s), (cut, s + c - cut)]);
        } else {
            runs.push((s, c));
        }
    }
    let run_of = |p: usize| {
        runs.iter()
            .position(|&(s, c)| (s..s + c).contains(&p))
            .unwrap()
    };
    let (ra, rb) = (run_of(order[pa]), run_of(order[pb]));
    runs.swap(ra, rb);
    let mut forged = h.baked.clone();
    let mut per_frame: Vec<Vec<_>> = (0..forged.frames.len())
        .map(|f| forged.frame_draws(f).to_vec())
        .collect();
    per_frame[0] = runs.iter().map(|&(s, c)| range(s, c)).collect();
    set_draws(&mut forged, per_frame);
    let (a, b) = (
        h.baked.scene_ids[e.from as usize],
        h.baked.scene_ids[e.to as usize],
    );
    h.rejected("swapped", &forged, &[], &["frame 0: order ", "is violated"]);
    eprintln!("swapped: moved {a}→{b} out of order");
}

#[test]
fn a_changed_camera_is_rejected() {
    let Some(h) = honest() else { return };
    let mut forged = h.baked.clone();
    forged.frame_states[2].camera.view[12] += 0.25;
    h.rejected(
        "camera",
        &forged,
        &[],
        &["frame 2: the baked camera differs from recording 0's"],
    );
}

#[test]
fn forged_statistics_are_rejected() {
    let Some(h) = honest() else { return };
    type Edit = fn(&mut Baked);
    let cases: [(&str, Edit, &str); 6] = [
        (
            "index",
            |b| b.stats.index_triangles /= 2,
            "statistic index_triangles: the file states",
        ),
        (
            "draws-max",
            |b| b.stats.draws_per_frame_max = 1,
            "statistic draws_per_frame_max",
        ),
        (
            "draws-mean",
            |b| b.stats.draws_per_frame_mean *= 0.5,
            "statistic draws_per_frame_mean",
        ),
        (
            "fill",
            |b| b.stats.drawn_not_visible_mean += 1.0,
            "statistic drawn_not_visible_mean",
        ),
        (
            "unordered",
            |b| b.stats.unordered_samples += 7,
            "statistic unordered_samples",
        ),
        (
            "source",
            |b| b.stats.source_triangles -= 1,
            "statistic source_triangles",
        ),
    ];
    for (name, edit, needle) in cases {
        let mut forged = h.baked.clone();
        edit(&mut forged);
        if forged.stats == h.baked.stats {
            continue;
        }
        h.rejected(name, &forged, &[], &[needle]);
    }
}

/// A file that names another recording device is checked, not measured: with its
/// device renamed and its index buffer reversed, `verify --scene` alone (no recording to take
/// the device from) fails it (exit 3), saying it played on another device at the recorded
/// pattern. The honest file with the renamed device still passes.
#[test]
fn a_renamed_device_does_not_wave_a_wrong_file_through() {
    let Some(h) = honest() else { return };
    let mut renamed = h.baked.clone();
    renamed.device.adapter.push_str(" (renamed)");
    let mut forged = renamed.clone();
    forged.copies.reverse();
    let d = h.dir.path();
    for (name, file) in [("renamed", &renamed), ("reversed", &forged)] {
        trisort_format::write_file_atomic(FileKind::Baked, &d.join(format!("{name}.baked")), file)
            .unwrap();
    }
    let images = |name: &str, ok: bool| {
        let file = format!("{name}.baked");
        let out = run(
            d,
            &[
                "verify", &file, "--scene", SCENE, "--mode", "depth", "--json",
            ],
            ok,
        );
        if !ok {
            assert_eq!(out.status.code(), Some(3), "{name}");
        }
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["at_recorded_pattern"], true, "{name}: {v}");
        assert_eq!(v["played_on_recording_device"], false, "{name}: {v}");
        v
    };
    images("renamed", true);
    let v = images("reversed", false);
    assert_eq!(v["images_ok"], false, "{v}");
}

/// The same cells reversed (every copy's position mirrored, every frame's draws in reverse
/// order), nothing else changed.
fn cells_reversed(b: &Baked) -> Baked {
    let mut forged = b.clone();
    let n = forged.copies.len() as u32;
    forged.copies.reverse();
    for d in &mut forged.draws {
        d.first_index = 3 * n - d.first_index - d.index_count;
    }
    let per_frame: Vec<Vec<_>> = (0..forged.frames.len())
        .map(|f| forged.frame_draws(f).iter().rev().copied().collect())
        .collect();
    set_draws(&mut forged, per_frame);
    forged
}

/// Issue 28: a depth-only file is checked for the mode it plays in. A legitimate
/// `merge --depth-only` passes graph and images in depth mode (the demo car's glass is
/// translucent: what lies behind it must be drawn after it even with the depth test), fails
/// as a blend file, and the file that claims depth-only with every cell reversed fails both.
#[test]
fn a_depth_only_file_is_checked_for_the_mode_it_plays_in() {
    let Some(h) = honest() else { return };
    let d = h.dir.path();
    run(
        d,
        &args("merge car.baked.rec --depth-only -o depth.baked"),
        true,
    );
    let depth = run_json(
        d,
        &args(&format!(
            "verify depth.baked --recording car.baked.rec --scene {SCENE} --mode depth"
        )),
    );
    assert_eq!(depth["ok"], true, "{depth}");
    assert_eq!(depth["graph_check"], "depth", "{depth}");
    assert_eq!(depth["depth_only"], true, "{depth}");
    assert_eq!(depth["image_check"], "recorded_pattern", "{depth}");
    for f in depth["frames"].as_array().unwrap() {
        assert_eq!(
            f["pixels_differing"], 0,
            "depth mode, a legitimate depth-only bake: {f}"
        );
    }
    // As a blend file its order is checked against every edge of E_f, and fails.
    let depth_only: Baked =
        trisort_format::read_file(FileKind::Baked, &d.join("depth.baked")).unwrap();
    let out = h.rejected("depth-only-as-blend", &depth_only, &[], &["is violated"]);
    assert!(out.contains("a depth-only file checked for blend"), "{out}");
    // The honest file's cells reversed, claiming depth-only: fails in blend and depth mode.
    let mut forged = cells_reversed(&h.baked);
    forged.merge.depth_only = true;
    h.rejected("depth-only-reversed", &forged, &[], &["is violated"]);
    h.rejected(
        "depth-only-reversed",
        &forged,
        &["--mode", "depth"],
        &["is violated"],
    );
}

/// Issue 28: what the file says of its merge and path and the recording decides is checked:
/// the matrix cells against the frames that draw each copy, the frame rate against the
/// recording's.
#[test]
fn forged_cells_and_frame_rate_are_rejected() {
    let Some(h) = honest() else { return };
    let mut cells = h.baked.clone();
    let c = cells
        .merge
        .cells
        .iter()
        .position(|c| c.first_frame < c.last_frame)
        .expect("a cell spans frames");
    cells.merge.cells[c].last_frame -= 1;
    h.rejected("cells", &cells, &[], &[&format!("its merge cell {c} says")]);
    let mut gap = h.baked.clone();
    gap.merge.cells.pop();
    h.rejected("cells-short", &gap, &[], &["the merge cells cover copies"]);
    let mut fps = h.baked.clone();
    fps.fps = Some(fps.fps.unwrap_or(30.0) * 2.0);
    h.rejected("fps", &fps, &[], &["the frame rate"]);
}

/// Issue 28: the stored light is a claim too. The built-in studio is made anew and compared
/// by `verify --recording` and by `verify --environment studio`; a moved sun fails both.
#[test]
fn a_forged_sun_is_rejected() {
    let Some(h) = honest() else { return };
    let d = h.dir.path();
    let v = run_json(d, &args("verify car.baked --environment studio"));
    assert_eq!(v["ok"], true, "{v}");
    assert_eq!(v["environment"]["checked"], "given", "{v}");
    let mut forged = h.baked.clone();
    let sun = forged
        .environment
        .sun
        .as_mut()
        .expect("the studio has a sun");
    sun.direction = [0.0, -1.0, 0.0];
    h.rejected(
        "sun",
        &forged,
        &[],
        &["claims to be the built-in studio but differs: sun"],
    );
    let out = run(d, &args("verify sun.baked --environment studio"), false);
    assert_eq!(out.status.code(), Some(3));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("environment: FAILED"), "{text}");
}
