//! The merger against the independent validator: random graphs, hand-made cases, mutations,
//! determinism and long synthetic paths.

use crate::merge;
use proptest::prelude::*;
use proptest::strategy::Strategy as _;
use trisort_format::{Baked, Recording};
use trisort_merger::synth::{recording_from_frames, split_frames, turntable, FrameSpec, Turntable};
use trisort_merger::{Bridge, Choice, Layout, MergeOptions, Seeding, Strategy};
use trisort_verify::{check_graph, check_graph_for, PlayedIn};

fn opts(strategy: Strategy, layout: Layout, bridge: Bridge, seeding: Seeding) -> MergeOptions {
    MergeOptions {
        strategy: Choice::Only(strategy),
        layout: Choice::Only(layout),
        bridge,
        seeding,
        ..MergeOptions::default()
    }
}

/// Fails with the validator's findings unless the file passes.
fn assert_valid(recs: &[Recording], baked: &Baked, what: &str) {
    // A depth-only file is made for depth mode (and checked for it).
    let played = if baked.merge.depth_only {
        PlayedIn::Depth
    } else {
        PlayedIn::Blend
    };
    let report = check_graph_for(recs, baked, played);
    assert!(
        report.ok,
        "{what}: {:?}\nframes: {:?}",
        report.problems,
        report
            .frames
            .iter()
            .filter(|f| !f.ok())
            .take(5)
            .collect::<Vec<_>>()
    );
    let s = &baked.stats;
    assert!(
        s.unique_visible <= s.index_triangles && s.index_triangles <= s.source_triangles,
        "{what}: {s:?}"
    );
}

/// Every strategy × layout × bridge × seeding passes the validator.
fn assert_all_valid(recs: &[Recording], what: &str) {
    for s in Strategy::ALL {
        for l in Layout::ALL {
            for b in [Bridge::Hidden, Bridge::Ignored, Bridge::Visible] {
                for seeding in [Seeding::Interval, Seeding::Paper] {
                    let baked = merge(recs, &opts(s, l, b, seeding)).expect("merge");
                    assert_valid(
                        recs,
                        &baked,
                        &format!("{what} {s:?} {l:?} {b:?} {seeding:?}"),
                    );
                }
            }
        }
    }
}

/// Random per-frame graphs over a few triangles: random visibility, hidden and never-covered
/// triangles, edges among covered triangles (chains through hidden ones), intra-frame cycles.
fn random_frames() -> impl proptest::strategy::Strategy<Value = Vec<FrameSpec>> {
    let frame = (
        proptest::collection::vec(0u8..4, 8),
        proptest::collection::vec((0u32..8, 0u32..8, 1u32..9, any::<bool>()), 0..14),
    )
        .prop_map(|(state, raw)| {
            // 0: not covered, 1: hidden, 2–3: visible.
            let visible: Vec<u32> = (0..8).filter(|&t| state[t as usize] >= 2).collect();
            let hidden: Vec<u32> = (0..8).filter(|&t| state[t as usize] == 1).collect();
            let covered = |t: u32| state[t as usize] >= 1;
            let edges: Vec<(u32, u32, u32)> = raw
                .iter()
                .filter(|e| e.0 != e.1 && covered(e.0) && covered(e.1))
                .map(|e| (e.0, e.1, e.2))
                .collect();
            let ties = raw
                .iter()
                .filter(|e| e.3 && e.0 < e.1 && covered(e.0) && covered(e.1))
                .map(|e| (e.0, e.1, e.2))
                .collect();
            FrameSpec {
                visible,
                hidden,
                edges,
                ties,
            }
        });
    proptest::collection::vec(frame, 1..6)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn random_graphs_pass_the_validator(frames in random_frames(), cut in 0usize..6) {
        prop_assume!(frames.iter().any(|f| !f.visible.is_empty()));
        let rec = recording_from_frames(8, &frames);
        let recs = if cut > 0 && cut < frames.len() { split_frames(&rec, &[0, cut as u32]) } else { vec![rec] };
        assert_all_valid(&recs, "random");
        let depth = MergeOptions { depth_only: true, ..MergeOptions::default() };
        let baked = merge(&recs, &depth).expect("merge");
        assert_valid(&recs, &baked, "depth-only");
        for seeding in [Seeding::Interval, Seeding::Paper] {
            let seg = MergeOptions { segment: Some(2), seeding, ..MergeOptions::default() };
            let baked = merge(&recs, &seg).expect("merge");
            assert_valid(&recs, &baked, "segments of 2");
            assert!(baked.merge.cells.iter().all(|c| c.first_frame / 2 == c.last_frame / 2));
        }
    }
}

