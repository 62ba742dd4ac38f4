//! The on-device self-check (`trisort_player::self_check`) and the sub-pixel offset of the
//! projection, on the hand-built quads (GPU; skipped without an adapter unless
//! `TRISORT_REQUIRE_GPU=1`).

use trisort_player::self_check::zbuffer_baked;
use trisort_player::{HeadlessConfig, HeadlessRenderer, Mode, SelfCheck};

use crate::support::*;

fn gpu() -> Option<trisort_gpu::Gpu> {
    std::env::set_var(
        "XDG_RUNTIME_DIR",
        std::env::var("XDG_RUNTIME_DIR").unwrap_or("/tmp".into()),
    );
    trisort_testkit::gpu()
}

#[test]
fn an_honest_frame_has_no_hole_and_a_removed_triangle_is_one() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    let check = SelfCheck::new(&gpu, &baked, (SIZE, SIZE), 1).unwrap();
    // Frame 1 draws all three quads: nothing of the file is left out.
    let honest = check.check(1).unwrap();
    assert_eq!((honest.frame, honest.holes), (1, 0), "{honest:?}");
    // Frame 0 leaves out the opaque blue quad behind everything: wherever red and green do
    // not cover the view (about 43 % of it), the blue quad is the nearest surface and the
    // background shows. Under red and green, depth mode shows the nearest fragment alone.
    let open = check.check(0).unwrap();
    let pixels = (SIZE * SIZE) as u64;
    assert!(
        open.holes > pixels / 3 && open.holes < pixels / 2,
        "{open:?} of {pixels}"
    );

    // Forge frame 1: its blue draw keeps one of the quad's two triangles.
    let mut forged = quads();
    forged.draws[1].index_count = 3;
    let check = SelfCheck::new(&gpu, &forged, (SIZE, SIZE), 1).unwrap();
    let hole = check.check(1).unwrap();
    // About half of the view lies in the removed triangle, less what red and green cover.
    assert!(
        hole.holes > pixels / 5 && hole.holes < pixels / 2 + SIZE as u64,
        "{hole:?} of {pixels}"
    );
    assert!(hole.max_channel_diff > 100, "{hole:?}");
    let images = check.images(1).unwrap();
    assert_eq!(
        images.mask.iter().filter(|&&m| m).count() as u64,
        hole.holes
    );
    assert_ne!(images.played, images.zbuffer);
}

#[test]
fn against_the_scene_it_also_sees_triangles_the_file_lacks() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    // The scene: the file's quads and an opaque quad in front of them that never reached it.
    let mut scene = baked.geometry.clone();
    trisort_testkit::fixtures::flat_quad(&mut scene, -0.2, 0.2, -0.2, 0.2, 1.0, 2);
    let own = SelfCheck::new(&gpu, &baked, (SIZE, SIZE), 1).unwrap();
    assert_eq!(own.check(1).unwrap().holes, 0);
    let full = SelfCheck::against_scene(&gpu, &baked, &scene, (SIZE, SIZE), 1).unwrap();
    let h = full.check(1).unwrap();
    // The quad spans 0.4 of the 2-unit view at z = 0, more nearer the camera: ≈ 8 px wide.
    assert!(h.holes > 40 && h.holes < 150, "{h:?}");
    // Frame 0 leaves out the blue quad too: the new quad's pixels and the blue ones.
    assert!(full.check(0).unwrap().holes > own.check(0).unwrap().holes);
}

#[test]
fn the_zbuffer_twin_draws_each_window_then_every_triangle() {
    let baked = quads();
    let z = zbuffer_baked(&baked);
    z.check_structure().unwrap();
    let n = baked.geometry.triangles.len() as u32;
    for f in 0..baked.frames.len() {
        let own = baked.frame_draws(f);
        let twin = z.frame_draws(f);
        assert_eq!(&twin[..own.len()], own);
        assert_eq!(twin.len(), own.len() + 1);
        let all = twin[own.len()];
        assert_eq!(all.index_count, 3 * n);
        assert_eq!(drawn_copies(&z, &[all]), (0..n).collect::<Vec<_>>());
    }
}

#[test]
fn a_subpixel_offset_moves_the_image_and_zero_restores_it() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    let config = HeadlessConfig {
        mode: Mode::Depth,
        ..HeadlessConfig::recorded(&baked)
    };
    let r = HeadlessRenderer::new(&gpu, &baked, &config).unwrap();
    let still = r.render(1).unwrap().rgba8;
    // A whole pixel to the right and one down: the same samples meet the geometry, so the
    // picture moves by exactly one pixel (the blue quad fills the view, so the border too).
    r.set_subpixel_offset([1.0, 1.0]);
    let moved = r.render(1).unwrap().rgba8;
    assert_ne!(moved, still);
    let s = SIZE as usize;
    let px = |img: &[u8], x: usize, y: usize| img[(y * s + x) * 4..][..4].to_vec();
    let mut same = 0;
    for y in 1..s {
        for x in 1..s {
            same += (px(&moved, x, y) == px(&still, x - 1, y - 1)) as usize;
        }
    }
    // Rounding of the shifted projection may flip a sample exactly on an edge.
    assert!(
        same >= (s - 1) * (s - 1) - 2,
        "{same} of {}",
        (s - 1) * (s - 1)
    );
    // A sixteenth of a pixel moves edges, not whole pixels: a few pixels change at most
    // along the quads' edges.
    r.set_subpixel_offset([1.0 / 16.0, 0.0]);
    let nudged = r.render(1).unwrap().rgba8;
    let changed = (0..s * s)
        .filter(|&k| nudged[k * 4..][..4] != still[k * 4..][..4])
        .count();
    assert!(changed <= 4 * s, "{changed}");
    r.set_subpixel_offset([0.0, 0.0]);
    assert_eq!(r.render(1).unwrap().rgba8, still);
}
