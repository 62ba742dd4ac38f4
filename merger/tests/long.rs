//! Long synthetic paths: draws per frame stay bounded, cells stay sparse, and the result
//! still validates.

use crate::merge;
use trisort_format::Baked;
use trisort_merger::synth::{turntable, Turntable};
use trisort_merger::{Choice, Layout, MergeOptions, Strategy};
use trisort_verify::check_graph;

/// Merges the turntable `t` (IBL, compact layout, segments of `segment` frames), prints the
/// figures and the time under `what`, and checks the result with the validator.
fn merged_and_valid(what: &str, t: Turntable, segment: Option<u32>) -> Baked {
    let rec = turntable(&t);
    let opts = MergeOptions {
        strategy: Choice::Only(Strategy::Ibl),
        layout: Choice::Only(Layout::Compact),
        segment,
        ..MergeOptions::default()
    };
    let t = std::time::Instant::now();
    let baked = merge(std::slice::from_ref(&rec), &opts).unwrap();
    let secs = t.elapsed().as_secs_f64();
    eprintln!(
        "{what}: {:?}, cells {}, {secs:.2} s",
        baked.stats,
        baked.merge.cells.len()
    );
    let report = check_graph(std::slice::from_ref(&rec), &baked);
    assert!(report.ok, "{what}: {:?}", report.problems);
    baked
}

/// 1,000 frames (a full turn) in one matrix.
#[test]
fn thousand_frames_merge_with_bounded_draws() {
    let turn = Turntable {
        objects: 12,
        sides: 16,
        frames: 1000,
        samples: 128,
        degrees: 360.0,
        ..Turntable::default()
    };
    let baked = merged_and_valid("1,000 frames", turn, None);
    let s = &baked.stats;
    assert!(s.unique_visible <= s.index_triangles && s.index_triangles <= s.source_triangles);
    // A window is a set of cells; merged ranges can never outnumber the frame's cells, and
    // the compact layout bounds them by max(f+1, F−f). Far fewer are used in practice.
    let worst_cells = (0..1000u32)
        .map(|f| {
            baked
                .merge
                .cells
                .iter()
                .filter(|c| c.first_frame <= f && f <= c.last_frame)
                .count()
        })
        .max()
        .unwrap() as u32;
    assert!(s.draws_per_frame_max <= worst_cells.min(1000));
    assert!(
        s.draws_per_frame_max <= 100,
        "draws per frame {}",
        s.draws_per_frame_max
    );
}

/// 10,000 frames in segments of 100: every segment has its own matrix.
#[test]
fn ten_thousand_frames_in_segments() {
    let turn = Turntable {
        objects: 6,
        sides: 12,
        frames: 10_000,
        samples: 64,
        degrees: 3600.0,
        ..Turntable::default()
    };
    let baked = merged_and_valid("10,000 frames", turn, Some(100));
    let s = &baked.stats;
    assert!(s.index_triangles <= s.source_triangles);
    // No cell crosses a segment boundary, and a window never holds more ranges than its
    // segment's compact bound.
    assert!(baked
        .merge
        .cells
        .iter()
        .all(|c| c.first_frame / 100 == c.last_frame / 100 && c.triangles > 0));
    assert!(s.draws_per_frame_max <= 100);
    // Sparse: far fewer cells than the 100 · 5,050 of full matrices.
    assert!(
        baked.merge.cells.len() < 100 * 5050 / 20,
        "{} cells",
        baked.merge.cells.len()
    );
}

/// `auto` on a path of several segments: the combinations compete on the first segment and the
/// winner merges the whole path, so the result is that combination's own merge, and it is the
/// best on the first segment alone.
#[test]
fn auto_chooses_on_the_first_segment() {
    let rec = turntable(&Turntable {
        objects: 10,
        sides: 12,
        frames: 40,
        samples: 96,
        degrees: 120.0,
        ..Turntable::default()
    });
    let recs = std::slice::from_ref(&rec);
    let auto = MergeOptions {
        segment: Some(16),
        ..MergeOptions::default()
    };
    let baked = merge(recs, &auto).unwrap();
    assert!(check_graph(recs, &baked).ok);
    let only = |s, l, segment| MergeOptions {
        strategy: Choice::Only(s),
        layout: Choice::Only(l),
        segment,
        ..MergeOptions::default()
    };
    let (s, l) = (baked.merge.strategy, baked.merge.layout);
    let direct = merge(recs, &only(s, l, Some(16))).unwrap();
    assert_eq!(baked.copies, direct.copies);
    assert_eq!(baked.draws, direct.draws);
    // On the first segment (frames 0..16) alone, no combination beats it.
    let mut first = rec.clone();
    first.frames.truncate(16);
    first.frame_states.truncate(16);
    first.clips[0].count = 16;
    let head = std::slice::from_ref(&first);
    let best = merge(head, &only(s, l, Some(16))).unwrap();
    for s2 in Strategy::ALL {
        for l2 in Layout::ALL {
            let other = merge(head, &only(s2, l2, Some(16))).unwrap();
            assert!(
                other.copies.len() >= best.copies.len(),
                "{s2:?} {l2:?} beats {s:?} {l:?} on the first segment"
            );
        }
    }
}