/// A stack of transparent triangles seen from the front, then (from frame 4 on) from behind:
/// the order inverts, so no copy can span both halves.
#[test]
fn camera_turning_180_degrees_forces_splits() {
    let n = 5u32;
    let frames: Vec<FrameSpec> = (0..8)
        .map(|f| {
            let chain: Vec<u32> = if f < 4 {
                (0..n).collect()
            } else {
                (0..n).rev().collect()
            };
            FrameSpec {
                visible: (0..n).collect(),
                edges: chain.windows(2).map(|w| (w[0], w[1], 3)).collect(),
                ..FrameSpec::default()
            }
        })
        .collect();
    let rec = recording_from_frames(n, &frames);
    for s in Strategy::ALL {
        for l in Layout::ALL {
            for seeding in [Seeding::Interval, Seeding::Paper] {
                let baked = merge(
                    std::slice::from_ref(&rec),
                    &opts(s, l, Bridge::Hidden, seeding),
                )
                .unwrap();
                assert_valid(std::slice::from_ref(&rec), &baked, "180°");
                // One triangle may keep a single copy (the cycle needs two), the rest need two.
                assert!(
                    baked.stats.index_triangles >= 2 * n as u64 - 1,
                    "{s:?} {l:?}: {:?}",
                    baked.stats
                );
            }
        }
    }
    // Interval splitting splits exactly at the inversion: two copies per triangle at most.
    let baked = merge(std::slice::from_ref(&rec), &MergeOptions::default()).unwrap();
    assert!(
        baked.stats.index_triangles <= 2 * n as u64,
        "{:?}",
        baked.stats
    );
}

/// A real turntable turning 180°: every combination validates.
#[test]
fn turntable_half_turn_validates() {
    let rec = turntable(&Turntable {
        objects: 6,
        sides: 8,
        frames: 10,
        samples: 64,
        degrees: 180.0,
        ..Turntable::default()
    });
    assert!(
        rec.frames.iter().any(|f| f.covered.len() > f.visible.len()),
        "some hidden triangles"
    );
    assert_all_valid(std::slice::from_ref(&rec), "turntable");
}

/// The merger leaves the light to its caller: [`trisort_merger::Merged::lit`] stores the
/// light it is given, changes nothing else, and the result passes a reader's structure check.
#[test]
fn merged_files_take_the_light_they_are_given() {
    let rec = turntable(&Turntable {
        objects: 2,
        sides: 6,
        frames: 3,
        ..Turntable::default()
    });
    let merged =
        trisort_merger::merge(std::slice::from_ref(&rec), &MergeOptions::default()).expect("merge");
    let dim = trisort_format::Environment::uniform(0.5);
    let bright = trisort_format::Environment::uniform(2.0);
    let a = merged.clone().lit(dim.clone());
    a.check_structure().expect("structure");
    assert_eq!(a.environment, dim);
    let b = merged.lit(bright.clone());
    assert_eq!(b.environment, bright);
    assert_eq!(
        Baked {
            environment: bright,
            ..a
        },
        b
    );
}

/// Three triangles overlapping cyclically in one frame: the lightest edge is removed and its
/// weight reported as unordered samples.
#[test]
fn three_triangle_cyclic_overlap() {
    let frames = vec![FrameSpec {
        visible: vec![0, 1, 2],
        edges: vec![(0, 1, 5), (1, 2, 4), (2, 0, 1)],
        ..FrameSpec::default()
    }];
    let rec = recording_from_frames(3, &frames);
    let baked = merge(std::slice::from_ref(&rec), &MergeOptions::default()).unwrap();
    assert_valid(std::slice::from_ref(&rec), &baked, "cycle");
    assert_eq!(
        baked.removed_edges,
        vec![vec![trisort_format::Edge {
            from: 2,
            to: 0,
            weight: 1
        }]]
    );
    assert_eq!(baked.stats.unordered_samples, 1);
    assert_eq!(baked.copies, vec![0, 1, 2]);
    let report = check_graph(std::slice::from_ref(&rec), &baked);
    assert_eq!(report.frames[0].unordered_samples, 1);
}

