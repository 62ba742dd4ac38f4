//! Image verification: baked files played by the player against the exact reference
//! of the full scene, in all three modes at the recorded pattern, on scenes built here with
//! known answers and on real scenes; and the mutation check (a file whose order was corrupted
//! on purpose fails).

use glam::DVec3;
use trisort_format::{
    AlphaMode, Baked, FrameState, Geometry, Material, Phase, RecordSettings, Recording,
};
use trisort_gpu::Gpu;
use trisort_player::Mode;
use trisort_recorder::{record, RecordJob};
use trisort_reference::{FrameImageReport, ImageCheck, ImageVerifier};
use trisort_testkit::fixtures::{frame_at, material, quad, scene, settings};
use trisort_testkit::gpu;

// ---- scenes built here: camera at the origin looking down −Z ----

/// Linear base colours shared by the scenes below.
const RED: [f32; 3] = [0.9, 0.1, 0.1];
const GREEN: [f32; 3] = [0.1, 0.9, 0.1];
const BLUE: [f32; 3] = [0.1, 0.1, 0.9];

/// A scene of [`quad`]s: flat colours as (linear rgb, alpha) ([`material`]), then each quad as
/// `[x0, x1, y0, y1, z0, z1]` with the index of its material; quad k gets triangles 2k, 2k + 1.
fn quads(materials: &[([f32; 3], f32)], quads: &[([f32; 6], u32)]) -> Geometry {
    let mut g = scene(materials.iter().map(|&(rgb, a)| material(rgb, a)).collect());
    for &([x0, x1, y0, y1, z0, z1], m) in quads {
        quad(&mut g, [x0, x1], [y0, y1], [z0, z1], m);
    }
    g
}

// ---- bake and verify through the libraries ----

fn bake(
    gpu: &Gpu,
    geometry: &Geometry,
    frames: &[FrameState],
    settings: RecordSettings,
) -> (Recording, Baked) {
    let job = RecordJob {
        geometry,
        frames,
        scene_hash: [1; 32],
        path_hash: [2; 32],
        settings,
        range: None,
        phase: Phase::Graphs,
        known_visible: None,
        internals: Default::default(),
    };
    let rec = record(gpu, &job, None, |_| {}).expect("recording succeeds");
    let baked = trisort_merger::merge(std::slice::from_ref(&rec), &Default::default())
        .expect("merge succeeds")
        .lit(trisort_light::studio());
    let graph = trisort_verify::check_graph(std::slice::from_ref(&rec), &baked);
    assert!(graph.ok, "graph rules: {:?}", graph.problems);
    (rec, baked)
}

/// Verifies every frame of `baked` in `mode`; `rec` (the recording it was merged from)
/// decides which pixels may be unordered, none without it.
fn verify(
    gpu: &Gpu,
    baked: &Baked,
    geometry: &Geometry,
    mode: Mode,
    rec: Option<&Recording>,
) -> Vec<FrameImageReport> {
    let recs = rec.map(std::slice::from_ref).unwrap_or_default();
    let check = ImageCheck::recorded(baked, mode);
    let v = ImageVerifier::new(gpu, baked, geometry, check, recs).expect("verifier");
    assert!(v.at_recorded_pattern());
    (0..baked.frames.len() as u32)
        .map(|f| v.verify(f).expect("frame verifies").report)
        .collect()
}

/// Verifies every frame in every mode with the recording, asserts they pass, and returns the
/// reports per mode.
fn verify_all_modes(
    gpu: &Gpu,
    name: &str,
    (rec, baked): &(Recording, Baked),
    geometry: &Geometry,
) -> Vec<(Mode, Vec<FrameImageReport>)> {
    Mode::ALL
        .into_iter()
        .map(|mode| {
            let reports = verify(gpu, baked, geometry, mode, Some(rec));
            for r in &reports {
                eprintln!(
                    "{name} {mode} frame {}: differing {} (ordered {}), max {} (ordered {}), psnr {:.1}, flip {:.5}, unordered {} (recording {}), layers {}, srgb8 max {:?}",
                    r.frame,
                    r.comparison.pixels_differing,
                    r.comparison.pixels_differing_ordered,
                    r.comparison.max_channel_diff,
                    r.comparison.max_channel_diff_ordered,
                    r.comparison.psnr,
                    r.comparison.flip_mean,
                    r.unordered_samples,
                    r.unordered_samples_recorded,
                    r.layers,
                    r.srgb8.map(|s| s.max_channel_diff),
                );
                assert!(r.ok, "{name}, {mode} mode, frame {}: {r:?}", r.frame);
                assert!(!r.truncated);
                // The reference's peel finds exactly the samples of the recording's cycles.
                assert_eq!(
                    r.unordered_samples, r.unordered_samples_recorded,
                    "{name}, {mode} mode, frame {}",
                    r.frame
                );
                assert!(r.layers > 0);
            }
            (mode, reports)
        })
        .collect()
}

