//! The GPU-only depth peeling renderer against the exact reference, on scenes built here with
//! known layer counts: stacked transparent quads, coplanar ties, an opaque occluder, a random
//! soup of overlapping triangles, at 1× and 4×, in `blend` and `depth`, and a truncated frame.
//!
//! Tolerance: none. The renderer keeps the reference's keys, per-pixel shading, back-to-front
//! order and blend state, so every frame must equal the reference's byte for byte.

use glam::DVec3;
use trisort_format::{FrameState, Geometry, Vertex};
use trisort_gpu::{Gpu, Lighting};
use trisort_player::Mode;
use trisort_reference::{
    ExactReference, PeelingConfig, PeelingRenderer, ReferenceConfig, ReferenceError,
};
use trisort_testkit::fixtures::{frame_at, material, quad, scene};
use trisort_testkit::gpu;

// ---- scenes built here: camera at the origin looking down −Z ----

/// `n` transparent quads of distinct colours stacked along −Z, each a little smaller than the
/// one behind it, all covering the image centre.
fn stack(n: u32) -> Geometry {
    let mut g = scene(
        (0..n)
            .map(|k| {
                let t = k as f32 / n.max(1) as f32;
                material([t, 1.0 - t, 0.5 + 0.4 * t], 0.35 + 0.05 * k as f32)
            })
            .collect(),
    );
    for k in 0..n {
        let z = -2.0 - k as f32;
        let r = 0.5 + 0.3 * k as f32;
        quad(&mut g, [-r, r], [-r, r * 0.8], [z, z], k);
    }
    g
}

/// Small deterministic generator (the tests need no crate for it).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }
}

/// A soup of `n` random triangles in front of the camera: transparent and opaque, single- and
/// double-sided, tilted so they interpenetrate, with every fifth one an exact copy of an
/// earlier one (coplanar ties of different colour).
fn soup(n: u32, seed: u64) -> Geometry {
    let mut rng = Lcg(seed);
    let mut materials = Vec::new();
    for k in 0..8 {
        let mut m = material(
            [rng.next(), rng.next(), rng.next()],
            if k % 4 == 3 { 1.0 } else { rng.range(0.2, 0.8) },
        );
        m.double_sided = k % 3 != 1;
        materials.push(m);
    }
    let mut g = scene(materials);
    for t in 0..n {
        let material = (rng.next() * 8.0) as u32 % 8;
        let base = g.vertices.len() as u32;
        if t % 5 == 4 && t > 0 {
            let src = g.triangles[(rng.next() * t as f32) as usize % t as usize];
            for v in src {
                let mut vertex = g.vertices[v as usize];
                vertex.material = material;
                g.vertices.push(vertex);
            }
        } else {
            let (cx, cy, cz) = (
                rng.range(-1.5, 1.5),
                rng.range(-1.5, 1.5),
                rng.range(-6.0, -1.5),
            );
            for _ in 0..3 {
                let p = [
                    cx + rng.range(-1.2, 1.2),
                    cy + rng.range(-1.2, 1.2),
                    cz + rng.range(-1.0, 1.0),
                ];
                let n = [rng.range(-0.5, 0.5), rng.range(-0.5, 0.5), 1.0];
                g.vertices.push(Vertex {
                    position: p,
                    normal: n,
                    uv: [0.0; 2],
                    material,
                    node: 0,
                    tangent: [0.0; 4],
                    uv1: [0.0; 2],
                });
            }
        }
        g.triangles.push([base, base + 1, base + 2]);
    }
    g
}

fn frames() -> Vec<FrameState> {
    vec![frame_at(DVec3::ZERO), frame_at(DVec3::new(0.3, -0.2, 0.5))]
}

// ---- comparison ----

struct Rendered {
    layers: u32,
    truncated: bool,
}

/// How both renderers render in [`same_as_reference`]: square images of `size` pixels at
/// `samples`, in `mode`, peeling at most `max_layers`.
#[derive(Clone, Copy)]
struct Setup {
    size: u32,
    samples: u32,
    mode: Mode,
    max_layers: u32,
}

