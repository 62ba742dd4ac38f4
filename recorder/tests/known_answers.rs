//! Recorder tests with known answers on scenes built here: camera at the origin looking down
//! −Z, axis-aligned quads facing it. Each scene is recorded by capture and by peeling, which
//! must agree byte for byte.

use glam::DVec3;
use trisort_format::{FrameState, Geometry, Phase, RecordSettings, Recording};
use trisort_recorder::{record, Internals, RecordJob};
use trisort_testkit::fixtures::{flat_quad, frame_at, material, scene, settings, tri};

fn run(g: &Geometry, frames: &[FrameState], settings: RecordSettings) -> Option<Recording> {
    let gpu = trisort_testkit::gpu()?;
    let job = RecordJob {
        geometry: g,
        frames,
        scene_hash: [1; 32],
        path_hash: [2; 32],
        settings,
        range: None,
        phase: Phase::Graphs,
        known_visible: None,
        internals: Default::default(),
    };
    let r = record(&gpu, &job, None, |_| {}).expect("recording succeeds");
    // Every known answer holds for both ways of getting the layers: the one-pass capture (as
    // shipped) and depth peeling, which record the same bytes.
    let peel = RecordJob {
        internals: Internals {
            peel: true,
            ..Internals::default()
        },
        ..job.clone()
    };
    let peeled = record(&gpu, &peel, None, |_| {}).expect("peeling succeeds");
    let bytes = |r: &Recording| postcard::to_stdvec(r).expect("serialises");
    assert!(bytes(&r) == bytes(&peeled), "capture and peeling differ");
    Some(r)
}

fn edge_weight(r: &Recording, f: usize, from: u32, to: u32) -> u32 {
    r.frames[f]
        .edges
        .iter()
        .find(|e| e.from == from && e.to == to)
        .map_or(0, |e| e.weight)
}

#[test]
fn three_stacked_transparent_quads() {
    // Full-screen quads at z = -2, -3, -4 (ids 0-1, 2-3, 4-5), alpha 0.5: all visible, and each
    // sample shows front → middle → back. A quad's diagonal splits the samples between its two
    // triangles, so sum the weights per quad.
    let mut g = scene(vec![material([1.0, 1.0, 1.0], 0.5)]);
    for z in [-2.0, -3.0, -4.0] {
        flat_quad(&mut g, -10.0, 10.0, -10.0, 10.0, z, 0);
    }
    let Some(r) = run(&g, &[frame_at(DVec3::ZERO)], settings(16, 4)) else {
        return;
    };
    let f = &r.frames[0];
    assert_eq!(f.visible, vec![0, 1, 2, 3, 4, 5]);
    assert_eq!(f.covered, vec![0, 1, 2, 3, 4, 5]);
    let samples = 16 * 16 * 4;
    let quad_weight = |a: u32, b: u32| -> u32 {
        [2 * a, 2 * a + 1]
            .iter()
            .flat_map(|&x| [2 * b, 2 * b + 1].map(|y| edge_weight(&r, 0, x, y)))
            .sum()
    };
    assert_eq!(quad_weight(0, 1), samples, "front → middle at every sample");
    assert_eq!(quad_weight(1, 2), samples, "middle → back at every sample");
    assert_eq!(
        quad_weight(0, 2),
        0,
        "only neighbours in the peel order give edges"
    );
    assert_eq!(f.edges.iter().map(|e| e.weight).sum::<u32>(), 2 * samples);
    assert_eq!(f.layers[1], 3);
    assert!(f.ties.is_empty());
    assert!(!f.truncated);
}

#[test]
fn an_opaque_occluder_hides_unless_visible_elsewhere() {
    // Opaque quad (ids 0-1) in front of a small quad (ids 2-3) in frame 0; frame 1 looks from
    // the side so the small quad shows beside the occluder.
    let mut g = scene(vec![material([1.0, 1.0, 1.0], 1.0)]);
    flat_quad(&mut g, -0.5, 0.5, -0.5, 0.5, -2.0, 0);
    flat_quad(&mut g, -0.2, 0.2, -0.2, 0.2, -3.0, 0);
    let only_front = run(&g, &[frame_at(DVec3::ZERO)], settings(16, 4));
    let Some(only_front) = only_front else { return };
    assert_eq!(
        only_front.unique_visible,
        vec![0, 1],
        "hidden in the only frame: not in G"
    );
    assert_eq!(only_front.geometry.triangles.len(), 2);

    let r = run(
        &g,
        &[frame_at(DVec3::ZERO), frame_at(DVec3::new(3.0, 0.0, 0.0))],
        settings(16, 4),
    )
    .unwrap();
    assert!(
        r.unique_visible.contains(&2) || r.unique_visible.contains(&3),
        "{:?}",
        r.unique_visible
    );
    let f0 = &r.frames[0];
    assert!(
        !f0.visible.contains(&2) && !f0.visible.contains(&3),
        "hidden at frame 0"
    );
    assert!(
        f0.covered.contains(&2) || f0.covered.contains(&3),
        "but covered there (phase 2 peels G fully)"
    );
    assert!(
        f0.edges.iter().any(|e| e.from <= 1 && e.to >= 2),
        "occluder → occluded edge"
    );
}