#[test]
fn stacked_transparent_quads_verify_in_every_mode() {
    let Some(gpu) = gpu() else { return };
    // Ids chosen so that id order is not depth order: the back quad first.
    let g = quads(
        &[
            (RED, 0.5),
            (GREEN, 0.6),
            (BLUE, 0.4),
            ([0.9, 0.9, 0.2], 0.7),
            ([0.8; 3], 1.0),
        ],
        &[
            ([-1.0, 1.0, -1.0, 1.0, -6.0, -6.0], 4),
            ([-0.6, 0.3, -0.5, 0.6, -2.0, -2.0], 0),
            ([-0.3, 0.7, -0.7, 0.3, -4.0, -4.0], 1),
            ([-0.8, 0.1, -0.2, 0.8, -3.0, -3.0], 2),
            ([-0.1, 0.9, -0.9, 0.1, -5.0, -5.0], 3),
        ],
    );
    let frames = [frame_at(DVec3::ZERO), frame_at(DVec3::new(0.3, 0.1, 0.0))];
    let bakes = bake(&gpu, &g, &frames, settings(64, 4));
    let reports = verify_all_modes(&gpu, "stacked quads", &bakes, &g);
    // Five layers deep in the middle, nothing unordered.
    for (mode, rs) in &reports {
        for r in rs {
            assert_eq!(r.unordered_samples, 0);
            if *mode != Mode::Depth {
                assert!(r.layers >= 5);
            }
        }
    }
}

/// The exact reference's settings for the 64², 4× scenes built here, in `mode` (opaque
/// glass, up to 64 layers).
fn reference_config(mode: Mode) -> trisort_reference::ReferenceConfig {
    trisort_reference::ReferenceConfig {
        size: (64, 64),
        samples: 4,
        mode,
        glass_opacity: 0.0,
        max_layers: 64,
    }
}

/// On an opaque scene the `depth` reference equals a plain z-buffer of all triangles
/// in ascending id order (the player drawing the whole scene in id order with `Less`).
#[test]
fn depth_reference_equals_the_plain_z_buffer_on_opaque_scenes() {
    let Some(gpu) = gpu() else { return };
    // Far ones first in id order, a coplanar pair (tie), and a tilted quad through another.
    let g = quads(
        &[(RED, 1.0), (GREEN, 1.0), (BLUE, 1.0)],
        &[
            ([-1.0, 1.0, -1.0, 1.0, -6.0, -6.0], 0),
            ([-0.6, 0.5, -0.5, 0.6, -3.0, -3.0], 1),
            ([-0.2, 0.8, -0.7, 0.3, -3.0, -3.0], 2),
            ([-0.9, 0.9, -0.4, 0.4, -2.0, -4.5], 0),
        ],
    );
    let frames = [frame_at(DVec3::ZERO), frame_at(DVec3::new(0.2, -0.1, 0.3))];
    let s = settings(64, 4);
    // Lit alike: the z-buffer bake and the reference under the default (uniform) environment.
    let lighting = trisort_gpu::Lighting::default();
    let zbuffer = trisort_reference::exact::whole_scene_baked(&g, &frames, s, lighting.environment);
    let played =
        trisort_player::render_frames(&gpu, &zbuffer, &[0, 1], (64, 64), 4, Mode::Depth, None)
            .expect("z-buffer renders");
    let reference = trisort_reference::ExactReference::new(
        &gpu,
        &g,
        &frames,
        lighting,
        reference_config(Mode::Depth),
    )
    .expect("reference");
    for f in 0..2 {
        let r = reference.render(f, None).expect("reference frame");
        assert_eq!(r.rgba8, played[f as usize].rgba8, "frame {f}");
        // Not a blank image: three colours show.
        let colours: std::collections::HashSet<&[u8]> = r.rgba8.chunks(4).collect();
        assert!(colours.len() >= 4);
    }
}