/// Renders every frame with both renderers, asserts the images are identical and the layer
/// counts agree, and returns the peeling renderer's counts.
fn same_as_reference(
    gpu: &Gpu,
    name: &str,
    geometry: &Geometry,
    frames: &[FrameState],
    setup: Setup,
) -> Vec<Rendered> {
    let Setup {
        size,
        samples,
        mode,
        max_layers,
    } = setup;
    let reference = ExactReference::new(
        gpu,
        geometry,
        frames,
        Lighting::default(),
        ReferenceConfig {
            size: (size, size),
            samples,
            mode,
            glass_opacity: 0.0,
            max_layers,
        },
    )
    .expect("reference");
    let peeling = PeelingRenderer::new(
        gpu,
        geometry,
        frames,
        Lighting::default(),
        PeelingConfig::new((size, size), samples, mode, max_layers),
    )
    .expect("peeling renderer");
    assert_eq!(peeling.triangles(), geometry.triangles.len() as u64);
    (0..frames.len() as u32)
        .map(|f| {
            let want = reference.render(f, None).expect("reference frame");
            let got = peeling.render(f).expect("peeled frame");
            let differing: Vec<usize> = (0..got.rgba8.len())
                .filter(|&i| got.rgba8[i] != want.rgba8[i])
                .collect();
            let max = differing
                .iter()
                .map(|&i| got.rgba8[i].abs_diff(want.rgba8[i]))
                .max()
                .unwrap_or(0);
            assert!(
                differing.is_empty(),
                "{name} frame {f} {samples}x {mode:?}: {} channels differ from the exact \
                 reference (max {max}), first at pixel {}",
                differing.len(),
                differing[0] / 4
            );
            let want_layers = if mode == Mode::Depth {
                want.layers.min(1)
            } else {
                want.layers
            };
            assert_eq!(got.layers, want_layers, "{name} frame {f}: layers");
            assert_eq!(got.truncated, want.truncated, "{name} frame {f}: truncated");
            assert_eq!(peeling.layers(f).expect("cached"), got.layers);
            Rendered {
                layers: got.layers,
                truncated: got.truncated,
            }
        })
        .collect()
}

/// [`same_as_reference`] for a stack seen head-on: one frame, 48 pixels, `blend`.
fn one_frame_stack(gpu: &Gpu, g: &Geometry, samples: u32, max_layers: u32) -> Vec<Rendered> {
    let frame = [frame_at(DVec3::ZERO)];
    same_as_reference(
        gpu,
        "stack",
        g,
        &frame,
        Setup {
            size: 48,
            samples,
            mode: Mode::Blend,
            max_layers,
        },
    )
}

// ---- tests ----

#[test]
fn stacked_quads_peel_as_many_layers_as_the_stack_is_deep() {
    let Some(gpu) = gpu() else { return };
    for n in [1, 3, 6] {
        let g = stack(n);
        for samples in [1, 4] {
            let r = one_frame_stack(&gpu, &g, samples, 64);
            assert_eq!(r[0].layers, n, "{n} quads at {samples}x");
            assert!(!r[0].truncated);
        }
    }
}

#[test]
fn coplanar_ties_resolve_by_id_as_in_the_reference() {
    let Some(gpu) = gpu() else { return };
    // Three coplanar quads of different colours, overlapping in part, behind one tilted quad
    // that cuts through them, and a coplanar pair facing away (double-sided).
    let mut g = scene(vec![
        material([1.0, 0.0, 0.0], 0.5),
        material([0.0, 1.0, 0.0], 0.6),
        material([0.0, 0.0, 1.0], 0.4),
        material([1.0, 1.0, 0.0], 0.7),
    ]);
    quad(&mut g, [-1.0, 0.6], [-1.0, 0.6], [-3.0, -3.0], 0);
    quad(&mut g, [-0.6, 1.0], [-0.6, 1.0], [-3.0, -3.0], 1);
    quad(&mut g, [-0.8, 0.8], [-0.3, 0.3], [-3.0, -3.0], 2);
    quad(&mut g, [-1.2, 1.2], [-1.2, 1.2], [-2.0, -4.0], 3);
    quad(&mut g, [0.6, -0.6], [-0.9, 0.2], [-2.5, -2.5], 0);
    quad(&mut g, [0.6, -0.6], [-0.9, 0.2], [-2.5, -2.5], 2);
    for samples in [1, 4] {
        for mode in [Mode::Blend, Mode::Depth] {
            let r = same_as_reference(
                &gpu,
                "coplanar",
                &g,
                &frames(),
                Setup {
                    size: 64,
                    samples,
                    mode,
                    max_layers: 64,
                },
            );
            if mode == Mode::Blend {
                assert_eq!(r[0].layers, 6, "{samples}x");
            }
        }
    }
}

#[test]
fn an_opaque_occluder_is_peeled_through_like_the_reference() {
    let Some(gpu) = gpu() else { return };
    let mut g = stack(4);
    g.materials.push(material([0.9, 0.9, 0.9], 1.0));
    // Opaque, between the second and third quad, covering the left half.
    quad(&mut g, [-2.0, 0.0], [-2.0, 2.0], [-3.5, -3.5], 4);
    for samples in [1, 4] {
        for mode in [Mode::Blend, Mode::Depth] {
            let r = same_as_reference(
                &gpu,
                "occluder",
                &g,
                &frames(),
                Setup {
                    size: 64,
                    samples,
                    mode,
                    max_layers: 64,
                },
            );
            let want = if mode == Mode::Depth { 1 } else { 5 };
            assert_eq!(r[0].layers, want, "{samples}x {mode:?}");
        }
    }
}

