//! GPU tests of the player (lavapipe in CI; skipped without an adapter unless
//! `TRISORT_REQUIRE_GPU=1`): the calls a frame issues, the images of each mode, both index
//! widths, both draw paths, and a pipeline-statistics cross-check.

use trisort_format::{Baked, DrawIndexedIndirectArgs};
use trisort_gpu::Gpu;
use trisort_player::{
    Call, CallLog, DrawPath, HeadlessConfig, HeadlessRenderer, Mode, Player, PlayerConfig,
    PlayerError, BACKGROUND,
};

use crate::support::*;

fn gpu() -> Option<Gpu> {
    std::env::set_var(
        "XDG_RUNTIME_DIR",
        std::env::var("XDG_RUNTIME_DIR").unwrap_or("/tmp".into()),
    );
    trisort_testkit::gpu()
}

fn config(mode: Mode, draw_path: DrawPath) -> PlayerConfig {
    let baked = quads();
    PlayerConfig {
        mode,
        draw_path,
        depth_format: (mode == Mode::Depth).then_some(wgpu::TextureFormat::Depth32Float),
        // The pixels these tests expect are `support::lit`'s: the basic model.
        shading: trisort_gpu::Shading::Basic,
        ..PlayerConfig::recorded(&baked, wgpu::TextureFormat::Rgba8Unorm)
    }
}

/// A player of `baked` in `mode` along `draw_path` ([`config`]).
fn player(gpu: &Gpu, baked: &Baked, mode: Mode, draw_path: DrawPath) -> Player {
    Player::new(&gpu.device, &gpu.queue, baked, config(mode, draw_path)).unwrap()
}

fn headless(mode: Mode, samples: u32) -> HeadlessConfig {
    HeadlessConfig {
        samples,
        mode,
        shading: trisort_gpu::Shading::Basic,
        ..HeadlessConfig::recorded(&quads())
    }
}

fn read_commands(
    gpu: &Gpu,
    player: &Player,
    offset: u64,
    count: u32,
) -> Vec<DrawIndexedIndirectArgs> {
    let size = count as u64 * std::mem::size_of::<DrawIndexedIndirectArgs>() as u64;
    bytemuck::cast_slice(&gpu.read_buffer(player.indirect_buffer(), offset, size)).to_vec()
}

/// The triangles (vertex triples) that `draws` cover in `player`'s index buffer.
fn drawn_triangles(gpu: &Gpu, player: &Player, draws: &[DrawIndexedIndirectArgs]) -> Vec<[u32; 3]> {
    let bytes = gpu.read_buffer(player.index_buffer(), 0, player.index_buffer().size());
    let index = |k: u32| match player.index_format() {
        wgpu::IndexFormat::Uint16 => {
            u16::from_le_bytes([bytes[2 * k as usize], bytes[2 * k as usize + 1]]) as u32
        }
        wgpu::IndexFormat::Uint32 => {
            u32::from_le_bytes(bytes[4 * k as usize..][..4].try_into().unwrap())
        }
    };
    draws
        .iter()
        .flat_map(|d| (d.first_index..d.first_index + d.index_count).step_by(3))
        .map(|k| [index(k), index(k + 1), index(k + 2)])
        .collect()
}