#[test]
fn coplanar_quads_verify_in_every_mode() {
    let Some(gpu) = gpu() else { return };
    // Two overlapping quads in one plane (ties broken by id), a third behind.
    let g = quads(
        &[
            ([0.9, 0.2, 0.1], 0.5),
            ([0.1, 0.3, 0.9], 0.5),
            ([0.2, 0.9, 0.2], 1.0),
        ],
        &[
            ([-0.7, 0.4, -0.6, 0.5, -2.0, -2.0], 0),
            ([-0.3, 0.8, -0.4, 0.7, -2.0, -2.0], 1),
            ([-1.0, 1.0, -1.0, 1.0, -4.0, -4.0], 2),
        ],
    );
    let frames = [frame_at(DVec3::ZERO), frame_at(DVec3::new(-0.2, 0.1, 0.5))];
    let bakes = bake(&gpu, &g, &frames, settings(64, 4));
    assert!(
        bakes.0.frames.iter().any(|f| !f.ties.is_empty()),
        "the scene has depth ties"
    );
    verify_all_modes(&gpu, "coplanar quads", &bakes, &g);
}

/// The pixels an interpenetrating pair leaves unordered are excused only by the recording's
/// cycles: with the recording the bake verifies and differs only there; without it (nothing
/// excused) the same frames fail, in every mode where the removed edge shows.
#[test]
fn interpenetrating_pair_differs_only_on_unordered_pixels() {
    let Some(gpu) = gpu() else { return };
    // A flat quad and a tilted one passing through it: each is in front on one side.
    let g = quads(
        &[(RED, 0.5), ([0.1, 0.2, 0.9], 0.5)],
        &[
            ([-0.8, 0.8, -0.8, 0.8, -3.0, -3.0], 0),
            ([-0.8, 0.8, -0.6, 0.6, -2.0, -4.0], 1),
        ],
    );
    let frames = [frame_at(DVec3::ZERO)];
    let bakes = bake(&gpu, &g, &frames, settings(64, 4));
    let baked = &bakes.1;
    assert!(
        baked.stats.unordered_samples > 0,
        "the merger removed a cycle edge"
    );
    let reports = verify_all_modes(&gpu, "interpenetrating pair", &bakes, &g);
    for (mode, rs) in &reports {
        let r = &rs[0];
        assert!(r.unordered_samples > 0 && r.unordered_pixels > 0);
        // The recording's cycle covers at least what the merger removed.
        assert!(r.unordered_samples >= baked.stats.unordered_samples);
        // Half the overlap is composited in the wrong order, and only there.
        assert!(
            r.comparison.pixels_differing > 0,
            "{mode}: the removed edge shows"
        );
        assert_eq!(r.comparison.pixels_differing_ordered, 0, "{mode}: {r:?}");
        assert!(r.comparison.max_channel_diff > 1);
        // Without the recording no pixel is excused: the same differences fail the frame.
        let alone = &verify(&gpu, baked, &g, *mode, None)[0];
        assert_eq!(alone.unordered_samples, 0);
        assert_eq!(alone.unordered_pixels, 0);
        assert_eq!(
            alone.comparison.pixels_differing_ordered, r.comparison.pixels_differing,
            "{mode}"
        );
        assert!(!alone.ok, "{mode}: {alone:?}");
    }
}

/// The demo car while its driver door opens (frames 8–20 of its default path).
#[test]
fn demo_car_door_opening_verifies_in_every_mode() {
    let Some(gpu) = gpu() else { return };
    let car = trisort_scene::demo_car::demo_car(trisort_scene::demo_car::MIN_TRIANGLES);
    let path = trisort_paths::demo_default(&car);
    let frames: Vec<FrameState> = [8usize, 14, 20]
        .iter()
        .map(|&f| path.frames[f].clone())
        .collect();
    assert!(
        frames.iter().skip(1).all(|f| !f.poses.is_empty()),
        "the door moves"
    );
    let bakes = bake(&gpu, &car.geometry, &frames, settings(96, 4));
    verify_all_modes(&gpu, "demo car door", &bakes, &car.geometry);
}

fn real_scene(name: &str) -> Option<trisort_scene::Scene> {
    let path = trisort_testkit::scene_path(&format!("{name}/{name}.glb"))?;
    Some(trisort_scene::load(&path).expect("scene loads"))
}

/// Bakes the shared scene `name` along the orbit `spec` at 96², 4×, and verifies every frame
/// in every mode ([`verify_all_modes`]); skips without a GPU or without the scene.
fn orbit_verifies_in_every_mode(name: &str, spec: &str) {
    let Some(gpu) = gpu() else { return };
    let Some(s) = real_scene(name) else {
        return;
    };
    let frames = trisort_paths::load(spec, &s, &trisort_paths::PathOptions { fps: 30.0 })
        .expect("path")
        .frames;
    let bakes = bake(&gpu, &s.geometry, &frames, settings(96, 4));
    verify_all_modes(&gpu, name, &bakes, &s.geometry);
}