#[test]
fn a_soup_of_interpenetrating_triangles_matches_the_reference() {
    let Some(gpu) = gpu() else { return };
    let g = soup(300, 7);
    for samples in [1, 4] {
        for mode in [Mode::Blend, Mode::Depth] {
            let r = same_as_reference(
                &gpu,
                "soup",
                &g,
                &frames(),
                Setup {
                    size: 96,
                    samples,
                    mode,
                    max_layers: 256,
                },
            );
            assert!(r.iter().all(|r| !r.truncated));
            if mode == Mode::Blend {
                assert!(r[0].layers > 5, "a deep soup: {} layers", r[0].layers);
            }
        }
    }
}

#[test]
fn depth_mode_draws_the_first_layer_only() {
    let Some(gpu) = gpu() else { return };
    let g = stack(5);
    for samples in [1, 4] {
        let r = same_as_reference(
            &gpu,
            "stack",
            &g,
            &frames(),
            Setup {
                size: 48,
                samples,
                mode: Mode::Depth,
                max_layers: 64,
            },
        );
        assert!(r.iter().all(|r| r.layers == 1 && !r.truncated));
    }
}

#[test]
fn a_frame_beyond_max_layers_is_truncated_to_its_front_layers() {
    let Some(gpu) = gpu() else { return };
    let g = stack(6);
    for samples in [1, 4] {
        for max_layers in [1, 2, 5] {
            let r = one_frame_stack(&gpu, &g, samples, max_layers);
            assert_eq!(r[0].layers, max_layers);
            assert!(r[0].truncated, "6 quads, at most {max_layers} layers");
        }
        // Exactly as many layers as the stack: complete.
        let r = one_frame_stack(&gpu, &g, samples, 6);
        assert_eq!((r[0].layers, r[0].truncated), (6, false));
    }
}

#[test]
fn an_empty_view_has_no_layer_and_shows_the_background() {
    let Some(gpu) = gpu() else { return };
    let mut g = stack(2);
    // Behind the camera.
    for v in &mut g.vertices {
        v.position[2] = -v.position[2];
    }
    for mode in [Mode::Blend, Mode::Depth] {
        let r = same_as_reference(
            &gpu,
            "behind",
            &g,
            &frames(),
            Setup {
                size: 32,
                samples: 4,
                mode,
                max_layers: 8,
            },
        );
        assert!(r.iter().all(|r| r.layers == 0 && !r.truncated));
    }
    let empty = scene(vec![]);
    let r = same_as_reference(
        &gpu,
        "empty",
        &empty,
        &frames(),
        Setup {
            size: 32,
            samples: 1,
            mode: Mode::Blend,
            max_layers: 8,
        },
    );
    assert_eq!(r[0].layers, 0);
}

#[test]
fn encode_records_a_frame_without_readback_and_counts_passes() {
    let Some(gpu) = gpu() else { return };
    let g = stack(3);
    let fs = [frame_at(DVec3::ZERO)];
    let peeling = PeelingRenderer::new(
        &gpu,
        &g,
        &fs,
        Lighting::default(),
        PeelingConfig::new((32, 32), 4, Mode::Blend, 16),
    )
    .unwrap();
    let layers = peeling.layers(0).unwrap();
    assert_eq!(layers, 3);
    let stats = gpu
        .device
        .features()
        .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
        .then(|| {
            gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("peeling stats"),
                ty: wgpu::QueryType::PipelineStatistics(
                    wgpu::PipelineStatisticsTypes::CLIPPER_INVOCATIONS,
                ),
                count: layers,
            })
        });
    let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    peeling.encode(&mut enc, 0, layers, stats.as_ref());
    gpu.queue.submit([enc.finish()]);
    assert!(pollster::block_on(scope.pop()).is_none());
    // Rendering again gives the same frame (no state carried between frames).
    let a = peeling.render(0).unwrap();
    let b = peeling.render(0).unwrap();
    assert_eq!(a, b);
    assert_eq!(peeling.target().format(), wgpu::TextureFormat::Rgba16Float);
}

#[test]
fn saturate_and_bad_patterns_are_rejected() {
    let Some(gpu) = gpu() else { return };
    let g = stack(1);
    let fs = [frame_at(DVec3::ZERO)];
    let new = |size, samples, mode| {
        PeelingRenderer::new(
            &gpu,
            &g,
            &fs,
            Lighting::default(),
            PeelingConfig::new(size, samples, mode, 8),
        )
    };
    assert!(matches!(
        new((8, 8), 4, Mode::Saturate),
        Err(ReferenceError::Invalid(_))
    ));
    assert!(matches!(
        new((8, 8), 2, Mode::Blend),
        Err(ReferenceError::Invalid(_))
    ));
    assert!(matches!(
        new((0, 8), 1, Mode::Blend),
        Err(ReferenceError::Invalid(_))
    ));
    let r = new((8, 8), 1, Mode::Blend).unwrap();
    assert!(matches!(r.layers(1), Err(ReferenceError::Invalid(_))));
}
