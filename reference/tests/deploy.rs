//! The player on an 8-bit sRGB target (`Srgb8Player`) against the exact reference at 4× on a
//! bright emissive scene: colours far above 1, if not tone mapped, would be clamped per sample
//! before the MSAA resolve on the 8-bit target but not in the reference (118/255 apart at
//! edges); PBR shading tone maps each fragment into [0, 1] before blending and resolve, so the
//! two agree within 1/255.

use glam::DVec3;
use trisort_format::{AlphaMode, Environment, Geometry, Material};
use trisort_gpu::{Gpu, Lighting, Shading, ToneMap};
use trisort_player::Mode;
use trisort_reference::exact::whole_scene_baked;
use trisort_reference::{ExactReference, ReferenceConfig, Srgb8Player};
use trisort_testkit::fixtures::{frame_at, scene, settings, tri};
use trisort_testkit::gpu;

const SIZE: u32 = 48;

/// Emissive triangles far above 1 with slanted edges, at z = −2 (opaque, higher ids) and a
/// half-transparent one in front (id 0): the whole scene in id order plays back to front in
/// `blend` and front to back in `saturate`, both correct here.
fn bright_scene() -> Geometry {
    let glow = |emissive: [f32; 3], alpha: f32| Material {
        base_color: [0.8, 0.8, 0.8, alpha],
        alpha_mode: if alpha < 1.0 {
            AlphaMode::Blend
        } else {
            AlphaMode::Opaque
        },
        emissive,
        double_sided: true,
        metallic: 0.0,
        ..Default::default()
    };
    let mut g = scene(vec![
        glow([3.0, 12.0, 6.0], 0.5),
        glow([40.0, 8.0, 2.0], 1.0),
        glow([5.0, 5.0, 30.0], 1.0),
    ]);
    tri(
        &mut g,
        [[-0.6, -0.5, -1.0], [0.45, -0.3, -1.0], [-0.1, 0.55, -1.0]],
        0,
    );
    tri(
        &mut g,
        [[-1.7, -1.5, -2.0], [0.3, -1.2, -2.0], [-0.9, 1.1, -2.0]],
        1,
    );
    tri(
        &mut g,
        [[0.4, -1.6, -2.0], [1.8, 0.2, -2.0], [0.5, 1.4, -2.0]],
        2,
    );
    g
}

fn max_rgb_diff(a: &[u8], b: &[u8]) -> u8 {
    a.chunks(4)
        .zip(b.chunks(4))
        .flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c])))
        .max()
        .unwrap()
}

/// The largest channel difference between the 8-bit sRGB player and the exact reference.
fn srgb8_error(gpu: &Gpu, mode: Mode, shading: Shading, environment: &Environment) -> u8 {
    let g = bright_scene();
    let frames = [
        frame_at(DVec3::ZERO),
        frame_at(DVec3::new(0.13, -0.07, 0.2)),
    ];
    let baked = whole_scene_baked(&g, &frames, settings(SIZE, 4), environment);
    let lighting = Lighting {
        shading,
        tone_map: ToneMap::Neutral,
        environment,
    };
    let player = Srgb8Player::with_shading(
        gpu,
        &baked,
        (SIZE, SIZE),
        4,
        mode,
        (shading, ToneMap::Neutral),
    )
    .expect("sRGB player");
    let config = ReferenceConfig {
        glass_opacity: baked.settings.glass_opacity,
        max_layers: 64,
        ..ReferenceConfig::recorded(&baked, mode)
    };
    let reference = ExactReference::new(gpu, &g, &frames, lighting, config).expect("reference");
    (0..frames.len() as u32)
        .map(|f| {
            let p = player.render(f).expect("sRGB frame");
            let r = reference.render(f, None).expect("reference frame").rgba8;
            max_rgb_diff(&p, &r)
        })
        .max()
        .unwrap()
}

#[test]
fn the_8_bit_srgb_player_matches_the_reference_on_bright_emissive_edges() {
    let Some(gpu) = gpu() else { return };
    let mut env = Environment::uniform(0.5);
    env.exposure = 1.5;
    for mode in [Mode::Blend, Mode::Saturate] {
        let pbr = srgb8_error(&gpu, mode, Shading::Pbr, &env);
        assert!(pbr <= 1, "{mode}: pbr {pbr}/255");
        // The scene exercises the clamp: the basic model (no tone map) is far apart.
        let basic = srgb8_error(&gpu, mode, Shading::Basic, &env);
        assert!(basic > 16, "{mode}: basic only {basic}/255 apart");
    }
}