/// CarConcept on tour frames around the opening driver door.
#[test]
fn car_concept_tour_range_verifies_in_every_mode() {
    let Some(gpu) = gpu() else { return };
    let Some(car) = real_scene("CarConcept") else {
        return;
    };
    let tour = trisort_paths::load(
        concat!(env!("CARGO_MANIFEST_DIR"), "/examples/car-tour.toml"),
        &car,
        &trisort_paths::PathOptions { fps: 30.0 },
    )
    .expect("tour loads");
    // Two frames: merged across frames, and each drawn by the reference in three modes.
    let frames = tour.frames[228..230].to_vec();
    assert!(
        frames.iter().all(|f| !f.poses.is_empty()),
        "the door is open"
    );
    let bakes = bake(&gpu, &car.geometry, &frames, settings(128, 4));
    verify_all_modes(&gpu, "CarConcept", &bakes, &car.geometry);
}

/// Textured alpha (BLEND leaves and glass).
#[test]
fn glass_vase_flowers_verifies_in_every_mode() {
    orbit_verifies_in_every_mode("GlassVaseFlowers", "orbit:frames=2,degrees=40");
}

/// Textured alpha (MASK and BLEND materials with alpha from textures).
#[test]
fn alpha_blend_mode_test_verifies_in_every_mode() {
    orbit_verifies_in_every_mode(
        "AlphaBlendModeTest",
        "orbit:frames=2,degrees=30,elevation=10",
    );
}

/// The default pipeline (opaque first, transparent unsorted in id order, depth writes off)
/// equals the exact reference where id order happens to be back-to-front, and differs where
/// it is not: what sorting buys.
#[test]
fn default_pipeline_is_exact_only_when_id_order_is_back_to_front() {
    let Some(gpu) = gpu() else { return };
    let frames = [frame_at(DVec3::ZERO)];
    let view = trisort_gpu::scene_gpu::View {
        width: 64,
        height: 64,
        samples: 4,
        glass_opacity: 0.0,
    };
    let render = |g: &Geometry| {
        let lighting = trisort_gpu::Lighting::default();
        let default = trisort_reference::DefaultRenderer::new(&gpu, g, &frames, view, lighting)
            .expect("default pipeline");
        let reference = trisort_reference::ExactReference::new(
            &gpu,
            g,
            &frames,
            lighting,
            reference_config(Mode::Blend),
        )
        .expect("reference");
        let d = default.render(0).expect("default frame");
        let r = reference.render(0, None).expect("reference frame");
        trisort_reference::compare(&d, &r.rgba8, 64, 64, &[])
    };
    let materials = [(RED, 0.5), ([0.1, 0.2, 0.9], 0.5), ([0.7; 3], 1.0)];
    let wall = ([-1.0, 1.0, -1.0, 1.0, -6.0, -6.0], 2);
    let far = ([-0.6, 0.4, -0.6, 0.4, -4.0, -4.0], 1);
    let near = ([-0.4, 0.6, -0.4, 0.6, -2.0, -2.0], 0);
    // Ids back to front: opaque wall, then the far transparent quad, then the near one.
    let c = render(&quads(&materials, &[wall, far, near]));
    assert_eq!(c.pixels_differing, 0, "{c:?}");
    // The same quads with the transparent ones in front-to-back id order.
    let c = render(&quads(&materials, &[wall, near, far]));
    // The overlap of the two transparent quads (about 8 × 10 pixels) is wrong.
    assert!(c.pixels_differing >= 60 && c.max_channel_diff > 10, "{c:?}");
    assert!(c.psnr < 45.0 && c.flip_mean > 0.0, "{c:?}");
}