#[test]
fn each_frame_is_exactly_one_multi_draw_over_its_window() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    for mode in Mode::ALL {
        let player = player(&gpu, &baked, mode, DrawPath::MultiDrawIndirect);
        for frame in 0..3u32 {
            let mut log = CallLog::default();
            player.draw(&mut log, frame).unwrap();
            let draws = log.draws();
            assert_eq!(draws.len(), 1, "{mode} frame {frame}: {:?}", log.calls);
            let Call::MultiDrawIndexedIndirect {
                buffer,
                offset,
                count,
            } = draws[0]
            else {
                panic!("{mode} frame {frame}: not a multi-draw: {:?}", draws[0]);
            };
            assert_eq!(buffer, player.indirect_buffer());
            let window = baked.frames[frame as usize];
            assert_eq!(*count, window.count, "{mode} frame {frame}");
            // The commands on the GPU cover the frame's triangles, in the mode's order.
            let commands = read_commands(&gpu, &player, *offset, *count);
            let mut want: Vec<[u32; 3]> = drawn_copies(&baked, baked.frame_draws(frame as usize))
                .iter()
                .map(|&t| baked.geometry.triangles[t as usize])
                .collect();
            if mode == Mode::Blend {
                want.reverse();
            }
            assert_eq!(
                drawn_triangles(&gpu, &player, &commands),
                want,
                "{mode} frame {frame}"
            );
            // The draw is the last call; the frame's offsets are bound before it.
            assert!(matches!(
                log.calls.last(),
                Some(Call::MultiDrawIndexedIndirect { .. })
            ));
            assert!(log
                .calls
                .iter()
                .any(|c| matches!(c, Call::SetBindGroup { index: 0, .. })));
        }
        assert!(matches!(
            player.draw(&mut CallLog::default(), 3),
            Err(PlayerError::FrameOutOfRange {
                frame: 3,
                frames: 3
            })
        ));
    }
}

#[test]
fn fallback_draws_the_same_ranges_one_by_one_and_the_same_image() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    for mode in Mode::ALL {
        let multi = player(&gpu, &baked, mode, DrawPath::MultiDrawIndirect);
        let direct = player(&gpu, &baked, mode, DrawPath::Direct);
        for frame in 0..3u32 {
            let mut m = CallLog::default();
            multi.draw(&mut m, frame).unwrap();
            let Call::MultiDrawIndexedIndirect { offset, count, .. } = m.draws()[0] else {
                panic!()
            };
            let on_gpu = read_commands(&gpu, &multi, *offset, *count);
            let mut d = CallLog::default();
            direct.draw(&mut d, frame).unwrap();
            let ranges: Vec<_> = d
                .draws()
                .into_iter()
                .map(|c| match c {
                    Call::DrawIndexed {
                        indices,
                        base_vertex: 0,
                        instances,
                    } if *instances == (0..1) => indices.clone(),
                    other => panic!("{mode} frame {frame}: unexpected {other:?}"),
                })
                .collect();
            let want: Vec<_> = on_gpu
                .iter()
                .map(|a| a.first_index..a.first_index + a.index_count)
                .collect();
            assert_eq!(ranges, want, "{mode} frame {frame}");
        }
        let a = HeadlessRenderer::new(
            &gpu,
            &baked,
            &HeadlessConfig {
                draw_path: Some(DrawPath::MultiDrawIndirect),
                ..headless(mode, 4)
            },
        )
        .unwrap();
        let b = HeadlessRenderer::new(
            &gpu,
            &baked,
            &HeadlessConfig {
                draw_path: Some(DrawPath::Direct),
                ..headless(mode, 4)
            },
        )
        .unwrap();
        for frame in 0..3 {
            assert_eq!(
                a.render(frame).unwrap().rgba8,
                b.render(frame).unwrap().rgba8,
                "{mode} frame {frame}"
            );
        }
    }
}

#[test]
fn blend_composites_back_to_front() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    let bg = BACKGROUND.map(|c| c as f64);
    let (red, green, blue) = (lit(RED), lit(GREEN), lit(BLUE));
    for samples in [1, 4] {
        let r = HeadlessRenderer::new(&gpu, &baked, &headless(Mode::Blend, samples)).unwrap();
        let f0 = r.render(0).unwrap().rgba8;
        assert_pixel(
            &f0,
            (16, 16),
            over(red, over(green, bg)),
            1,
            "red over green",
        );
        assert_pixel(&f0, (6, 25), over(red, bg), 1, "red alone");
        assert_pixel(&f0, (25, 6), over(green, bg), 1, "green alone");
        assert_pixel(&f0, (30, 30), bg, 0, "background");
        let f1 = r.render(1).unwrap().rgba8;
        let b = over(blue, bg);
        assert_pixel(
            &f1,
            (16, 16),
            over(red, over(green, b)),
            1,
            "red over green over blue",
        );
        assert_pixel(&f1, (30, 30), b, 1, "blue");
        // Frame 2 draws the same quads as frame 0 from other ranges.
        assert_eq!(r.render(2).unwrap().rgba8, f0, "{samples}x");
        // Played the wrong way round (green over red) the overlap differs: the test can fail.
        let wrong = srgb8(over(green, over(red, bg)));
        assert!(pixel(&f0, 16, 16)
            .iter()
            .zip(wrong)
            .any(|(a, b)| a.abs_diff(b) > 8));
    }
}

