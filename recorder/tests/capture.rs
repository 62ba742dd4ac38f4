//! Capturing every fragment of a frame in one pass and sorting each sample's list records
//! exactly what depth peeling, one pass per layer, records: byte-identical `Recording`s, both
//! made in this process, on the demo car, GlassVaseFlowers (textured MASK and BLEND leaves,
//! glass) and CarConcept, plain, robust and conservative, at 4× and 1× MSAA; also when the
//! pool must grow and when a frame's fragments are split into bands of rows.

use trisort_format::RecordSettings;
use trisort_recorder::{capture_counters, Internals};
use trisort_scene::Scene;

use crate::compact_readback::{assert_internals_keep_recording, shared_scene, variants};

fn capture_matches_peeling(gpu: &trisort_gpu::Gpu, scene: &Scene, settings: RecordSettings) {
    capture_in_pools_matches_peeling(gpu, scene, settings, None);
}

/// [`capture_matches_peeling`] with captures' pools limited to `pools` (first nodes, most
/// fragments a pass: [`Internals::pool_limits`]).
fn capture_in_pools_matches_peeling(
    gpu: &trisort_gpu::Gpu,
    scene: &Scene,
    settings: RecordSettings,
    pools: Option<(u64, u64)>,
) {
    let capture = Internals {
        pool_limits: pools,
        ..Internals::default()
    };
    let peel = Internals {
        peel: true,
        ..capture
    };
    assert_internals_keep_recording(
        gpu,
        scene,
        settings,
        (capture, peel),
        "capturing instead of peeling",
    );
}

#[test]
fn capture_matches_peeling_on_the_demo_car() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let scene = trisort_scene::demo_car(20_000);
    let before = capture_counters();
    for s in variants() {
        capture_matches_peeling(&gpu, &scene, s);
    }
    // Not peeling both times: the device captured (other tests may capture at the same time,
    // so only a lower bound).
    assert!(capture_counters()[0] > before[0], "nothing was captured");
}

/// Pools of 256 nodes at first: every phase's first frame asks for more, so it is drawn again
/// in a grown pool, and the recording is still the one peeling makes.
#[test]
fn capture_with_a_growing_pool_matches_peeling() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let scene = trisort_scene::demo_car(20_000);
    let before = capture_counters();
    for s in [variants()[0], variants()[2]] {
        capture_in_pools_matches_peeling(&gpu, &scene, s, Some((256, u64::MAX)));
    }
    let after = capture_counters();
    // Other tests may capture at the same time, so only a lower bound.
    assert!(after[1] > before[1], "the pool never grew");
}

#[test]
fn capture_matches_peeling_on_a_real_scene() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let Some(scene) = shared_scene("GlassVaseFlowers/GlassVaseFlowers.glb") else {
        return;
    };
    for s in variants() {
        capture_matches_peeling(&gpu, &scene, s);
    }
}

#[test]
fn capture_matches_peeling_on_car_concept() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let Some(scene) = shared_scene("CarConcept/CarConcept.glb") else {
        return;
    };
    // Plain at 4×, glass recorded at the demo's 0.35 (so it saturates part-way).
    let s = RecordSettings {
        glass_opacity: 0.35,
        ..variants()[0]
    };
    capture_matches_peeling(&gpu, &scene, s);
}

/// Small pools: the car's frames ask for more, so each is split into bands of rows (each
/// drawing every triangle again), halved until each fits, and the recording is still the one
/// peeling makes; plain (at most 500 nodes) and conservative (the grown capture, far more
/// fragments a sample: at most 8,000).
#[test]
fn capture_in_bands_matches_peeling() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let scene = trisort_scene::demo_car(20_000);
    for (s, most) in [(variants()[0], 500), (variants()[2], 8_000)] {
        let s = RecordSettings {
            width: 32,
            height: 32,
            ..s
        };
        let before = capture_counters();
        capture_in_pools_matches_peeling(&gpu, &scene, s, Some((256, most)));
        let after = capture_counters();
        assert!(
            after[2] > before[2],
            "no frame was split into bands ({s:?})"
        );
    }
}

/// Glass recorded opaque (opacity 1) is drawn in phase 1's depth prepass like any opaque
/// surface, so what lies behind it is never captured: still the recording peeling makes.
#[test]
fn capture_with_opaque_glass_matches_peeling() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let scene = trisort_scene::demo_car(20_000);
    let s = RecordSettings {
        glass_opacity: 1.0,
        ..variants()[0]
    };
    capture_matches_peeling(&gpu, &scene, s);
}