/// Alpha from a texture whose texels are smaller than a pixel (a MASK checker and a BLEND
/// ramp, tilted): evaluated at the sample positions instead of the pixel centre, the recorder's
/// cut-outs and opacities would disagree with the player's inside a pixel and the images would
/// differ. Recorder and player both evaluate at the pixel centre.
#[test]
fn sub_pixel_texture_alpha_verifies_in_every_mode() {
    let Some(gpu) = gpu() else { return };
    let n = 64u32;
    let mut rgba8 = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for x in 0..n {
            let a = if (x + y) % 2 == 0 { 255 } else { (x * 4) as u8 };
            rgba8.extend_from_slice(&[(x * 4) as u8, 200, (y * 4) as u8, a]);
        }
    }
    let (texture, _) =
        trisort_scene::mips::texture_with_mips("checker".into(), n, n, rgba8, true, 1024);
    let textured = |mode| Material {
        base_color: [1.0, 1.0, 1.0, 1.0],
        base_color_texture: Some(0),
        alpha_mode: mode,
        alpha_cutoff: 0.5,
        double_sided: true,
        ..Default::default()
    };
    let mut g = scene(vec![
        textured(AlphaMode::Mask),
        textured(AlphaMode::Blend),
        material([0.6, 0.6, 0.6], 1.0),
    ]);
    g.textures.push(texture);
    quad(&mut g, [-1.0, 1.0], [-1.0, 1.0], [-6.0, -6.0], 2);
    quad(&mut g, [-0.8, 0.5], [-0.7, 0.6], [-2.0, -3.0], 0);
    quad(&mut g, [-0.4, 0.9], [-0.5, 0.8], [-2.5, -3.5], 1);
    // uv: four texels per pixel or so across the quads.
    for (k, v) in g.vertices.iter_mut().enumerate() {
        let corner = k % 4;
        v.uv = [
            if corner == 1 || corner == 2 { 2.5 } else { 0.0 },
            if corner >= 2 { 2.5 } else { 0.0 },
        ];
    }
    let frames = [frame_at(DVec3::ZERO), frame_at(DVec3::new(0.1, 0.05, 0.2))];
    let bakes = bake(&gpu, &g, &frames, settings(64, 4));
    verify_all_modes(&gpu, "sub-pixel texture alpha", &bakes, &g);
}

/// Ten stacked quads at opacity 0.6: seven with grey `front`, three bright ones behind. Seven
/// layers leave 0.4⁷ ≈ 0.0016 < 0.002: the samples saturate and the bright quads are never
/// visible (not in G) at the default threshold.
fn saturated_stack(front: f32) -> Geometry {
    let mut g = scene(vec![
        material([front; 3], 0.6),
        material([1.0, 1.0, 1.0], 0.6),
    ]);
    for k in 0..10 {
        let m = if k < 7 { 0 } else { 1 };
        let z = -2.0 - k as f32 * 0.3;
        quad(&mut g, [-0.7, 0.7], [-0.7, 0.7], [z, z], m);
    }
    g
}

/// Samples that saturate before their last fragment: the player leaves the hidden quads out,
/// the reference composites them; the difference is the residual transmittance times their
/// colour, within 1/255 behind a mid-grey stack.
#[test]
fn layers_behind_saturation_stay_within_tolerance() {
    let Some(gpu) = gpu() else { return };
    let g = saturated_stack(0.3);
    let frames = [frame_at(DVec3::ZERO)];
    let bakes = bake(&gpu, &g, &frames, settings(64, 4));
    assert_eq!(
        bakes.0.unique_visible.len(),
        14,
        "the three back quads are hidden"
    );
    let reports = verify_all_modes(&gpu, "saturated stack", &bakes, &g);
    for (mode, rs) in &reports {
        if *mode != Mode::Depth {
            assert_eq!(rs[0].layers, 10, "the reference composites every layer");
        }
    }
}

/// The limit of the 0.998 threshold: its residual (≤ 0.002 of what lies behind) is small in
/// linear light, but near black the sRGB encoding magnifies it (slope 12.92 at 0), so behind a
/// near-black stack the hidden bright quads show as 2/255 in `blend` and `saturate`, and the
/// frame fails the 1/255 gate. Recorded with threshold 1 (only opaque stops) the same scene
/// keeps every quad and verifies.
#[test]
fn dark_stack_shows_the_saturation_residual() {
    let Some(gpu) = gpu() else { return };
    let g = saturated_stack(0.01);
    let frames = [frame_at(DVec3::ZERO)];
    let (rec, baked) = bake(&gpu, &g, &frames, settings(64, 4));
    assert_eq!(rec.unique_visible.len(), 14);
    let r = &verify(&gpu, &baked, &g, Mode::Blend, Some(&rec))[0];
    assert!(!r.ok, "{r:?}");
    assert_eq!(r.unordered_samples, 0);
    assert_eq!(r.comparison.max_channel_diff_ordered, 2, "{r:?}");
    let (rec, baked) = bake(
        &gpu,
        &g,
        &frames,
        RecordSettings {
            saturation: 1.0,
            ..settings(64, 4)
        },
    );
    assert_eq!(rec.unique_visible.len(), 20);
    verify_all_modes(&gpu, "dark stack at threshold 1", &(rec, baked), &g);
}
