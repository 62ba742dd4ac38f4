//! The demo car and CarConcept over their paths: every invariant of `common::check`, and the
//! figures printed (run with `--nocapture` to see them; `examples/split_stats.rs` prints them
//! from the command line, in release mode).

use std::path::Path;
use std::time::Instant;

use trisort_format::FrameState;
use trisort_intersect::{split_intersections, SplitOptions, SplitScene};
use trisort_scene::Scene;
use trisort_testkit::scene_path;

use crate::common::{check, Expect};

/// Splits `scene` over `frames`, prints the figures and checks the invariants.
fn split_and_check(scene: &Scene, frames: &[FrameState], options: &SplitOptions) -> SplitScene {
    let start = Instant::now();
    let out = split_intersections(&scene.geometry, frames, options);
    let seconds = start.elapsed().as_secs_f64();
    let r = &out.report;
    eprintln!(
        "{} ({}): {} triangles, {} frames, {} groups: {} pairs split, {} skipped (sliver), {} \
         below precision, {} triangles split, {} added, {} rounds, {} T-junctions left, \
         {seconds:.2} s (this build)",
        scene.name,
        if options.cut_both_sides {
            "both sides"
        } else {
            "one side"
        },
        scene.geometry.triangles.len(),
        frames.len(),
        r.groups,
        r.pairs_split,
        r.pairs_skipped_sliver,
        r.pairs_below_precision,
        r.triangles_split,
        r.triangles_added,
        r.rounds,
        r.t_junctions_left
    );
    // Scene triangles can be thin: the area bound is mostly the rounding of new vertices.
    let expect = Expect {
        area: 1e-9,
        interpolation: None,
    };
    check(&scene.geometry, frames, &out, &expect);
    out
}

#[test]
fn demo_car_over_its_path() {
    let scene = trisort_scene::demo_car(trisort_scene::DEFAULT_TRIANGLES);
    let frames = trisort_paths::demo_default(&scene).frames;
    let out = split_and_check(&scene, &frames, &SplitOptions::default());
    // The door (with its window) moves on the path: two groups.
    assert_eq!(out.report.groups, 2);
    assert!(out.report.pairs_split > 0);
    let one_side = SplitOptions {
        cut_both_sides: false,
        ..SplitOptions::default()
    };
    let fewer = split_and_check(&scene, &frames, &one_side);
    assert_eq!(fewer.report.pairs_split, out.report.pairs_split);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let again =
        pool.install(|| split_intersections(&scene.geometry, &frames, &SplitOptions::default()));
    assert_eq!(again, out, "one thread or many, the same output");
}

#[test]
fn car_concept_over_the_tour() {
    let Some(path) = scene_path("CarConcept/CarConcept.glb") else {
        return;
    };
    let scene = trisort_scene::load(&path).expect("CarConcept imports");
    let tour = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/car-tour.toml");
    let frames = trisort_paths::load(tour.to_str().unwrap(), &scene, &Default::default())
        .expect("the tour loads")
        .frames;
    let out = split_and_check(&scene, &frames, &SplitOptions::default());
    assert!(out.report.groups >= 2, "the driver door moves on the tour");
    assert!(out.report.pairs_split > 0);
}
