//! Block-compressed textures (issue 34) on the test GPU: the player samples a file's BC7
//! blocks natively where the device has `TEXTURE_COMPRESSION_BC` (lavapipe does) and draws
//! the pixels of the same file uploaded decoded (`decode_textures`) in a quarter of the
//! memory: linear and alpha texels exactly, sRGB colour within 1/255 (lavapipe's sRGB
//! conversion of BC7 texels differs from its RGBA8 one in the last bit). ETC2, which lavapipe
//! lacks, is uploaded decoded there and draws as RGBA8 texels do; Mesa's GL (llvmpipe) samples
//! it natively, exactly as decoded.
use trisort_format::{Baked, BlockFormat};
use trisort_gpu::scene_gpu::ArrayUpload;
use trisort_gpu::Gpu;
use trisort_player::headless::{HeadlessConfig, HeadlessRenderer};
use trisort_player::Mode;
use trisort_testkit::blocks::{texture_of_blocks, Bits};
use trisort_testkit::gpu;

use crate::shading::{slot, textured};

/// [`textured`] with every map of the grey quad and the base colour of the red one (now
/// visible, its texture's alpha blended over the rest) stored as random `format` blocks of
/// several sizes, so that smaller textures repeat over larger layers, and levels past a
/// texture's chain are sampled: sRGB 128² base colour, 16² emissive, 8² red base colour;
/// linear 64² metallic-roughness, 4² occlusion.
fn blocky(format: BlockFormat, seed: u64) -> Baked {
    let mut bits = Bits(seed);
    let mut b = textured();
    let g = &mut b.geometry;
    g.textures = [(128, true), (16, true), (8, true), (64, false), (4, false)]
        .into_iter()
        .map(|(size, srgb)| texture_of_blocks(&mut bits, format, (size, size), srgb))
        .collect();
    let grey = &mut g.materials[2];
    grey.base_color_texture = Some(0);
    grey.emissive = [1.0, 1.0, 1.0];
    grey.emissive_texture = slot(1);
    grey.metallic_roughness_texture = slot(3);
    grey.occlusion_texture = slot(4);
    let red = &mut g.materials[0];
    red.base_color = [1.0, 1.0, 1.0, 1.0];
    red.base_color_texture = Some(2);
    for v in &mut g.vertices {
        v.uv = [
            (v.position[0] / 1.1 + 1.0) / 2.0,
            (1.0 - v.position[1] / 1.1) / 2.0,
        ];
        v.uv1 = v.uv;
    }
    b.geometry.check_structure().unwrap();
    b
}

/// The player of `baked` at 4× in blend mode, at twice the recorded size (more texels of
/// each level), with textures decoded or not.
fn player<'g>(gpu: &'g Gpu, baked: &Baked, decode_textures: bool) -> HeadlessRenderer<'g> {
    let config = HeadlessConfig {
        samples: 4,
        mode: Mode::Blend,
        size: (64, 64),
        decode_textures,
        ..HeadlessConfig::recorded(baked)
    };
    HeadlessRenderer::new(gpu, baked, &config).expect("renderer")
}

/// Frames 0 and 1 of `p`.
fn frames(p: &HeadlessRenderer<'_>) -> Vec<Vec<u8>> {
    (0..2).map(|f| p.render(f).expect("frame").rgba8).collect()
}

/// Pixels that differ between `a` and `b`, and the largest channel difference.
fn differing(a: &[u8], b: &[u8]) -> (usize, u8) {
    let n = a.chunks(4).zip(b.chunks(4)).filter(|(x, y)| x != y).count();
    (n, crate::shading::max_diff(a, b))
}