#[test]
fn depth_mode_keeps_the_front_quad() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    let bg = BACKGROUND.map(|c| c as f64);
    let (red, green, blue) = (lit(RED), lit(GREEN), lit(BLUE));
    for samples in [1, 4] {
        let r = HeadlessRenderer::new(&gpu, &baked, &headless(Mode::Depth, samples)).unwrap();
        let f0 = r.render(0).unwrap().rgba8;
        // Front to back with depth writes: red is drawn first and hides green where they overlap.
        assert_pixel(&f0, (16, 16), over(red, bg), 1, "front quad only");
        assert_pixel(&f0, (25, 6), over(green, bg), 1, "green alone");
        let f1 = r.render(1).unwrap().rgba8;
        assert_pixel(&f1, (16, 16), over(red, bg), 1, "front quad hides the rest");
        assert_pixel(&f1, (30, 30), over(blue, bg), 1, "blue");
    }
}

#[test]
fn saturate_matches_blend_within_one_step() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    for samples in [1, 4] {
        let blend = HeadlessRenderer::new(&gpu, &baked, &headless(Mode::Blend, samples)).unwrap();
        let saturate =
            HeadlessRenderer::new(&gpu, &baked, &headless(Mode::Saturate, samples)).unwrap();
        for frame in 0..3 {
            let a = blend.render(frame).unwrap().rgba8;
            let b = saturate.render(frame).unwrap().rgba8;
            let d = max_diff(&a, &b);
            assert!(
                d <= 1,
                "{samples}x frame {frame}: saturate differs from blend by {d}/255"
            );
        }
    }
}

#[test]
fn u16_and_u32_indices_give_the_same_frames() {
    let Some(gpu) = gpu() else { return };
    let small = quads();
    let big = quads_u32();
    for mode in Mode::ALL {
        let a = HeadlessRenderer::new(&gpu, &small, &headless(mode, 1)).unwrap();
        let b = HeadlessRenderer::new(&gpu, &big, &headless(mode, 1)).unwrap();
        let c = HeadlessRenderer::new(
            &gpu,
            &small,
            &HeadlessConfig {
                force_u32: true,
                ..headless(mode, 1)
            },
        )
        .unwrap();
        assert_eq!(a.player().index_format(), wgpu::IndexFormat::Uint16);
        assert_eq!(b.player().index_format(), wgpu::IndexFormat::Uint32);
        assert_eq!(c.player().index_format(), wgpu::IndexFormat::Uint32);
        assert_eq!(a.player().index_buffer().size(), 24 * 2);
        for frame in 0..3 {
            let want = a.render(frame).unwrap().rgba8;
            assert_eq!(b.render(frame).unwrap().rgba8, want, "{mode} frame {frame}");
            assert_eq!(c.render(frame).unwrap().rgba8, want, "{mode} frame {frame}");
        }
    }
}

#[test]
fn warnings_at_another_size_sample_count_or_device() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    let exact = player(&gpu, &baked, Mode::Blend, DrawPath::MultiDrawIndirect);
    assert!(exact.warnings().is_empty(), "{:?}", exact.warnings());
    let resized = PlayerConfig {
        size: (64, 32),
        ..config(Mode::Blend, DrawPath::MultiDrawIndirect)
    };
    let p = Player::new(&gpu.device, &gpu.queue, &baked, resized).unwrap();
    assert_eq!(p.warnings().len(), 1, "{:?}", p.warnings());
    assert!(
        p.warnings()[0].contains("64x32") && p.warnings()[0].contains("32x32"),
        "{:?}",
        p.warnings()
    );
    let r = HeadlessRenderer::new(&gpu, &baked, &headless(Mode::Blend, 4)).unwrap();
    let w = r.player().warnings();
    assert!(w.iter().any(|w| w.contains("4 sample")), "{w:?}");
    assert!(
        w.iter().any(|w| w.contains("recorded on hand-made")),
        "{w:?}"
    );
}

