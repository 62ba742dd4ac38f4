//! The run-time rivals on a real scene: GlassVaseFlowers (textured BLEND leaves, transmissive
//! glass drawn at opacity 0.3) along an orbit, 1× and 4×. Per-sample linked-list OIT (inside
//! its budget) and GPU depth peeling both equal the exact reference byte for byte, in `blend`
//! and (peeling) `depth` mode; the default pipeline does not.

use trisort_gpu::scene_gpu::View;
use trisort_gpu::Lighting;
use trisort_player::Mode;
use trisort_reference::{
    DefaultRenderer, ExactReference, OitConfig, OitRenderer, PeelingConfig, PeelingRenderer,
    ReferenceConfig,
};
use trisort_testkit::gpu;

#[test]
fn oit_and_peeling_equal_the_reference_on_glass_vase_flowers() {
    let Some(gpu) = gpu() else { return };
    let Some(path) = trisort_testkit::scene_path("GlassVaseFlowers/GlassVaseFlowers.glb") else {
        return;
    };
    let scene = trisort_scene::load(&path).expect("scene loads");
    let frames = trisort_paths::load(
        "orbit:frames=2,degrees=60,elevation=10",
        &scene,
        &trisort_paths::PathOptions { fps: 30.0 },
    )
    .expect("path")
    .frames;
    let glass = 0.3;
    let size = (80, 80);
    let mut default_differs = false;
    for samples in [1, 4] {
        for mode in [Mode::Blend, Mode::Depth] {
            let config = ReferenceConfig {
                size,
                samples,
                mode,
                glass_opacity: glass,
                max_layers: 4096,
            };
            let exact =
                ExactReference::new(&gpu, &scene.geometry, &frames, Lighting::default(), config)
                    .expect("reference");
            let peeling = PeelingRenderer::new(
                &gpu,
                &scene.geometry,
                &frames,
                Lighting::default(),
                PeelingConfig {
                    glass_opacity: glass,
                    ..PeelingConfig::new(size, samples, mode, 4096)
                },
            )
            .expect("peeling");
            let oit = (mode == Mode::Blend).then(|| {
                let config = OitConfig {
                    glass_opacity: glass,
                    ..OitConfig::new(size, samples)
                };
                OitRenderer::new(&gpu, &scene.geometry, &frames, Lighting::default(), config)
                    .expect("oit")
            });
            let default = (mode == Mode::Blend).then(|| {
                DefaultRenderer::new(
                    &gpu,
                    &scene.geometry,
                    &frames,
                    View {
                        width: size.0,
                        height: size.1,
                        samples,
                        glass_opacity: glass,
                    },
                    Lighting::default(),
                )
                .expect("default")
            });
            for f in 0..frames.len() as u32 {
                let r = exact.render(f, None).expect("reference frame");
                let p = peeling.render(f).expect("peeled frame");
                assert!(!p.truncated);
                assert!(
                    p.rgba8 == r.rgba8,
                    "peeling {samples}x {} frame {f} differs from the reference",
                    mode.name()
                );
                if let Some(oit) = &oit {
                    let o = oit.render(f).expect("oit frame");
                    assert_eq!((o.dropped, o.overflowed_samples), (0, 0));
                    assert!(o.rgba8 == r.rgba8, "oit {samples}x frame {f} differs");
                }
                if let Some(d) = &default {
                    default_differs |= d.render(f).expect("default frame") != r.rgba8;
                }
            }
        }
    }
    assert!(
        default_differs,
        "unsorted glass and leaves should differ somewhere"
    );
}