#[test]
fn native_bc7_draws_the_pixels_of_its_decoded_texels() {
    let Some(gpu) = gpu() else { return };
    let started = std::time::Instant::now();
    let bc = gpu
        .device
        .features()
        .contains(wgpu::Features::TEXTURE_COMPRESSION_BC);
    let as_decoded = ArrayUpload::Rgba8 {
        decoded_from: vec!["bc7"],
    };
    let want = if bc {
        ArrayUpload::Blocks(BlockFormat::Bc7)
    } else {
        as_decoded.clone()
    };
    let blocks = blocky(BlockFormat::Bc7, 0x2545_f491_4f6c_dd1d);
    // Every texture linear: the device's BC7 decoder against texture2ddecoder's, every mode,
    // tiled layers and mip levels.
    let mut linear = blocks.clone();
    for t in &mut linear.geometry.textures {
        t.srgb = false;
    }
    // As made: sRGB colour; and the red quad black, so its pixels show only its alpha.
    let srgb = blocks;
    let mut alpha = srgb.clone();
    alpha.geometry.materials[0].base_color = [0.0, 0.0, 0.0, 1.0];
    for (what, baked) in [("linear", &linear), ("sRGB", &srgb), ("alpha", &alpha)] {
        let native = player(&gpu, baked, false);
        let decoded = player(&gpu, baked, true);
        let (n, d) = (native.player(), decoded.player());
        // The linear case leaves the sRGB array empty: one white RGBA8 texel.
        let arrays_as = |upload: &ArrayUpload| match what {
            "linear" => [
                ArrayUpload::Rgba8 {
                    decoded_from: vec![],
                },
                upload.clone(),
            ],
            _ => [upload.clone(), upload.clone()],
        };
        assert_eq!(n.texture_uploads(), &arrays_as(&want));
        assert_eq!(d.texture_uploads(), &arrays_as(&as_decoded));
        // What each allocated is what its budget said; BC7 takes a quarter of RGBA8 (a
        // little more: levels under 4×4 texels take a whole block).
        for p in [n, d] {
            assert_eq!(p.gpu_bytes_allocated(), &p.gpu_budget().bytes);
        }
        let arrays = |p: &trisort_player::Player| {
            let bytes = p.gpu_bytes_allocated();
            bytes.textures() - bytes.texture(trisort_gpu::scene_gpu::GpuKind::Environment)
        };
        if bc {
            assert!(arrays(n) * 4 >= arrays(d) && arrays(n) * 3 < arrays(d));
            assert!(n.texture_bytes() < d.texture_bytes());
        }
        let (a, b) = (frames(&native), frames(&decoded));
        for (f, (a, b)) in a.iter().zip(&b).enumerate() {
            let (pixels, max) = differing(a, b);
            eprintln!(
                "{what} frame {f}: {pixels} pixels differ (max {max}/255); texture arrays {} bytes as {}, {} decoded",
                arrays(n),
                n.texture_uploads()[1].name(),
                arrays(d)
            );
            // lavapipe converts BC7 sRGB texels to linear a step of 8 bits apart from
            // RGBA8 sRGB ones now and then: the texels agree (linear, alpha), the
            // conversion differs in its last bit.
            let tolerance = if what == "sRGB" { 1 } else { 0 };
            let frame_alpha_only = what != "alpha" || f == 0;
            if frame_alpha_only {
                assert!(
                    max <= tolerance,
                    "{what} frame {f}: {pixels} pixels differ between native and decoded BC7 (max {max}/255)"
                );
            }
        }
    }
    // The textures show: the frame is not the plain grey of the untextured quad.
    let textured_frame = frames(&player(&gpu, &srgb, false));
    let plain = frames(&player(&gpu, &textured(), false));
    assert_ne!(textured_frame[1], plain[1]);
    eprintln!("native and decoded BC7 frames in {:?}", started.elapsed());
}

