//! A host application that owns its wgpu device, its render target and its render pass, and
//! lets the trisort player draw one baked frame into that pass.
//!
//! ```text
//! cargo run -p trisort-player --example embed -- scene.baked [frame]
//! ```
//!
//! Headless (there may be no display): it renders into its own texture, reads it back and
//! prints how many pixels the player covered and a checksum of the image.

use std::path::PathBuf;

fn main() {
    if let Err(e) = run() {
        eprintln!("embed: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = PathBuf::from(args.next().ok_or("usage: embed FILE.baked [FRAME]")?);
    let frame: u32 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(0);

    // The host's own device. Its instance flags decide whether wgpu validates indirect calls;
    // `trisort_player::instance_flags(false)` turns that GPU-side check off.
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        flags: trisort_player::instance_flags(true),
        ..wgpu::InstanceDescriptor::new_without_display_handle_from_env()
    });
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&Default::default()))?;
    println!("adapter: {}", adapter.get_info().name);

    // The file, checked, and a player for the host's target: an sRGB colour target with a
    // depth buffer, single-sampled, at the recorded size.
    let baked = trisort_player::open_baked(&path)?;
    let color_format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let depth_format = wgpu::TextureFormat::Depth32Float;
    let config = trisort_player::PlayerConfig {
        depth_format: Some(depth_format),
        sample_count: 1,
        ..trisort_player::PlayerConfig::for_adapter(&baked, &adapter, color_format)
    };
    let (width, height) = config.size;
    let player = trisort_player::Player::new(&device, &queue, &baked, config)?;
    for w in player.warnings() {
        eprintln!("warning: {w}");
    }

    // The host's target and pass.
    let size = wgpu::Extent3d {
        width,
        height,
        depth_or_array_layers: 1,
    };
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host target"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: color_format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let depth = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host depth"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: depth_format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let target_view = target.create_view(&Default::default());
    let depth_view = depth.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("host pass"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        // The host may draw its own things here; the player sets its own pipeline and
        // bindings and issues one multi-draw-indirect for the frame.
        player.draw(&mut pass, frame)?;
    }

    // Read back (rows padded to 256 bytes) and summarize.
    let row = (width * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
        * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("host readback"),
        size: row as u64 * height as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        target.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(height),
            },
        },
        size,
    );
    queue.submit([encoder.finish()]);
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.expect("map"));
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let data = staging.slice(..).get_mapped_range()?.to_vec();
    let (covered, checksum) = coverage_and_checksum(&data, row, width, height);
    println!(
        "frame {frame} of {}: {} triangles in {} draw(s); {covered} of {} pixels covered; checksum {checksum:016x}",
        player.frame_count(),
        player.frame_triangles(frame),
        player.frame_commands(frame).len(),
        width as u64 * height as u64,
    );
    Ok(())
}

/// How many pixels of a read-back RGBA8 image (`height` rows of `width` pixels, each row
/// `row` bytes apart) are not black, and an FNV-1a checksum over its pixels.
fn coverage_and_checksum(data: &[u8], row: u32, width: u32, height: u32) -> (u64, u64) {
    let mut covered = 0u64;
    let mut checksum = 0xcbf2_9ce4_8422_2325u64; // FNV-1a over the pixels
    for y in 0..height as usize {
        for px in data[y * row as usize..][..width as usize * 4].chunks_exact(4) {
            if px[..3] != [0, 0, 0] {
                covered += 1;
            }
            for &b in px {
                checksum = (checksum ^ b as u64).wrapping_mul(0x100_0000_01b3);
            }
        }
    }
    (covered, checksum)
}