#[test]
fn depth_mode_without_depth_format_and_inconsistent_files_are_errors() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    let no_depth = PlayerConfig {
        depth_format: None,
        ..config(Mode::Depth, DrawPath::MultiDrawIndirect)
    };
    assert!(matches!(
        Player::new(&gpu.device, &gpu.queue, &baked, no_depth),
        Err(PlayerError::DepthFormatMissing)
    ));
    let mut bad = quads();
    bad.draws[1].first_index = 21; // 21 + 6 > 24 indices
    let err = Player::new(
        &gpu.device,
        &gpu.queue,
        &bad,
        config(Mode::Blend, DrawPath::MultiDrawIndirect),
    )
    .err()
    .expect("a draw outside the index buffer is refused");
    assert!(err.to_string().contains("draw 1"), "{err}");
}

#[test]
fn indirect_validation_can_be_switched_off() {
    let Some(on) = gpu() else { return };
    let off = Gpu::with_flags(trisort_player::instance_flags(false)).expect("a second device");
    let baked = quads();
    let a = HeadlessRenderer::new(&on, &baked, &headless(Mode::Blend, 1)).unwrap();
    let b = HeadlessRenderer::new(&off, &baked, &headless(Mode::Blend, 1)).unwrap();
    for frame in 0..3 {
        assert_eq!(
            a.render(frame).unwrap().rgba8,
            b.render(frame).unwrap().rgba8
        );
    }
    assert!(trisort_player::instance_flags(true)
        .contains(wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL));
    assert!(!trisort_player::instance_flags(false)
        .contains(wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL));
}

#[test]
fn render_frames_reports_each_frame_with_gpu_time_where_available() {
    let Some(gpu) = gpu() else { return };
    let baked = quads();
    let frames =
        trisort_player::render_frames(&gpu, &baked, &[2, 0], (SIZE, SIZE), 1, Mode::Blend, None)
            .unwrap();
    assert_eq!(
        frames.iter().map(|f| f.frame).collect::<Vec<_>>(),
        vec![2, 0]
    );
    for f in &frames {
        assert_eq!(f.rgba8.len(), (SIZE * SIZE * 4) as usize);
        let timed = gpu
            .device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY);
        assert_eq!(f.gpu_ms.is_some(), timed, "gpu_ms {:?}", f.gpu_ms);
        eprintln!("frame {}: gpu_ms {:?}", f.frame, f.gpu_ms);
        if let Some(ms) = f.gpu_ms {
            assert!(ms.is_finite() && ms >= 0.0);
        }
    }
    assert!(
        trisort_player::render_frames(&gpu, &baked, &[7], (SIZE, SIZE), 1, Mode::Blend, None)
            .is_err()
    );
}

/// Pipeline statistics: a frame runs the clipper on exactly its window's triangles and the
/// vertex shader on at most three vertices each.
#[test]
fn pipeline_statistics_count_exactly_the_windows_triangles() {
    let Some(gpu) = gpu() else { return };
    if !gpu
        .device
        .features()
        .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
    {
        eprintln!(
            "skipping: no PIPELINE_STATISTICS_QUERY on {}",
            gpu.describe()
        );
        return;
    }
    let baked = quads();
    let device = &gpu.device;
    let player = player(&gpu, &baked, Mode::Blend, DrawPath::MultiDrawIndirect);
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width: SIZE,
            height: SIZE,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let view = target.create_view(&Default::default());
    let set = device.create_query_set(&wgpu::QuerySetDescriptor {
        label: None,
        ty: wgpu::QueryType::PipelineStatistics(
            wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS
                | wgpu::PipelineStatisticsTypes::CLIPPER_INVOCATIONS,
        ),
        count: 3,
    });
    let resolve = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 3 * 16,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    for frame in 0..3u32 {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        pass.begin_pipeline_statistics_query(&set, frame);
        player.draw(&mut pass, frame).unwrap();
        pass.end_pipeline_statistics_query();
    }
    enc.resolve_query_set(&set, 0..3, &resolve, 0);
    gpu.queue.submit([enc.finish()]);
    let stats: Vec<u64> = bytemuck::cast_slice(&gpu.read_buffer(&resolve, 0, 3 * 16)).to_vec();
    for frame in 0..3u32 {
        let (vs, clipped) = (stats[2 * frame as usize], stats[2 * frame as usize + 1]);
        let triangles = player.frame_triangles(frame);
        let want = drawn_copies(&baked, baked.frame_draws(frame as usize)).len() as u64;
        assert_eq!(triangles, want);
        eprintln!("frame {frame}: {triangles} triangles, clipper {clipped}, vertex shader {vs}");
        assert_eq!(clipped, triangles, "frame {frame}: clipper invocations");
        // Every distinct vertex of the window is shaded at least once, no vertex more than
        // once per triangle corner (lavapipe reuses vertices within a draw: 4 per quad).
        let mut vertices: Vec<u32> = drawn_copies(&baked, baked.frame_draws(frame as usize))
            .iter()
            .flat_map(|&t| baked.geometry.triangles[t as usize])
            .collect();
        vertices.sort_unstable();
        vertices.dedup();
        assert!(
            (vertices.len() as u64..=3 * triangles).contains(&vs),
            "frame {frame}: {vs} vertex invocations for {triangles} triangles over {} vertices",
            vertices.len()
        );
    }
}