#[test]
fn a_small_triangle_missed_by_every_sample_is_ignored() {
    // A tiny triangle: covers a sample centre in frame 0 (placed on one), none in frame 1.
    let mut g = scene(vec![material([1.0, 1.0, 1.0], 1.0)]);
    // Background, ids 0-1.
    flat_quad(&mut g, -10.0, 10.0, -10.0, 10.0, -5.0, 0);
    // Pixel (8, 8) centre at 1x is at NDC (1/16, -1/16) → at z=-1, x = 0.0625, y = -0.0625.
    let (cx, cy, d) = (0.0625f32, -0.0625f32, 0.01f32);
    let corners = [(cx - d, cy - d), (cx + d, cy - d), (cx, cy + d)].map(|(x, y)| [x, y, -1.0]);
    tri(&mut g, corners, 0); // id 2
    let shifted = frame_at(DVec3::new(0.03, 0.0, 0.0)); // moves it off every sample centre
    let Some(r) = run(&g, &[frame_at(DVec3::ZERO), shifted], settings(16, 1)) else {
        return;
    };
    assert!(r.frames[0].visible.contains(&2), "sampled in frame 0");
    assert!(r.unique_visible.contains(&2));
    assert!(
        !r.frames[1].covered.contains(&2),
        "no fragment in frame 1: ignore list"
    );
    assert!(r.frames[1].covered.contains(&0) || r.frames[1].covered.contains(&1));
}

#[test]
fn coplanar_quads_are_both_peeled_lower_id_in_front() {
    let mut g = scene(vec![material([1.0, 1.0, 1.0], 0.5)]);
    flat_quad(&mut g, -10.0, 10.0, -10.0, 10.0, -2.0, 0); // ids 0-1
    flat_quad(&mut g, -10.0, 10.0, -10.0, 10.0, -2.0, 0); // ids 2-3, same plane and diagonal
    let Some(r) = run(&g, &[frame_at(DVec3::ZERO)], settings(16, 4)) else {
        return;
    };
    let f = &r.frames[0];
    assert_eq!(f.visible, vec![0, 1, 2, 3]);
    assert!(
        edge_weight(&r, 0, 0, 2) > 0 && edge_weight(&r, 0, 1, 3) > 0,
        "{:?}",
        f.edges
    );
    assert_eq!(
        edge_weight(&r, 0, 2, 0) + edge_weight(&r, 0, 3, 1),
        0,
        "never the higher id first"
    );
    assert_eq!(f.ties, f.edges, "every edge here is between equal depths");
}

#[test]
fn a_stack_of_alpha_point_one_stops_at_saturation() {
    // 64 full-screen quads of alpha 0.1: 1 − 0.9^k ≥ 0.998 first at k = 59.
    let mut g = scene(vec![material([1.0, 1.0, 1.0], 0.1)]);
    for k in 0..64 {
        flat_quad(&mut g, -10.0, 10.0, -10.0, 10.0, -2.0 - k as f32 * 0.1, 0);
    }
    let Some(r) = run(&g, &[frame_at(DVec3::ZERO)], settings(16, 1)) else {
        return;
    };
    let k = (1..=64).find(|&k| 1.0 - 0.9f64.powi(k) >= 0.998).unwrap() as u32;
    assert_eq!(k, 59);
    let quads: std::collections::BTreeSet<u32> =
        r.frames[0].visible.iter().map(|t| t / 2).collect();
    assert_eq!(quads.len() as u32, k, "quads reached before saturation");
    assert_eq!(*quads.iter().max().unwrap(), k - 1, "the front ones");
    assert_eq!(r.frames[0].layers[0], k);
    // Phase 2 peels G (the 59 quads) completely.
    assert_eq!(r.frames[0].layers[1], k);
    // With a layer bound below that, the frame is marked truncated.
    let capped = run(
        &g,
        &[frame_at(DVec3::ZERO)],
        RecordSettings {
            max_layers: 10,
            ..settings(16, 1)
        },
    )
    .unwrap();
    assert!(capped.frames[0].truncated);
    assert_eq!(capped.frames[0].layers[0], 10);
}