/// a → h → b with h hidden (not drawn under `--bridge ignored`) still orders a before b, even
/// though another frame puts b in front of a.
#[test]
fn order_through_an_undrawn_triangle() {
    let (a, h, b) = (0, 1, 2);
    let frames = vec![
        FrameSpec {
            visible: vec![a, b],
            hidden: vec![h],
            edges: vec![(a, h, 2), (h, b, 2)],
            ..FrameSpec::default()
        },
        FrameSpec {
            visible: vec![a, b],
            edges: vec![(b, a, 2)],
            ..FrameSpec::default()
        },
        FrameSpec {
            visible: vec![h],
            ..FrameSpec::default()
        },
    ];
    let rec = recording_from_frames(3, &frames);
    for s in Strategy::ALL {
        for l in Layout::ALL {
            let baked = merge(
                std::slice::from_ref(&rec),
                &opts(s, l, Bridge::Ignored, Seeding::Interval),
            )
            .unwrap();
            assert_valid(std::slice::from_ref(&rec), &baked, "a→h→b");
            let order: Vec<u32> = baked
                .frame_draws(0)
                .iter()
                .flat_map(|d| {
                    baked.copies[(d.first_index / 3) as usize..][..(d.index_count / 3) as usize]
                        .to_vec()
                })
                .collect();
            assert_eq!(
                order,
                vec![a, b],
                "{s:?} {l:?}: h must not be drawn and a must precede b"
            );
        }
    }
}

/// Corrupting a valid file's order, dropping a visible triangle or misreporting the removed
/// weight makes the validator fail.
#[test]
fn validator_catches_mutations() {
    let rec = turntable(&Turntable {
        objects: 8,
        sides: 10,
        frames: 8,
        samples: 96,
        degrees: 60.0,
        ..Turntable::default()
    });
    let recs = std::slice::from_ref(&rec);
    let baked = merge(recs, &MergeOptions::default()).unwrap();
    assert_valid(recs, &baked, "original");

    // Swap the copies of a kept edge's endpoints drawn in frame f.
    let frame_order = |b: &Baked, f: usize| -> Vec<usize> {
        b.frame_draws(f)
            .iter()
            .flat_map(|d| {
                (d.first_index / 3) as usize..((d.first_index + d.index_count) / 3) as usize
            })
            .collect()
    };
    let mut swapped = false;
    'search: for (f, fr) in rec.frames.iter().enumerate() {
        let order = frame_order(&baked, f);
        let local = |t: u32| baked.scene_ids.binary_search(&t).unwrap() as u32;
        for e in &fr.edges {
            let (a, b) = (local(e.from), local(e.to));
            if baked.removed_edges[f]
                .iter()
                .any(|r| (r.from, r.to) == (a, b))
            {
                continue;
            }
            let ka = order.iter().copied().find(|&k| baked.copies[k] == a);
            let kb = order.iter().copied().find(|&k| baked.copies[k] == b);
            if let (Some(ka), Some(kb)) = (ka, kb) {
                let mut bad = baked.clone();
                bad.copies.swap(ka, kb);
                let report = check_graph(recs, &bad);
                assert!(
                    !report.ok && report.frames[f].graph_violations > 0,
                    "swap not caught"
                );
                swapped = true;
                break 'search;
            }
        }
    }
    assert!(swapped, "no edge between drawn triangles to swap");

    // Drop the last copy of a draw whose triangle is visible there.
    let mut dropped = false;
    'drop: for f in 0..baked.frames.len() {
        let w = baked.frames[f];
        for d in w.first..w.first + w.count {
            let draw = baked.draws[d as usize];
            let last = baked.copies[((draw.first_index + draw.index_count) / 3 - 1) as usize];
            let scene = baked.scene_ids[last as usize];
            if rec.frames[f].visible.binary_search(&scene).is_ok() {
                let mut bad = baked.clone();
                bad.draws[d as usize].index_count -= 3;
                let report = check_graph(recs, &bad);
                assert!(
                    !report.ok && report.frames[f].visible_missing > 0,
                    "drop not caught"
                );
                dropped = true;
                break 'drop;
            }
        }
    }
    assert!(dropped);

    // Misreported unordered samples.
    let mut bad = baked.clone();
    bad.stats.unordered_samples += 1;
    assert!(!check_graph(recs, &bad).ok);
    // A removed edge that is not in the recording.
    let mut bad = baked.clone();
    bad.removed_edges[0].push(trisort_format::Edge {
        from: 0,
        to: 0,
        weight: 0,
    });
    assert!(!check_graph(recs, &bad).ok);
    // A different recording.
    let other = turntable(&Turntable {
        objects: 8,
        sides: 10,
        frames: 8,
        samples: 96,
        degrees: 60.0,
        seed: 9,
        ..Turntable::default()
    });
    assert!(!check_graph(std::slice::from_ref(&other), &baked).ok);
}

