//! The material table as the shaders read it (`MaterialGpu`): factors, alpha mode, and per
//! texture slot its transform and where its texture lies in the arrays.

use bytemuck::{Pod, Zeroable};
use trisort_format::{AlphaMode, Material, TextureTransform};

use super::textures::TexturePlace;

/// The `MaterialGpu` struct of the shared WGSL.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MaterialGpu {
    base_color: [f32; 4],
    emissive: [f32; 4],
    params: [f32; 4],
    pbr: [f32; 4],
    coat: [f32; 4],
    /// Base colour, metallic-roughness, normal, occlusion, emissive: u row, v row, scale.
    slots: [[[f32; 4]; 3]; 5],
}

/// A texture slot as the shaders read it: transform rows with the layer (< 0: none) and the
/// texture coordinate set, and the layer's uv scale with its array (0 sRGB, 1 linear).
fn slot_gpu(
    texture: Option<u32>,
    tex_coord: u32,
    transform: &TextureTransform,
    places: &[TexturePlace],
) -> [[f32; 4]; 3] {
    let m = transform.matrix();
    let place = texture.and_then(|t| places.get(t as usize));
    let (layer, scale, array) = match place {
        Some(p) => (p.layer as f32, p.scale, if p.linear { 1.0 } else { 0.0 }),
        None => (-1.0, [1.0, 1.0], 0.0),
    };
    [
        [m[0][0], m[0][1], m[0][2], layer],
        [m[1][0], m[1][1], m[1][2], tex_coord.min(1) as f32],
        [scale[0], scale[1], array, 0.0],
    ]
}

/// The materials as the shaders read them (one zeroed material where the scene has none).
pub(super) fn material_table(materials: &[Material], places: &[TexturePlace]) -> Vec<MaterialGpu> {
    let mut mats: Vec<MaterialGpu> = materials
        .iter()
        .map(|m| {
            let mode = match m.alpha_mode {
                AlphaMode::Opaque => 0.0,
                AlphaMode::Mask => 1.0,
                AlphaMode::Blend => 2.0,
            };
            let slot = |s: &Option<trisort_format::TextureSlot>| match s {
                Some(s) => slot_gpu(Some(s.texture), s.tex_coord, &s.transform, places),
                None => slot_gpu(None, 0, &TextureTransform::default(), places),
            };
            let base = slot_gpu(
                m.base_color_texture,
                m.base_color_tex_coord,
                &m.base_color_transform,
                places,
            );
            MaterialGpu {
                base_color: m.base_color,
                emissive: [m.emissive[0], m.emissive[1], m.emissive[2], m.transmission],
                params: [
                    mode,
                    m.alpha_cutoff,
                    if m.double_sided { 1.0 } else { 0.0 },
                    base[0][3],
                ],
                pbr: [
                    m.metallic,
                    m.roughness,
                    m.normal_scale,
                    m.occlusion_strength,
                ],
                coat: [m.clearcoat, m.clearcoat_roughness, 0.0, 0.0],
                slots: [
                    base,
                    slot(&m.metallic_roughness_texture),
                    slot(&m.normal_texture),
                    slot(&m.occlusion_texture),
                    slot(&m.emissive_texture),
                ],
            }
        })
        .collect();
    if mats.is_empty() {
        mats.push(MaterialGpu::zeroed());
    }
    mats
}
