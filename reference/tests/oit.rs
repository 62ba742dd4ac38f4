//! The per-sample linked-list OIT renderer against the exact reference in `blend` mode: small
//! scenes built here (stacked and intersecting transparent quads, coplanar triangles whose
//! order only the id tie-break decides, opaque in front, at 1 and 4 samples) and its budgets
//! (a pool too small drops fragments, a sort array too short overflows).
//!
//! Tolerance: none. Within its budgets the OIT frame equals the reference's bit for bit: both
//! shade with the player's `player_colour` at the pixel centre, order each sample's fragments
//! by (rasterized depth, id), and round to binary16 after every `over` (the OIT resolve in the
//! shader, toward zero like lavapipe's blend unit; the reference in its `Rgba16Float` blend
//! unit), then resolve MSAA with the same pass and quantize once. Real scenes need
//! `trisort-scene` and `trisort-paths`, which this crate does not depend on: they were
//! compared outside the test suite (GlassVaseFlowers, AlphaBlendModeTest, CarConcept: equal).

use glam::DVec3;
use trisort_format::{FrameState, Geometry};
use trisort_gpu::{Gpu, Lighting};
use trisort_player::Mode;
use trisort_reference::{
    ExactReference, OitConfig, OitFrame, OitRenderer, ReferenceConfig, ReferenceError,
};
use trisort_testkit::fixtures::{frame_at, material, scene, split_quad, tri};
use trisort_testkit::gpu;

// ---- scenes built here: camera at the origin looking down −Z ----

/// Two frames: straight on, and from the side so the quads' edges are not aligned.
fn frames() -> Vec<FrameState> {
    vec![
        frame_at(DVec3::ZERO),
        frame_at(DVec3::new(0.37, -0.21, 0.4)),
    ]
}

// ---- comparison ----

fn reference<'g>(
    gpu: &'g Gpu,
    g: &Geometry,
    frames: &[FrameState],
    size: u32,
    samples: u32,
) -> ExactReference<'g> {
    let config = ReferenceConfig {
        size: (size, size),
        samples,
        mode: Mode::Blend,
        glass_opacity: trisort_format::RecordSettings::default().glass_opacity,
        max_layers: 256,
    };
    ExactReference::new(gpu, g, frames, Lighting::default(), config).expect("exact reference")
}

/// Channels that differ and the largest difference.
fn diff(a: &[u8], b: &[u8]) -> (usize, u8) {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .filter(|(x, y)| x != y)
        .fold((0, 0), |(n, m), (x, y)| (n + 1, m.max(x.abs_diff(*y))))
}

/// Renders every frame with both renderers, asserts the OIT frames are within budget and
/// equal to the reference's, and returns them.
fn assert_matches(name: &str, g: &Geometry, frames: &[FrameState], size: u32) -> Vec<OitFrame> {
    let Some(gpu) = gpu() else { return vec![] };
    let mut out = vec![];
    for samples in [1, 4] {
        let exact = reference(&gpu, g, frames, size, samples);
        let oit = OitRenderer::new(
            &gpu,
            g,
            frames,
            Lighting::default(),
            OitConfig::new((size, size), samples),
        )
        .expect("oit renderer");
        for f in 0..frames.len() as u32 {
            let r = exact.render(f, None).expect("reference frame");
            let o = oit.render(f).expect("oit frame");
            let (n, max) = diff(&o.rgba8, &r.rgba8);
            eprintln!(
                "{name} {samples}x frame {f}: {} fragments, {} dropped, {} overflowed, {} layers; \
                 {n} channels differ, max {max}",
                o.fragments, o.dropped, o.overflowed_samples, r.layers
            );
            let pixels = o.rgba8.chunks(4).zip(r.rgba8.chunks(4)).enumerate();
            for (i, (x, y)) in pixels.filter(|(_, (x, y))| x != y).take(8) {
                let (px, py) = (i as u32 % size, i as u32 / size);
                eprintln!("  pixel ({px}, {py}): oit {x:?}, reference {y:?}");
            }
            assert_eq!(
                (o.dropped, o.overflowed_samples),
                (0, 0),
                "{name}: within budget"
            );
            assert!(o.fragments > 0, "{name}: something drawn");
            assert_eq!(
                (n, max),
                (0, 0),
                "{name} {samples}x frame {f}: OIT equals the reference"
            );
            out.push(o);
        }
    }
    out
}

