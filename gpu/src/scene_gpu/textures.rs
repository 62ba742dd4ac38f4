//! The material texture arrays (sRGB and linear, with mips): where each texture lies in them
//! and how it is uploaded.

use trisort_format::Geometry;

/// Where a texture lies on the GPU: its array (sRGB or linear), layer, and the uv scale of the
/// corner it fills at level 0.
///
/// One scale serves every level, which is exact at level 0 (and so for the alpha that decides
/// visibility, always sampled there) but only approximate at a coarser level `k` of a texture
/// `w` texels wide in a layer `tw` wide: the shader maps uv ∈ [0, 1) onto
/// `P = (w / tw)·(tw >> k)` texels of the layer's level, while the texture's own level repeats
/// there ([`tiled`]) every `max(1, w >> k)` texels. Both lie in `(w / 2^k − 1, w / 2^k]`, so
/// across one repeat the sampled point drifts from the texture's by less than one texel *of
/// level k* (growing linearly from uv 0), and steps back by as much where uv wraps
/// (likewise along v with the heights). Level k is chosen where a pixel spans about one of
/// its texels, so this misplaces already pixel-sized detail by under about a pixel, and never
/// reads anything but the texture (the repeat fills the whole layer). It is zero when `2^k` divides both `w` and
/// `tw`, and where the texture's level is one texel along an axis (constant along it): a
/// power-of-two texture in a power-of-two layer, and the array's largest texture (`w = tw`),
/// are exact at every level. Example: 300 texels in a 1024 layer are exact to level 2 and
/// drift by up to half a texel at level 3 (37.5 against a period of 37). Exact coarse levels
/// for the rest would need the shader to pick the level itself and scale per level (two
/// `textureSampleLevel` calls instead of one `textureSampleGrad`), or each level resampled
/// onto the stretched period at upload (a blur of its own); neither is worth it for this bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TexturePlace {
    pub(super) linear: bool,
    pub(super) layer: u32,
    pub(super) scale: [f32; 2],
}

/// The two material texture arrays.
pub(super) struct Textures {
    pub(super) srgb: wgpu::TextureView,
    pub(super) linear: wgpu::TextureView,
    /// Per texture of the geometry.
    pub(super) places: Vec<TexturePlace>,
    /// Bytes both arrays take with every level.
    pub(super) bytes: u64,
}

/// Number of mip levels of a full chain for a `w` × `h` level 0, level 0 included.
pub(super) fn chain_levels(w: u32, h: u32) -> u32 {
    trisort_format::Texture::mip_count(w, h) as u32 + 1
}

/// Level `k` of `t` as its size and RGBA8 bytes: level 0, a level of its stored chain
/// ([`trisort_format::Texture::mips`], full as [`Geometry::check_structure`] requires), or for
/// a level beyond the chain (the array's largest texture has more levels) its last, 1×1
/// level again, which is what averaging a 1×1 level would give.
fn texture_level(t: &trisort_format::Texture, k: usize) -> ((u32, u32), &[u8]) {
    let k = k.min(t.mips.len());
    let size = trisort_format::Texture::level_size(t.width, t.height, k as u32);
    let bytes = if k == 0 { &t.rgba8 } else { &t.mips[k - 1] };
    (size, bytes)
}

/// A `w` × `h` RGBA8 level of `size` repeated over a layer level of `layer` texels from the
/// top-left corner (cropped where the texture is larger: texels beyond the device limit, a
/// documented limitation). Filtering across the right and bottom edges of the texture's corner
/// (linear filtering at level 0, and every coarser level's footprint) then reads the texels
/// its repeat would, not the unused rest of the layer.
fn tiled(level: &[u8], (w, h): (u32, u32), (lw, lh): (u32, u32)) -> Vec<u8> {
    let mut data = Vec::with_capacity((lw * lh * 4) as usize);
    for y in 0..lh {
        let row = &level[((y % h) * w * 4) as usize..][..(w * 4) as usize];
        let mut x = 0;
        while x < lw {
            let n = (lw - x).min(w);
            data.extend_from_slice(&row[..(n * 4) as usize]);
            x += n;
        }
    }
    data
}

