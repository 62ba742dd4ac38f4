//! The material texture arrays (sRGB and linear, with mips): where each texture lies in them
//! and how it is uploaded.

use trisort_format::Geometry;

use trisort_format::gpu_layout::TextureArray;
pub(crate) use trisort_format::gpu_layout::TexturePlace;

use super::budget::{texture_allocation_bytes, ArrayUpload, GpuBytes, SceneBudget};

/// The two material texture arrays.
pub(super) struct Textures {
    pub(super) srgb: wgpu::TextureView,
    pub(super) linear: wgpu::TextureView,
    /// Per texture of the geometry.
    pub(super) places: Vec<TexturePlace>,
    /// Bytes both arrays take with every level.
    pub(super) bytes: u64,
}

/// Uploads the material textures into two arrays, sRGB and linear, each in the format of
/// [`SceneBudget::uploads`] (`Rgba8UnormSrgb` and `Rgba8Unorm`, or the members' blocks), as
/// the budget's plan ([`plan_texture_arrays`](trisort_format::gpu_layout::plan_texture_arrays), in [`SceneBudget::arrays`])
/// lays them out (each texture in the array of its colour space, layers as large as the
/// array's largest texture clamped to the device's limit, full mip chains, smaller textures
/// repeated from the top-left corner), with [`SceneBudget::layers`] layers each. An empty
/// array gets one white texel. With `visibility_only` ([`SceneGpu::for_visibility`](super::SceneGpu::for_visibility))
/// the linear array is left empty (its textures placed at its layer 0, the white texel) unless
/// a material's base-colour texture is linear. Counts both arrays into `allocated`.
pub(super) fn upload_textures(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    geometry: &Geometry,
    budget: &SceneBudget,
    allocated: &mut GpuBytes,
) -> Textures {
    let plan = &budget.arrays;
    let [srgb, linear] = [&plan.srgb, &plan.linear].map(|array| {
        let k = array.linear as usize;
        let uploaded = upload_array(
            device,
            queue,
            geometry,
            array,
            &budget.uploads[k],
            budget.layers[k],
        );
        allocated.count_texture_layers(&uploaded.0, &budget.layer_kinds[k]);
        uploaded
    });
    Textures {
        srgb: srgb.1,
        linear: linear.1,
        places: plan.places.clone(),
        bytes: srgb.2 + linear.2,
    }
}

/// One array of [`upload_textures`], as [`plan_texture_arrays`](trisort_format::gpu_layout::plan_texture_arrays) planned it, with `layers`
/// layers, in the format `upload` says; returns the texture, its view and its bytes.
///
/// In a block format every level is written at its physical size, whole blocks (a level of
/// 2×2 texels as its one 4×4 block), rows of blocks as
/// [`TextureArray::level_blocks`] gives them.
fn upload_array(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    geometry: &Geometry,
    array: &TextureArray,
    upload: &ArrayUpload,
    layers: u32,
) -> (wgpu::Texture, wgpu::TextureView, u64) {
    let (tw, th, levels, linear) = (array.width, array.height, array.levels, array.linear);
    // wgpu's GL backend picks the GL texture target when the texture is made, from its
    // layer count alone: one layer becomes TEXTURE_2D, which a `texture_2d_array` binding
    // (sampler2DArray) then samples as an incomplete texture, black. The budget gives two
    // layers at least on GL (`BudgetConfig::min_array_layers`), which makes it
    // TEXTURE_2D_ARRAY; the spare layer is never addressed.
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(if linear {
            "linear textures"
        } else {
            "sRGB textures"
        }),
        size: wgpu::Extent3d {
            width: tw,
            height: th,
            depth_or_array_layers: layers,
        },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: upload.texture_format(linear),
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    // A level of `w` × `h` blocks of `block_bytes` (1×1 texel blocks of 4 bytes for RGBA8).
    let (block, block_bytes) = match upload {
        ArrayUpload::Blocks(f) => (4, f.block_bytes() as u32),
        ArrayUpload::Rgba8 { .. } => (1, 4),
    };
    let write = |level: u32, layer: u32, w: u32, h: u32, data: &[u8]| {
        let (bw, bh) = (w.div_ceil(block), h.div_ceil(block));
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: level,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: layer,
                },
                aspect: wgpu::TextureAspect::All,
            },
            data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(bw * block_bytes),
                rows_per_image: Some(bh),
            },
            wgpu::Extent3d {
                width: bw * block,
                height: bh * block,
                depth_or_array_layers: 1,
            },
        );
    };
    for layer in 0..array.members.len() as u32 {
        for k in 0..levels {
            let (aw, ah) = array.level_size(k);
            let data = match upload {
                ArrayUpload::Blocks(f) => array.level_blocks(geometry, *f, layer, k),
                ArrayUpload::Rgba8 { .. } => array.level_bytes(geometry, layer, k),
            };
            write(k, layer, aw, ah, &data.expect("a planned layer and level"));
        }
    }
    if array.members.is_empty() {
        write(0, 0, 1, 1, &[255u8; 4]);
    }
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let bytes = texture_allocation_bytes(&texture);
    (texture, view, bytes)
}