/// Three overlapping transparent quads at different depths, two of them tilted through each
/// other (the order changes inside a pixel), over a partly uncovered background.
fn stacked() -> Geometry {
    let mut g = scene(vec![
        material([0.9, 0.2, 0.1], 0.5),
        material([0.1, 0.8, 0.3], 0.35),
        material([0.2, 0.3, 0.95], 0.7),
    ]);
    split_quad(&mut g, [-1.5, 0.9], [-1.2, 0.8], [-3.0, -3.0], 0);
    split_quad(&mut g, [-0.7, 1.6], [-0.6, 1.4], [-2.2, -4.1], 1);
    split_quad(&mut g, [-1.1, 1.2], [-1.5, 0.3], [-4.0, -2.0], 2);
    tri(
        &mut g,
        [[-1.8, -1.7, -2.5], [1.7, -1.1, -3.5], [0.2, 1.9, -3.2]],
        1,
    );
    g
}

#[test]
fn stacked_transparent_quads_match_the_reference() {
    assert_matches("stacked", &stacked(), &frames(), 48);
}

/// Coplanar triangles: only the id decides their order, and it shows (the colours differ).
#[test]
fn coplanar_triangles_break_ties_by_id() {
    let build = |first: u32| {
        let mut g = scene(vec![
            material([0.95, 0.1, 0.1], 0.6),
            material([0.1, 0.1, 0.95], 0.6),
        ]);
        split_quad(&mut g, [-1.0, 1.0], [-1.0, 1.0], [-2.5, -3.0], first);
        split_quad(&mut g, [-1.4, 0.6], [-0.7, 1.3], [-2.5, -3.0], 1 - first);
        g
    };
    let a = assert_matches("coplanar red first", &build(0), &frames(), 40);
    let b = assert_matches("coplanar blue first", &build(1), &frames(), 40);
    if !a.is_empty() {
        assert_ne!(a[0].rgba8, b[0].rgba8, "the tie-break decides the colour");
    }
}

/// Opaque in front of transparent, transparent in front of opaque, and opaque behind opaque.
#[test]
fn opaque_in_front_matches_the_reference() {
    let mut g = scene(vec![
        material([0.8, 0.8, 0.2], 1.0),
        material([0.2, 0.7, 0.9], 0.4),
        material([0.6, 0.1, 0.6], 1.0),
    ]);
    split_quad(&mut g, [-1.5, 1.5], [-1.5, 1.5], [-5.0, -5.0], 2);
    split_quad(&mut g, [-1.0, 0.5], [-1.0, 1.0], [-3.0, -3.0], 1);
    split_quad(&mut g, [-0.2, 1.2], [-0.8, 0.6], [-2.0, -2.6], 0);
    split_quad(&mut g, [-1.3, 0.0], [0.2, 1.2], [-1.5, -1.5], 1);
    let oit = assert_matches("opaque", &g, &frames(), 40);
    for o in &oit {
        assert_eq!(o.dropped, 0);
    }
}

/// `layers` full-screen transparent quads: every sample holds `layers` fragments.
fn full_screen_layers(layers: u32) -> Geometry {
    let mut g = scene(vec![material([0.5, 0.6, 0.7], 0.3)]);
    for k in 0..layers {
        let z = -2.0 - k as f32 * 0.25;
        split_quad(&mut g, [-5.0, 5.0], [-5.0, 5.0], [z, z], 0);
    }
    g
}