/// The same inputs give the same bytes with one and with two worker threads, and from
/// recordings cut into frame ranges given in any order.
#[test]
fn deterministic_across_thread_counts() {
    let rec = turntable(&Turntable {
        objects: 10,
        sides: 12,
        frames: 12,
        samples: 96,
        degrees: 120.0,
        ..Turntable::default()
    });
    let parts = split_frames(&rec, &[0, 5, 9]);
    let run = |threads: usize, recs: &[Recording]| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let baked = pool.install(|| merge(recs, &MergeOptions::default()).unwrap());
        trisort_format::container::encode(trisort_format::FileKind::Baked, &baked)
    };
    let one = run(1, &parts);
    let two = run(2, &parts);
    assert_eq!(one, two);
    let reversed: Vec<Recording> = parts.iter().rev().cloned().collect();
    assert_eq!(run(2, &reversed), one);
}

/// Mismatched recordings are refused, naming the recording.
#[test]
fn mismatched_recordings_are_refused() {
    let rec = turntable(&Turntable {
        objects: 4,
        sides: 10,
        frames: 6,
        samples: 64,
        ..Turntable::default()
    });
    let mut parts = split_frames(&rec, &[0, 3]);
    parts[1].path_hash[0] ^= 1;
    let e = merge(&parts, &MergeOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains("recording 1") && e.to_string().contains("path hash"),
        "{e}"
    );
    let parts = split_frames(&rec, &[0, 3]);
    let e = merge(&parts[1..], &MergeOptions::default()).unwrap_err();
    assert!(e.to_string().contains("comes next"), "{e}");
    let mut bad = rec.clone();
    bad.frames[0].visible.reverse();
    assert!(bad.frames[0].visible.len() >= 2);
    let e = merge(std::slice::from_ref(&bad), &MergeOptions::default()).unwrap_err();
    assert!(e.to_string().contains("recording 0 is malformed"), "{e}");
    let e = merge(&parts[..1], &MergeOptions::default()).unwrap_err();
    assert!(e.to_string().contains("0..3 of a 6-frame"), "{e}");
}

/// Frames that see nothing, and a path that sees nothing at all, merge and validate.
#[test]
fn frames_without_visible_triangles() {
    let frames = vec![
        FrameSpec::default(),
        FrameSpec {
            visible: vec![1, 2],
            edges: vec![(1, 2, 1)],
            ..FrameSpec::default()
        },
        FrameSpec::default(),
        FrameSpec {
            visible: vec![2],
            hidden: vec![1],
            edges: vec![(2, 1, 1)],
            ..FrameSpec::default()
        },
    ];
    let rec = recording_from_frames(4, &frames);
    assert_all_valid(std::slice::from_ref(&rec), "empty frames");
    let hidden = MergeOptions {
        bridge: Bridge::Hidden,
        ..MergeOptions::default()
    };
    let baked = merge(std::slice::from_ref(&rec), &hidden).unwrap();
    // With `hidden`, copies extend (for free) through frames where their triangle has no
    // fragment, so frame 0 draws both triangles; one copy each suffices.
    assert_eq!(baked.stats.index_triangles, 2);
    // With `visible` (the default) triangle 2, visible at frames 1 and 3 only, needs a copy
    // for each, and nothing is drawn where it is not visible.
    let visible = merge(std::slice::from_ref(&rec), &MergeOptions::default()).unwrap();
    assert_eq!(visible.stats.index_triangles, 3);
    assert_eq!(visible.stats.drawn_not_visible_mean, 0.0);
    assert!(check_graph(std::slice::from_ref(&rec), &visible).ok);
    assert_eq!(
        trisort_merger::cell_counts(&baked)
            .iter()
            .map(|c| c.2)
            .sum::<u32>(),
        baked.copies.len() as u32
    );
    let nothing = recording_from_frames(4, &[FrameSpec::default(), FrameSpec::default()]);
    let baked = merge(std::slice::from_ref(&nothing), &MergeOptions::default()).unwrap();
    assert!(baked.copies.is_empty() && check_graph(std::slice::from_ref(&nothing), &baked).ok);
}
