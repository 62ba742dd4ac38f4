//! Paper 004's occlusion-query sort on the GPU: objects (connected pieces) found, sorted front
//! to back by real occlusion queries from a wrong starting order, drawn exactly where no two
//! objects interpenetrate, and a cycle reported where two do.

use glam::DVec3;
use trisort_format::{FrameState, Geometry};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::Lighting;
use trisort_player::Mode;
use trisort_reference::vis_sort::objects;
use trisort_reference::{ExactReference, ReferenceConfig, VisSortRenderer};
use trisort_testkit::fixtures::{frame_at, material, quad, scene};
use trisort_testkit::gpu;

const SIZE: u32 = 48;

fn view(samples: u32) -> View {
    View {
        width: SIZE,
        height: SIZE,
        samples,
        glass_opacity: 0.0,
    }
}

/// Three overlapping transparent quads, one object each (four shared corners), the farthest
/// first in scene order; the camera at the origin and a little to the side.
fn stacked() -> (Geometry, Vec<FrameState>) {
    let mut g = scene(vec![
        material([0.9, 0.2, 0.1], 0.5),
        material([0.1, 0.8, 0.3], 0.35),
        material([0.2, 0.3, 0.95], 0.7),
    ]);
    quad(&mut g, [-1.5, 0.9], [-1.2, 0.8], [-4.0, -4.0], 0);
    quad(&mut g, [-0.7, 1.6], [-0.6, 1.4], [-3.0, -3.2], 1);
    quad(&mut g, [-1.1, 1.2], [-1.5, 0.3], [-2.0, -2.1], 2);
    let frames = vec![frame_at(DVec3::ZERO), frame_at(DVec3::new(0.3, -0.2, 0.4))];
    (g, frames)
}

#[test]
fn objects_are_the_connected_pieces_of_the_transparent_triangles() {
    let (mut g, _) = stacked();
    g.materials.push(material([0.5; 3], 1.0));
    quad(&mut g, [-1.0, 1.0], [-1.0, 1.0], [-5.0, -5.0], 3);
    // Two pieces per quad would mean the shared corners were missed; the opaque quad is none.
    assert_eq!(objects(&g), vec![vec![0, 1], vec![2, 3], vec![4, 5]]);
}

#[test]
fn queries_sort_the_objects_front_to_back_and_the_frame_matches_the_reference() {
    let Some(gpu) = gpu() else { return };
    let (g, frames) = stacked();
    for samples in [1, 4] {
        let r = VisSortRenderer::new(&gpu, &g, &frames, view(samples), Lighting::default())
            .expect("renderer");
        let config = ReferenceConfig {
            size: (SIZE, SIZE),
            samples,
            mode: Mode::Blend,
            glass_opacity: 0.0,
            max_layers: 64,
        };
        let exact =
            ExactReference::new(&gpu, &g, &frames, Lighting::default(), config).expect("exact");
        // From the wrong order (back to front): more than one iteration, the right answer.
        let first = r.sort(0, Some(&[0, 1, 2])).expect("sort");
        assert_eq!(first.order, vec![2, 1, 0], "{samples}x: {first:?}");
        assert_eq!(first.cycles, 0);
        assert!(first.iterations > 1, "{first:?}");
        // From the previous frame's order: one iteration, two readbacks, 2 × 3 queries.
        let second = r.sort(1, Some(&first.order)).expect("sort");
        assert_eq!(second.order, vec![2, 1, 0]);
        assert_eq!(
            (second.iterations, second.batches, second.queries),
            (1, 2, 6),
            "{second:?}"
        );
        for (f, order) in [(0, &first.order), (1, &second.order)] {
            let indices = r.frame_indices(f, order);
            let (buffer, count) = r.upload(&indices);
            let image = r.render(f, (&buffer, count)).expect("frame");
            let reference = exact.render(f, None).expect("reference");
            assert_eq!(
                image, reference.rgba8,
                "{samples}x frame {f}: the sorted objects equal the reference"
            );
        }
    }
}

#[test]
fn interpenetrating_objects_are_reported_as_a_cycle() {
    let Some(gpu) = gpu() else { return };
    // Two quads tilted through each other: each is behind the other on one side.
    let mut g = scene(vec![
        material([0.9, 0.2, 0.1], 0.5),
        material([0.1, 0.8, 0.3], 0.5),
    ]);
    quad(&mut g, [-1.0, 1.0], [-1.0, 1.0], [-2.0, -4.0], 0);
    quad(&mut g, [-1.0, 1.0], [-0.8, 0.8], [-4.0, -2.0], 1);
    let frames = vec![frame_at(DVec3::ZERO)];
    let r =
        VisSortRenderer::new(&gpu, &g, &frames, view(4), Lighting::default()).expect("renderer");
    let out = r.sort(0, None).expect("sort");
    assert_eq!(out.cycles, 1, "{out:?}");
    let mut placed = out.order.clone();
    placed.sort();
    assert_eq!(placed, vec![0, 1], "every object still drawn");
}