#[test]
fn a_full_pool_drops_fragments_and_says_how_many() {
    let Some(gpu) = gpu() else { return };
    let g = full_screen_layers(3);
    let frames = vec![frame_at(DVec3::ZERO)];
    for samples in [1, 4] {
        let config = OitConfig {
            nodes_per_sample: 2,
            ..OitConfig::new((16, 16), samples)
        };
        let oit =
            OitRenderer::new(&gpu, &g, &frames, Lighting::default(), config).expect("oit renderer");
        let o = oit.render(0).expect("frame");
        let samples_total = 16 * 16 * samples as u64;
        assert_eq!(
            o.fragments,
            3 * samples_total,
            "every covered sample, every layer"
        );
        assert_eq!(o.dropped, samples_total, "a third does not fit");
        assert_eq!(o.overflowed_samples, 0);
        // The budget large enough again: exact.
        let fits = OitRenderer::new(
            &gpu,
            &g,
            &frames,
            Lighting::default(),
            OitConfig {
                nodes_per_sample: 3,
                ..config
            },
        )
        .expect("oit renderer")
        .render(0)
        .expect("frame");
        assert_eq!(fits.dropped, 0);
        let r = reference(&gpu, &g, &frames, 16, samples)
            .render(0, None)
            .unwrap();
        assert_eq!(fits.rgba8, r.rgba8);
        assert_ne!(o.rgba8, r.rgba8, "lost fragments show");
    }
}

#[test]
fn a_short_sort_array_overflows_and_keeps_the_nearest() {
    let Some(gpu) = gpu() else { return };
    let g = full_screen_layers(6);
    let frames = vec![frame_at(DVec3::ZERO)];
    let config = OitConfig {
        max_sorted: 4,
        ..OitConfig::new((16, 16), 4)
    };
    let o = OitRenderer::new(&gpu, &g, &frames, Lighting::default(), config)
        .expect("oit renderer")
        .render(0)
        .expect("frame");
    assert_eq!(o.dropped, 0);
    assert_eq!(
        o.overflowed_samples,
        16 * 16 * 4,
        "every sample holds 6 > 4"
    );
    // The nearest four of six equal the reference of those four alone.
    let near = full_screen_layers(4);
    let r = reference(&gpu, &near, &frames, 16, 4)
        .render(0, None)
        .unwrap();
    assert_eq!(o.rgba8, r.rgba8);
    // A long enough array: no overflow, the reference of all six.
    let all = OitRenderer::new(
        &gpu,
        &g,
        &frames,
        Lighting::default(),
        OitConfig {
            max_sorted: 6,
            ..config
        },
    )
    .expect("oit renderer")
    .render(0)
    .expect("frame");
    assert_eq!(all.overflowed_samples, 0);
    let r = reference(&gpu, &g, &frames, 16, 4).render(0, None).unwrap();
    assert_eq!(all.rgba8, r.rgba8);
}

#[test]
fn bad_configurations_are_errors_not_panics() {
    let Some(gpu) = gpu() else { return };
    let g = full_screen_layers(1);
    let frames = vec![frame_at(DVec3::ZERO)];
    let try_new =
        |config| OitRenderer::new(&gpu, &g, &frames, Lighting::default(), config).map(|_| ());
    assert!(matches!(
        try_new(OitConfig::new((16, 16), 2)),
        Err(ReferenceError::Invalid(_))
    ));
    assert!(matches!(
        try_new(OitConfig {
            max_sorted: 0,
            ..OitConfig::new((16, 16), 1)
        }),
        Err(ReferenceError::Invalid(_))
    ));
    // A pool beyond what one storage buffer binds.
    let huge = OitConfig {
        nodes_per_sample: 4096,
        ..OitConfig::new((2048, 2048), 4)
    };
    let e = try_new(huge).expect_err("too large a pool");
    assert!(
        matches!(
            e,
            ReferenceError::Unsupported(_) | ReferenceError::Invalid(_)
        ),
        "{e}"
    );
    eprintln!("{e}");
    // No triangles at all: the background.
    let empty = scene(vec![material([1.0, 1.0, 1.0], 0.5)]);
    let o = OitRenderer::new(
        &gpu,
        &empty,
        &frames,
        Lighting::default(),
        OitConfig::new((8, 8), 4),
    )
    .expect("oit renderer")
    .render(0)
    .expect("frame");
    assert_eq!(o.fragments, 0);
    let r = reference(&gpu, &empty, &frames, 8, 4)
        .render(0, None)
        .unwrap();
    assert_eq!(o.rgba8, r.rgba8);
}

