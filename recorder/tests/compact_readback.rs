//! The compact readback (three per-sample arrays, only those a phase needs copied back, and
//! phase 1's visible set as one flag a triangle) records exactly what the former interleaved
//! readback recorded: byte-identical `Recording`s, both made in this process, on the demo car
//! and a real scene, plain, robust and conservative, at 4× and 1× MSAA.

use trisort_format::{Phase, ProfileName, RecordSettings, Recording, Robust};
use trisort_recorder::{record, Internals, RecordJob};
use trisort_scene::Scene;

/// Records two frames spread around `scene`'s orbit with `settings`, once with the
/// recorder working as `other` says (another route, such as a former path) and once as
/// `base` says, and asserts the serialised `Recording`s are byte-identical; `change` names
/// what `other` changes, for the message.
pub(crate) fn assert_internals_keep_recording(
    gpu: &trisort_gpu::Gpu,
    scene: &Scene,
    settings: RecordSettings,
    (base, other): (Internals, Internals),
    change: &str,
) {
    let timeline = trisort_paths::load("orbit", scene, &Default::default()).expect("orbit path");
    // Two frames half an orbit apart: what one sees the other does not, and the recording
    // holds both (each equivalence test here records twice per settings variant).
    let step = (timeline.frames.len() / 2).max(1);
    let frames: Vec<_> = timeline
        .frames
        .iter()
        .step_by(step)
        .take(2)
        .cloned()
        .collect();
    let job = RecordJob {
        geometry: &scene.geometry,
        frames: &frames,
        scene_hash: scene.hash(),
        path_hash: [7; 32],
        settings,
        range: None,
        phase: Phase::Graphs,
        known_visible: None,
        internals: base,
    };
    let run = |internals| {
        let job = RecordJob {
            internals,
            ..job.clone()
        };
        record(gpu, &job, None, |_| {}).expect("recording succeeds")
    };
    let before: Recording = run(other);
    let after: Recording = run(base);
    // Not vacuous: something was seen, ordered and tied... or at least seen and ordered.
    assert!(after.frames.iter().all(|f| !f.visible.is_empty()));
    assert!(after.frames.iter().any(|f| !f.edges.is_empty()));
    let bytes = |r: &Recording| postcard::to_stdvec(r).expect("serialises");
    assert!(
        bytes(&before) == bytes(&after),
        "{}: {change} changed the recording ({settings:?})",
        scene.name,
    );
}

/// Both readbacks of the peeler: the recorder peels ([`Internals::peel`]; it captures where
/// it can, which `capture` compares with peeling).
fn record_both(gpu: &trisort_gpu::Gpu, scene: &Scene, settings: RecordSettings) {
    let peel = Internals {
        peel: true,
        ..Internals::default()
    };
    let interleaved = Internals {
        interleaved_readback: true,
        ..peel
    };
    assert_internals_keep_recording(
        gpu,
        scene,
        settings,
        (peel, interleaved),
        "the compact readback",
    );
}

/// The shared scene at `rel` under `TRISORT_SCENES`, loaded; `None` (the test skips) where
/// the scenes are absent and not required.
pub(crate) fn shared_scene(rel: &str) -> Option<Scene> {
    let path = trisort_testkit::scene_path(rel)?;
    Some(trisort_scene::load(&path).expect("scene loads"))
}

/// Plain (the recorded pattern only), robust and conservative at 4×, and plain at 1×, at
/// 64×64.
pub(crate) fn variants() -> Vec<RecordSettings> {
    let base = RecordSettings {
        width: 64,
        height: 64,
        samples: 4,
        robust: Robust::OFF,
        ..Default::default()
    };
    vec![
        base,
        RecordSettings {
            robust: Robust {
                patterns: 2,
                ..Robust::OFF
            },
            ..base
        },
        // The widest profile (the conservative default before raster profiles): many grown
        // fragments a sample, which the band test needs.
        RecordSettings {
            robust: Robust::profile_named(ProfileName::Browser),
            ..base
        },
        RecordSettings { samples: 1, ..base },
        // The default (conformant) profile.
        RecordSettings {
            robust: Robust::DEFAULT,
            ..base
        },
    ]
}

#[test]
fn compact_readback_records_the_demo_car_as_before() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let scene = trisort_scene::demo_car(20_000);
    for s in variants() {
        record_both(&gpu, &scene, s);
    }
}

#[test]
fn compact_readback_records_a_real_scene_as_before() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let Some(scene) = shared_scene("GlassVaseFlowers/GlassVaseFlowers.glb") else {
        return;
    };
    for s in variants() {
        record_both(&gpu, &scene, s);
    }
}
