//! The prefiltered environment radiance on the GPU.

use trisort_format::gpu_layout::environment_levels;
use trisort_format::Environment;

use super::budget::{GpuBytes, GpuKind, SceneBudget};

/// The prefiltered environment on the GPU.
pub(super) struct EnvironmentGpu {
    pub(super) view: wgpu::TextureView,
    /// Mip levels uploaded.
    pub(super) levels: u32,
    pub(super) bytes: u64,
}

/// Uploads an environment's prefiltered radiance as an `Rgba16Float` texture, its levels as
/// [`environment_levels`] gives them for the budget's largest texture (the device's); counts
/// it into `allocated`.
pub(super) fn upload_environment(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    env: &Environment,
    budget: &SceneBudget,
    allocated: &mut GpuBytes,
) -> EnvironmentGpu {
    let stored = environment_levels(env, budget.config.max_texture_dimension);
    let levels = stored.len() as u32;
    let (w0, h0) = (stored[0].width, stored[0].height);
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
    for (k, level) in stored.iter().enumerate() {
        let (w, h) = (level.width, level.height);
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: k as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&level.texels),
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
    allocated.count_texture(GpuKind::Environment, &texture);
    EnvironmentGpu {
        view: texture.create_view(&Default::default()),
        levels,
        bytes,
    }
}