#[test]
fn describe_and_counts() {
    let c = OitConfig::new((256, 256), 4);
    assert_eq!(c.nodes(), 16 * 256 * 256 * 4);
    assert_eq!(
        c.describe(),
        "16 fragments/sample pool (112.0 MiB), 32-entry sort"
    );
}

/// A pool larger than one storage buffer binding (128 MiB on lavapipe) is split over several:
/// 512² at 4× with 9 full-screen layers stores 9.4 M nodes (264 MiB) across three buffers.
#[test]
fn a_pool_split_over_several_buffers() {
    let Some(gpu) = gpu() else { return };
    let g = full_screen_layers(9);
    let frames = vec![frame_at(DVec3::ZERO)];
    // 10 nodes per sample: 280 MiB, room for the 9 layers.
    let config = OitConfig {
        nodes_per_sample: 10,
        ..OitConfig::new((512, 512), 4)
    };
    let o = match OitRenderer::new(&gpu, &g, &frames, Lighting::default(), config) {
        Ok(oit) => oit.render(0).expect("frame"),
        Err(e @ ReferenceError::Unsupported(_)) => {
            eprintln!("skipping: {e}");
            return;
        }
        Err(e) => panic!("{e}"),
    };
    assert_eq!(o.fragments, 9 * 512 * 512 * 4);
    assert_eq!((o.dropped, o.overflowed_samples), (0, 0));
    // Every pixel shows the same nine layers: the reference's pixel of a small image.
    let r = reference(&gpu, &g, &frames, 8, 4).render(0, None).unwrap();
    let expected = &r.rgba8[..4];
    assert!(o.rgba8.chunks(4).all(|px| px == expected));
}

/// `encode` with a pipeline-statistics query set (as `bench` records frames): the list pass
/// is bracketed, and counts the scene's triangles reaching the clipper.
#[test]
fn encode_brackets_the_list_pass_with_statistics_queries() {
    let Some(gpu) = gpu() else { return };
    if !gpu
        .device
        .features()
        .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
    {
        eprintln!("skipping: no pipeline statistics queries");
        return;
    }
    let g = stacked();
    let frames = frames();
    let oit = OitRenderer::new(
        &gpu,
        &g,
        &frames,
        Lighting::default(),
        OitConfig::new((32, 32), 4),
    )
    .expect("oit");
    assert_eq!(oit.passes(), 1);
    assert_eq!(oit.triangles(), g.triangles.len() as u64);
    let device = &gpu.device;
    let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
        label: Some("oit statistics"),
        ty: wgpu::QueryType::PipelineStatistics(wgpu::PipelineStatisticsTypes::CLIPPER_INVOCATIONS),
        count: oit.passes(),
    });
    let resolved = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("oit statistics"),
        size: 8 * oit.passes() as u64,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let mut enc = device.create_command_encoder(&Default::default());
    oit.encode(&mut enc, 1, Some(&queries));
    enc.resolve_query_set(&queries, 0..oit.passes(), &resolved, 0);
    gpu.queue.submit([enc.finish()]);
    assert!(pollster::block_on(scope.pop()).is_none(), "valid commands");
    let counts: Vec<u64> = bytemuck::pod_collect_to_vec(&gpu.read_buffer(&resolved, 0, 8));
    // Every triangle reaches the clipper on lavapipe; other devices may count fewer.
    assert!(
        (1..=g.triangles.len() as u64).contains(&counts[0]),
        "{counts:?}"
    );
    // The renderer still renders afterwards.
    assert!(oit.render(1).expect("frame").fragments > 0);
}

/// Lit colour varying across each triangle (per-vertex normals) at 4×: the list pass shades
/// per sample, yet its colour must be the player's per-pixel one (`uv` and `normal` are
/// centre-interpolated), or edge pixels would differ.
#[test]
fn shading_varies_across_triangles_like_the_players() {
    let mut g = stacked();
    let normals = [[0.6, -0.3, 0.7], [-0.5, 0.4, 0.8], [0.1, 0.9, 0.3]];
    for (k, v) in g.vertices.iter_mut().enumerate() {
        v.normal = normals[k % 3];
    }
    assert_matches("varying normals", &g, &frames(), 48);
}