#[test]
fn back_faces_mask_cut_outs_and_an_empty_frame() {
    let Some(gpu) = gpu() else { return };
    let baked = faces();
    baked.check_structure().unwrap();
    let bg = srgb8(BACKGROUND.map(|c| c as f64));
    for mode in Mode::ALL {
        let r = HeadlessRenderer::new(&gpu, &baked, &headless(mode, 1)).unwrap();
        // An empty window issues no draw (wgpu 30 with indirect validation would draw one
        // command for a multi-draw of count 0) and the frame shows only the background.
        let mut log = CallLog::default();
        r.player().draw(&mut log, 0).unwrap();
        assert!(log.draws().is_empty(), "{mode}: {:?}", log.draws());
        let f0 = r.render(0).unwrap().rgba8;
        assert!(
            f0.chunks(4).all(|p| p[..3] == bg),
            "{mode}: frame 0 is background only"
        );
        let f1 = r.render(1).unwrap().rgba8;
        assert_close(
            pixel(&f1, 5, 7),
            bg,
            0,
            &format!("{mode}: single-sided back face culled"),
        );
        assert_close(
            pixel(&f1, 15, 7),
            srgb8(lit([0.0, 1.0, 0.0, 1.0])[..3].try_into().unwrap()),
            1,
            &format!("{mode}: double-sided back face lit with its normal flipped"),
        );
        assert_close(
            pixel(&f1, 6, 23),
            srgb8(lit(YELLOW)[..3].try_into().unwrap()),
            1,
            &format!("{mode}: mask kept (opaque)"),
        );
        assert_close(pixel(&f1, 25, 23), bg, 0, &format!("{mode}: mask cut"));
    }
}

#[test]
fn glass_plays_at_the_recorded_or_the_chosen_opacity() {
    let Some(gpu) = gpu() else { return };
    // The red quad becomes glass, recorded see-through (opacity 0).
    let mut baked = quads();
    baked.geometry.materials[0].transmission = 1.0;
    baked.settings.glass_opacity = 0.0;
    let bg = BACKGROUND.map(|c| c as f64);
    let red = lit(RED);
    for (opacity, want) in [
        (None, srgb8(bg)),
        (Some(0.5), srgb8(over([red[0], red[1], red[2], 0.5], bg))),
        (Some(1.0), srgb8([red[0], red[1], red[2]])),
    ] {
        let config = HeadlessConfig {
            glass_opacity: opacity,
            ..headless(Mode::Blend, 1)
        };
        let r = HeadlessRenderer::new(&gpu, &baked, &config).unwrap();
        assert_close(
            pixel(&r.render(0).unwrap().rgba8, 6, 25),
            want,
            1,
            &format!("glass at {opacity:?}"),
        );
        // More opaque than recorded is exact: no glass warning.
        assert!(r.player().warnings().iter().all(|w| !w.contains("glass")));
    }
}