#[test]
fn etc2_without_the_feature_is_uploaded_decoded() {
    let Some(gpu) = gpu() else { return };
    let baked = blocky(BlockFormat::Etc2Rgb8, 0x9e37_79b9_7f4a_7c15);
    // The same texels stored as RGBA8 only.
    let mut plain = baked.clone();
    for t in &mut plain.geometry.textures {
        t.blocks = None;
    }
    let native = player(&gpu, &baked, false);
    let etc2 = gpu
        .device
        .features()
        .contains(wgpu::Features::TEXTURE_COMPRESSION_ETC2);
    let want = if etc2 {
        ArrayUpload::Blocks(BlockFormat::Etc2Rgb8)
    } else {
        ArrayUpload::Rgba8 {
            decoded_from: vec!["etc2"],
        }
    };
    assert_eq!(native.player().texture_uploads(), &[want.clone(), want]);
    if !etc2 {
        assert_eq!(
            native.player().texture_uploads()[1].name(),
            "rgba8 (decoded from etc2)"
        );
    }
    let rgba8 = player(&gpu, &plain, false);
    assert_eq!(
        rgba8.player().texture_uploads()[0],
        ArrayUpload::Rgba8 {
            decoded_from: vec![]
        }
    );
    assert!(
        frames(&native) == frames(&rgba8),
        "ETC2 blocks drew other pixels than their texels"
    );
    let native = native.player().gpu_bytes_allocated().textures();
    let rgba8 = rgba8.player().gpu_bytes_allocated().textures();
    assert!(if etc2 {
        native < rgba8
    } else {
        native == rgba8
    });
}

/// A device on Mesa's GL (llvmpipe through EGL, which samples ETC2), or `None` where none
/// opens (a skip on a developer machine, a failure under `TRISORT_REQUIRE_GPU=1`, as CI's
/// other GL tests).
fn gl_gpu() -> Option<Gpu> {
    let options = trisort_gpu::GpuOptions {
        backend: trisort_gpu::DeviceBackend::Gl,
        limits: trisort_gpu::DeviceLimits::Adapter,
    };
    let flags = wgpu::InstanceFlags::from_build_config().with_env();
    match Gpu::with_options(flags, options) {
        Ok(g) => Some(g),
        Err(e) if std::env::var(trisort_testkit::REQUIRE_GPU_ENV).as_deref() == Ok("1") => {
            panic!("no GL adapter and TRISORT_REQUIRE_GPU=1: {e}")
        }
        Err(e) => {
            eprintln!("skipping the GL test: {e}");
            None
        }
    }
}

#[test]
fn native_etc2_and_bc7_on_gl_draw_the_pixels_of_their_decoded_texels() {
    let Some(gpu) = gl_gpu() else { return };
    // ETC2 RGB8 textures with one ETC2 RGBA8 texture in each array (RGBA8 arrays, RGB8
    // blocks behind the opaque alpha block), exact; BC7, whose sRGB texels llvmpipe converts
    // to linear a step of 8 bits apart from RGBA8 ones now and then, as lavapipe does.
    let mut bits = Bits(0x0123_4567_89ab_cdef);
    let mut etc2 = blocky(BlockFormat::Etc2Rgb8, 0x5851_f42d_4c95_7f2d);
    etc2.geometry.textures[1] =
        texture_of_blocks(&mut bits, BlockFormat::Etc2Rgba8, (16, 16), true);
    etc2.geometry.textures[4] = texture_of_blocks(&mut bits, BlockFormat::Etc2Rgba8, (4, 4), false);
    let bc7 = blocky(BlockFormat::Bc7, 0x2545_f491_4f6c_dd1d);
    for (baked, format) in [(etc2, BlockFormat::Etc2Rgba8), (bc7, BlockFormat::Bc7)] {
        let feature = trisort_gpu::scene_gpu::budget::compression_feature(format);
        let native_format = gpu.device.features().contains(feature);
        eprintln!("{}: {format} {native_format}", gpu.describe());
        let native = player(&gpu, &baked, false);
        let decoded = player(&gpu, &baked, true);
        let want = if native_format {
            ArrayUpload::Blocks(format)
        } else {
            ArrayUpload::Rgba8 {
                decoded_from: vec![format.family()],
            }
        };
        assert_eq!(native.player().texture_uploads(), &[want.clone(), want]);
        let (a, b) = (frames(&native), frames(&decoded));
        for (f, (a, b)) in a.iter().zip(&b).enumerate() {
            let (pixels, max) = differing(a, b);
            eprintln!("GL {format} frame {f}: {pixels} pixels differ (max {max}/255)");
            let tolerance = if format == BlockFormat::Bc7 { 1 } else { 0 };
            assert!(
                max <= tolerance,
                "frame {f}: {pixels} pixels differ between native and decoded {format} (max {max}/255)"
            );
        }
    }
}
