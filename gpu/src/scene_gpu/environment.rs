//! The prefiltered environment radiance on the GPU.

use trisort_format::Environment;

use super::textures::chain_levels;

/// The prefiltered environment on the GPU.
pub(super) struct EnvironmentGpu {
    pub(super) view: wgpu::TextureView,
    /// Mip levels uploaded.
    pub(super) levels: u32,
    pub(super) bytes: u64,
}

/// Uploads an environment's prefiltered radiance as an `Rgba16Float` texture with one mip
/// level per stored level (as many as a full chain of its size holds; levels larger than the
/// device allows are left out from the top).
pub(super) fn upload_environment(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    env: &Environment,
) -> EnvironmentGpu {
    let max_dim = device.limits().max_texture_dimension_2d;
    let first = (0..env.levels.len())
        .find(|&k| {
            let (w, h) = env.level_size(k);
            w <= max_dim && h <= max_dim
        })
        .unwrap_or(env.levels.len());
    let white = [0x3c00u16; 4];
    let mut stored: Vec<(u32, u32, &[u16])> = (first..env.levels.len())
        .map(|k| {
            let (w, h) = env.level_size(k);
            (w, h, env.levels[k].as_slice())
        })
        .filter(|(w, h, l)| l.len() as u64 == *w as u64 * *h as u64 * 4)
        .collect();
    if stored.is_empty() {
        stored.push((1, 1, &white));
    }
    let (w0, h0) = (stored[0].0, stored[0].1);
    let levels = (stored.len() as u32).min(chain_levels(w0, h0));
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("environment"),
        size: wgpu::Extent3d {
            width: w0,
            height: h0,
            depth_or_array_layers: 1,
        },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba16Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let mut bytes = 0;
    for (k, &(sw, sh, texels)) in stored.iter().take(levels as usize).enumerate() {
        // A level's size is that of the chain (`max(1, w0 >> k)`): the file's sizes agree.
        let (w, h) = (sw.min((w0 >> k).max(1)), sh.min((h0 >> k).max(1)));
        let row = w as usize * 4;
        let mut data: Vec<u16> = Vec::with_capacity(row * h as usize);
        for y in 0..h as usize {
            data.extend_from_slice(&texels[y * sw as usize * 4..][..row]);
        }
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: k as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&data),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * 8),
                rows_per_image: Some(h),
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        bytes += w as u64 * h as u64 * 8;
    }
    EnvironmentGpu {
        view: texture.create_view(&Default::default()),
        levels,
        bytes,
    }
}