/// Uploads the material textures into two arrays, sRGB (`Rgba8UnormSrgb`) and linear
/// (`Rgba8Unorm`), each texture in the array of its [`trisort_format::Texture::srgb`] flag. A
/// layer is as large as its array's largest texture (clamped to the device's limit), with a
/// full mip chain; a smaller texture fills the top-left corner of every level with its own
/// level of the same index, repeated over the rest of the level ([`tiled`]). An empty array gets one white texel; on GL an array has two layers
/// at least (see the comment inside). With `visibility_only` ([`SceneGpu::for_visibility`](super::SceneGpu::for_visibility))
/// the linear array is left empty (its textures placed at its layer 0, the white texel) unless
/// a material's base-colour texture is linear.
pub(super) fn upload_textures(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    geometry: &Geometry,
    visibility_only: bool,
) -> Textures {
    let mut places = vec![
        TexturePlace {
            linear: false,
            layer: 0,
            scale: [1.0, 1.0]
        };
        geometry.textures.len()
    ];
    let mut bytes = 0;
    let mut views = Vec::new();
    // What `surface_base` samples: base-colour textures, in the array of their colour space.
    let linear_base = geometry.materials.iter().any(|m| {
        m.base_color_texture
            .and_then(|t| geometry.textures.get(t as usize))
            .is_some_and(|t| !t.srgb)
    });
    for linear in [false, true] {
        let mut members: Vec<usize> = (0..geometry.textures.len())
            .filter(|&i| geometry.textures[i].srgb != linear)
            .collect();
        if linear && visibility_only && !linear_base {
            for &i in &members {
                places[i] = TexturePlace {
                    linear: true,
                    layer: 0,
                    scale: [1.0, 1.0],
                };
            }
            members.clear();
        }
        let (view, b) = upload_array(device, queue, geometry, &members, linear, &mut places);
        views.push(view);
        bytes += b;
    }
    let linear = views.pop().expect("two arrays");
    let srgb = views.pop().expect("two arrays");
    Textures {
        srgb,
        linear,
        places,
        bytes,
    }
}

/// One array of [`upload_textures`]: the textures `members` of `geometry`; fills their places
/// and returns the view and its bytes.
fn upload_array(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    geometry: &Geometry,
    members: &[usize],
    linear: bool,
    places: &mut [TexturePlace],
) -> (wgpu::TextureView, u64) {
    let limits = device.limits();
    let (tw, th) = members.iter().fold((1u32, 1u32), |(w, h), &i| {
        let t = &geometry.textures[i];
        (w.max(t.width), h.max(t.height))
    });
    let max_dim = limits.max_texture_dimension_2d;
    let (tw, th) = (tw.min(max_dim), th.min(max_dim));
    let levels = chain_levels(tw, th);
    // wgpu's GL backend picks the GL texture target when the texture is made, from its
    // layer count alone: one layer becomes TEXTURE_2D, which a `texture_2d_array` binding
    // (sampler2DArray) then samples as an incomplete texture, black. Two layers at least on
    // GL make it TEXTURE_2D_ARRAY; the spare layer is never addressed.
    let min_layers = if device.adapter_info().backend == wgpu::Backend::Gl {
        2
    } else {
        1
    };
    let layers = members.len().max(min_layers) as u32;
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
        format: if linear {
            wgpu::TextureFormat::Rgba8Unorm
        } else {
            wgpu::TextureFormat::Rgba8UnormSrgb
        },
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let write = |level: u32, layer: u32, w: u32, h: u32, data: &[u8]| {
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
                bytes_per_row: Some(w * 4),
                rows_per_image: Some(h),
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
    };
    for (layer, &i) in members.iter().enumerate() {
        let t = &geometry.textures[i];
        for k in 0..levels {
            let (size, level) = texture_level(t, k as usize);
            let (aw, ah) = ((tw >> k).max(1), (th >> k).max(1));
            let data = tiled(level, size, (aw, ah));
            write(k, layer as u32, aw, ah, &data);
        }
        places[i] = TexturePlace {
            linear,
            layer: layer as u32,
            scale: [
                t.width.min(tw) as f32 / tw as f32,
                t.height.min(th) as f32 / th as f32,
            ],
        };
    }
    if members.is_empty() {
        write(0, 0, 1, 1, &[255u8; 4]);
    }
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let bytes = (0..levels)
        .map(|k| ((tw >> k).max(1) as u64) * ((th >> k).max(1) as u64) * 4)
        .sum::<u64>()
        * layers as u64;
    (view, bytes)
}
