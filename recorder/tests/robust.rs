//! Robust recording (`record --robust N`, `--conservative`; `trisort_format::Robust`) on a
//! scene with known answers: a tiny triangle that no sample of the recorded pattern reaches
//! but that a sample moved by 0.05 px would, and one hidden behind an opaque quad.

use glam::DVec3;
use trisort_format::{Geometry, Phase, RecordSettings, Recording, Robust};
use trisort_recorder::{record, RecordJob};
use trisort_testkit::fixtures::{flat_quad, frame_at, material, scene, settings, tri};

/// 16×16, one sample per pixel at its centre, 90° field of view: at z = −1 a pixel is 0.125
/// wide and pixel (8, 8)'s centre is at (0.0625, −0.0625).
///
/// - 0, 1: an opaque wall at z = −2 over the whole view;
/// - 2: a tiny triangle at z = −1 whose left edge lies 0.05 px right of pixel (8, 8)'s centre;
/// - 3, 4: an opaque quad at z = −0.5 over the left part of the view (NDC x < −0.2);
/// - 5: a tiny triangle at z = −1 behind it, around NDC x = −0.5, far from its edge.
fn scene_with_a_near_miss() -> Geometry {
    let mut g = scene(vec![material([1.0, 1.0, 1.0], 1.0)]);
    flat_quad(&mut g, -10.0, 10.0, -10.0, 10.0, -2.0, 0);
    let (cx, cy, px) = (0.0625f32, -0.0625f32, 0.125f32);
    let x0 = cx + 0.05 * px;
    tri(
        &mut g,
        [
            [x0, cy - 0.1 * px, -1.0],
            [x0 + 0.2 * px, cy - 0.1 * px, -1.0],
            [x0, cy + 0.1 * px, -1.0],
        ],
        0,
    );
    flat_quad(&mut g, -10.0, -0.1, -10.0, 10.0, -0.5, 0);
    tri(
        &mut g,
        [[-0.5, -0.5, -1.0], [-0.45, -0.5, -1.0], [-0.5, -0.45, -1.0]],
        0,
    );
    g
}

fn run(robust: Robust) -> Option<Recording> {
    let gpu = trisort_testkit::gpu()?;
    let g = scene_with_a_near_miss();
    let frames = [frame_at(DVec3::ZERO)];
    let job = RecordJob {
        geometry: &g,
        frames: &frames,
        scene_hash: [1; 32],
        path_hash: [2; 32],
        settings: RecordSettings {
            robust,
            ..settings(16, 1)
        },
        range: None,
        phase: Phase::Graphs,
        known_visible: None,
    };
    Some(record(&gpu, &job, None, |_| {}).expect("recording succeeds"))
}

fn robust(patterns: u32, conservative: bool) -> Robust {
    Robust {
        patterns,
        conservative,
        ..Robust::OFF
    }
}

#[test]
fn a_near_miss_is_kept_by_robust_recording_and_a_hidden_triangle_is_not() {
    let Some(plain) = run(Robust::OFF) else {
        return;
    };
    // The occluder's diagonal runs almost along its right edge: one of its triangles is seen.
    let seen = vec![0, 1, 3];
    assert_eq!(plain.frames[0].visible, seen, "no sample reaches 2");
    let with_2 = vec![0, 1, 2, 3];

    // The Halton offsets (0, 0), (0, −t/3), (−t/2, t/3), … with t = 1/8 px: the third moves
    // the image 1/16 px left, over pixel (8, 8)'s centre.
    let two = run(robust(2, false)).unwrap();
    assert_eq!(two.frames[0].visible, seen);
    let three = run(robust(3, false)).unwrap();
    assert_eq!(three.frames[0].visible, with_2);
    // Phase 2 of the union orders the new triangle in front of the wall.
    assert!(three.frames[0]
        .edges
        .iter()
        .any(|e| e.from == 2 && (e.to == 0 || e.to == 1)));
    assert!(three.frames[0].layers[0] > plain.frames[0].layers[0]);

    // Conservative: every triangle within 1/8 px of a sample, unless an opaque surface covering
    // the sample's whole box lies in front.
    let cons = run(robust(1, true)).unwrap();
    assert_eq!(cons.frames[0].visible, with_2);
    // No sample of the recorded pattern reaches 2; the grown peel orders it before the wall.
    assert!(cons.frames[0]
        .edges
        .iter()
        .any(|e| e.from == 2 && (e.to == 0 || e.to == 1)));
    assert!(cons.frames[0].covered.contains(&2));
    // A tolerance below the miss (0.05 px) does not reach it.
    let tight = run(Robust {
        tolerance: 0.04,
        ..robust(1, true)
    })
    .unwrap();
    assert_eq!(tight.frames[0].visible, seen);
}

#[test]
fn offsets_start_at_the_recorded_pattern_and_stay_within_the_tolerance() {
    let r = Robust {
        patterns: 8,
        tolerance: 0.25,
        conservative: false,
    };
    let o = r.offsets();
    assert_eq!(o.len(), 8);
    assert_eq!(o[0], [0.0, 0.0]);
    for (k, a) in o.iter().enumerate() {
        assert!(a[0].abs() <= 0.25 && a[1].abs() <= 0.25, "{a:?}");
        for b in &o[..k] {
            assert_ne!(a, b);
        }
    }
    assert_eq!(Robust::OFF.offsets(), vec![[0.0, 0.0]]);
    assert!(!Robust::OFF.is_on());
    for bad in [0, Robust::MAX_PATTERNS + 1] {
        let s = RecordSettings {
            robust: robust(bad, false),
            ..settings(16, 1)
        };
        assert!(s.validate().is_err(), "{bad} patterns");
    }
    for bad in [-0.1, f32::NAN, 5.0] {
        let s = RecordSettings {
            robust: Robust {
                tolerance: bad,
                ..Robust::OFF
            },
            ..settings(16, 1)
        };
        assert!(s.validate().is_err(), "tolerance {bad}");
    }
}
