//! The car's materials and its one texture, the licence plate.
//!
//! Physically plausible metallic-roughness values, so the physically based shading has
//! something to show: a metallic red paint under a clearcoat, chrome rims, rubber tyres,
//! tinted glass with transmission (drawn at the bake's glass opacity), dielectric interior
//! and plate.

use trisort_format::{AlphaMode, Material, Texture};

use super::{GLASS_MATERIAL, PLATE};

/// The materials, at the indices of the material constants (`PAINT`, `GLASS`, …).
pub(super) fn materials() -> Vec<Material> {
    // A dielectric (metallic 0) of the given colour and roughness.
    let dielectric = |name: &str, rgb: [f32; 3], roughness: f32| Material {
        name: name.into(),
        base_color: [rgb[0], rgb[1], rgb[2], 1.0],
        metallic: 0.0,
        roughness,
        ..Material::default()
    };
    let mut list = vec![
        // Metallic flake paint under a smooth clearcoat.
        Material {
            metallic: 0.6,
            clearcoat: 1.0,
            clearcoat_roughness: 0.03,
            ..dielectric("paint", [0.60, 0.04, 0.03], 0.35)
        },
        Material {
            name: GLASS_MATERIAL.into(),
            base_color: [0.60, 0.80, 1.00, 0.30],
            alpha_mode: AlphaMode::Blend,
            double_sided: true,
            transmission: 1.0,
            metallic: 0.0,
            roughness: 0.02,
            ..Material::default()
        },
        dielectric("tyre", [0.03, 0.03, 0.03], 0.9),
        // Chrome: a polished metal (base colour is its reflectance).
        Material {
            metallic: 1.0,
            ..dielectric("rim", [0.55, 0.56, 0.58], 0.08)
        },
        dielectric("seat", [0.30, 0.16, 0.08], 0.6),
        dielectric("dashboard", [0.05, 0.05, 0.06], 0.5),
        dielectric("steering", [0.02, 0.02, 0.02], 0.45),
        dielectric("licence plate", [1.0, 1.0, 1.0], 0.4),
    ];
    list[PLATE as usize].base_color_texture = Some(0);
    list
}

/// The licence plate texture: "TRISORT" in a 5×7 pixel font on a yellow plate with a dark
/// border, 64×16 texels, sRGB, with its mip chain.
pub(super) fn plate_texture() -> Texture {
    const W: usize = 64;
    const H: usize = 16;
    const TEXT: &str = "TRISORT";
    let glyph = |c: char| -> [u8; 7] {
        match c {
            'T' => [0x1f, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04],
            'R' => [0x1e, 0x11, 0x11, 0x1e, 0x14, 0x12, 0x11],
            'I' => [0x0e, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e],
            'S' => [0x0f, 0x10, 0x10, 0x0e, 0x01, 0x01, 0x1e],
            'O' => [0x0e, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e],
            _ => [0; 7],
        }
    };
    let background = [245u8, 210, 50, 255];
    let ink = [20u8, 24, 40, 255];
    let mut rgba8 = Vec::with_capacity(W * H * 4);
    let text_w = TEXT.len() * 6 - 1;
    let (x0, y0) = ((W - text_w) / 2, (H - 7) / 2);
    for y in 0..H {
        for x in 0..W {
            let border = x == 0 || y == 0 || x == W - 1 || y == H - 1;
            let in_text = x >= x0 && x < x0 + text_w && y >= y0 && y < y0 + 7 && {
                let (col, row) = (x - x0, y - y0);
                let c = TEXT.as_bytes()[col / 6] as char;
                col % 6 < 5 && glyph(c)[row] & (0x10 >> (col % 6)) != 0
            };
            rgba8.extend_from_slice(if border || in_text { &ink } else { &background });
        }
    }
    let (texture, _) = crate::mips::texture_with_mips(
        "licence plate".into(),
        W as u32,
        H as u32,
        rgba8,
        true,
        crate::mips::MAX_SIZE,
    );
    texture
}
