//! The GLES 3.0 / WebGL2 path (the web player's fallback): WebGL2 limits pick the data-texture bindings and the
//! direct draws, and draw the same bytes as the storage tier with the multi-draw; on GL
//! (EGL, Mesa's llvmpipe) both tiers draw the same bytes too. The bake read back with the
//! pure-Rust decoder the wasm32 build uses is the bake written.

use trisort_format::{Baked, FileKind};
use trisort_gpu::{Bindings, DeviceBackend, DeviceLimits, Gpu, GpuOptions};
use trisort_player::{DrawPath, HeadlessConfig, HeadlessRenderer, Mode};

use crate::support::*;

/// A device with `options`, or `None` to skip (panics instead with `TRISORT_REQUIRE_GPU=1`).
fn open(options: GpuOptions) -> Option<Gpu> {
    std::env::set_var(
        "XDG_RUNTIME_DIR",
        std::env::var("XDG_RUNTIME_DIR").unwrap_or("/tmp".into()),
    );
    let flags = wgpu::InstanceFlags::from_build_config().with_env();
    match Gpu::with_options(flags, options) {
        Ok(g) => Some(g),
        Err(e) if std::env::var(trisort_testkit::REQUIRE_GPU_ENV).as_deref() == Ok("1") => {
            panic!("{options:?}: {e} and TRISORT_REQUIRE_GPU=1 (for GL: apt-get install libegl1 libegl-mesa0 libgles2 libgl1-mesa-dri)")
        }
        Err(e) => {
            eprintln!("skipping {options:?}: {e}");
            None
        }
    }
}

/// Every frame of `baked` in every mode at 1 and 4 samples, with the tier and draw path that
/// played them.
fn all_frames(gpu: &Gpu, baked: &Baked) -> (Bindings, DrawPath, Vec<Vec<u8>>) {
    let mut out = Vec::new();
    let mut path = None;
    for mode in [Mode::Blend, Mode::Depth, Mode::Saturate] {
        for samples in [1, 4] {
            let config = HeadlessConfig {
                samples,
                mode,
                ..HeadlessConfig::recorded(baked)
            };
            let r = HeadlessRenderer::new(gpu, baked, &config).unwrap();
            path = Some((r.player().bindings(), r.player().config().draw_path));
            for f in 0..r.player().frame_count() {
                out.push(r.render(f).unwrap().rgba8);
            }
        }
    }
    let (bindings, draw_path) = path.unwrap();
    (bindings, draw_path, out)
}

fn options(backend: DeviceBackend, limits: DeviceLimits) -> GpuOptions {
    GpuOptions { backend, limits }
}

#[test]
fn webgl2_limits_pick_data_textures_and_direct_draws_and_the_same_bytes() {
    let Some(full) = open(GpuOptions::default()) else {
        return;
    };
    let Some(web) = open(options(DeviceBackend::Auto, DeviceLimits::Webgl2)) else {
        return;
    };
    assert_eq!(web.device.limits().max_storage_buffers_per_shader_stage, 0);
    // The plain quads, and a material with every texture slot (both arrays, 20 texels of
    // material data on the texture tier).
    for (name, baked) in [
        ("quads", quads()),
        ("every map", crate::shading::every_map()),
    ] {
        let (b, d, full_frames) = all_frames(&full, &baked);
        assert_eq!(b, Bindings::Storage);
        if full
            .adapter
            .get_downlevel_capabilities()
            .flags
            .contains(wgpu::DownlevelFlags::INDIRECT_EXECUTION)
        {
            assert_eq!(d, DrawPath::MultiDrawIndirect);
        }
        let (b, d, web_frames) = all_frames(&web, &baked);
        assert_eq!((b, d), (Bindings::Textures, DrawPath::Direct));
        assert_eq!(full_frames.len(), web_frames.len());
        for (k, (a, b)) in full_frames.iter().zip(&web_frames).enumerate() {
            assert!(a == b, "{name}: image {k} differs between the tiers");
        }
    }
}

#[test]
fn gl_draws_the_same_bytes_on_both_tiers() {
    let Some(gl) = open(options(DeviceBackend::Gl, DeviceLimits::Adapter)) else {
        return;
    };
    let Some(web) = open(options(DeviceBackend::Gl, DeviceLimits::Webgl2)) else {
        return;
    };
    assert_eq!(web.info.backend, wgpu::Backend::Gl);
    for (name, baked) in [
        ("quads", quads()),
        ("every map", crate::shading::every_map()),
    ] {
        let (_, _, gl_frames) = all_frames(&gl, &baked);
        let (b, d, web_frames) = all_frames(&web, &baked);
        assert_eq!((b, d), (Bindings::Textures, DrawPath::Direct));
        for (k, (a, b)) in gl_frames.iter().zip(&web_frames).enumerate() {
            assert!(a == b, "{name}: image {k} differs between the GL tiers");
        }
    }
}

#[test]
fn the_pure_rust_decoder_reads_a_bake_as_written() {
    use trisort_format::container::{decode, decode_pure, encode};
    for baked in [quads(), quads_u32()] {
        let bytes = encode(FileKind::Baked, &baked);
        let path = std::path::Path::new("quads.baked");
        let pure: Baked = decode_pure(FileKind::Baked, &bytes, path).unwrap();
        let native: Baked = decode(FileKind::Baked, &bytes, path).unwrap();
        assert_eq!(encode(FileKind::Baked, &pure), bytes);
        assert_eq!(encode(FileKind::Baked, &native), bytes);
    }
}
