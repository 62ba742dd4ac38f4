//! Material variants (glTF `KHR_materials_variants`): the tables a player applies, and which
//! of them a baked order stays exact under.

use serde::{Deserialize, Serialize};

use super::{AlphaMode, Geometry, Material, Texture, TextureTransform};

/// One material variant: which material each material slot shows under it.
///
/// glTF maps variants per primitive; the importer turns that into one table per variant over
/// [`Geometry::materials`] (giving a primitive a slot of its own where two primitives sharing a
/// material map it differently), so a variant is applied by rewriting the material table alone:
/// vertices keep their [`Vertex::material`](super::Vertex::material) slot.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MaterialVariant {
    /// Name from the file (`""` when unnamed; names need not be unique).
    pub name: String,
    /// Per material slot (same length as [`Geometry::materials`]): the index of the material
    /// drawn in that slot under this variant (the slot itself where the variant leaves it).
    pub materials: Vec<u32>,
}

/// Why a variant cannot be applied to a baked file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum VariantError {
    /// No variant has this name.
    #[error("no material variant {name:?}: {}", list_variants(available))]
    Unknown {
        /// The name asked for.
        name: String,
        /// The variants the file has.
        available: Vec<String>,
    },
    /// The variant changes what decides visibility, so the baked order would not be exact.
    #[error(
        "variant {variant:?} cannot be played on this bake: it replaces material {slot} {from:?} \
         by material {to:?}, which changes its {field}; that decides visibility, so the baked \
         order would not be exact (bake a scene whose default materials are this variant's)"
    )]
    ChangesVisibility {
        /// The variant.
        variant: String,
        /// The material slot.
        slot: u32,
        /// Name of the slot's default material.
        from: String,
        /// Name of the material the variant puts there.
        to: String,
        /// What differs (alpha mode, alpha cutoff, alpha, transmission, ...).
        field: &'static str,
    },
}

fn list_variants(available: &[String]) -> String {
    if available.is_empty() {
        "the file has no variants".to_string()
    } else {
        let names: Vec<String> = available.iter().map(|n| format!("{n:?}")).collect();
        format!("the file's variants are {}", names.join(", "))
    }
}

impl Geometry {
    /// The material table under variant `name` (`None`: the default materials): entry k is
    /// what slot k shows. Refused when the variant is unknown, or when it changes anything
    /// that decides which samples a triangle covers or how opaque it is, for any slot: alpha
    /// mode, double-sidedness, transmission, and for non-glass `Mask` materials the cutoff,
    /// and for non-glass `Mask` and `Blend` materials the alpha factor, the base-colour
    /// texture's alpha channel, and (where that alpha is not 255 everywhere) the base-colour
    /// texture coordinate set and transform. Colour, emissive and opaque textures may change freely.
    pub fn variant_materials(&self, name: Option<&str>) -> Result<Vec<Material>, VariantError> {
        let Some(name) = name else {
            return Ok(self.materials.clone());
        };
        let Some(variant) = self.variants.iter().find(|v| v.name == name) else {
            return Err(VariantError::Unknown {
                name: name.to_string(),
                available: self.variants.iter().map(|v| v.name.clone()).collect(),
            });
        };
        let mut out = Vec::with_capacity(self.materials.len());
        for (slot, from) in self.materials.iter().enumerate() {
            let target = variant.materials.get(slot).copied().unwrap_or(slot as u32);
            let to = self.materials.get(target as usize).unwrap_or(from);
            if let Some(field) = self.visibility_change(from, to) {
                return Err(VariantError::ChangesVisibility {
                    variant: variant.name.clone(),
                    slot: slot as u32,
                    from: from.name.clone(),
                    to: to.name.clone(),
                    field,
                });
            }
            out.push(to.clone());
        }
        Ok(out)
    }

    /// The first property deciding coverage or opacity that differs between `a` and `b`.
    fn visibility_change(&self, a: &Material, b: &Material) -> Option<&'static str> {
        if a.alpha_mode != b.alpha_mode {
            return Some("alpha mode");
        }
        if a.double_sided != b.double_sided {
            return Some("double-sidedness (back faces are culled or not)");
        }
        if a.transmission.to_bits() != b.transmission.to_bits() {
            return Some("transmission");
        }
        // Glass is drawn at the glass opacity whatever its alpha; opaque materials at 1.
        if a.transmission > 0.0 || a.alpha_mode == AlphaMode::Opaque {
            return None;
        }
        if a.alpha_mode == AlphaMode::Mask && a.alpha_cutoff.to_bits() != b.alpha_cutoff.to_bits() {
            return Some("alpha cutoff");
        }
        if a.base_color[3].to_bits() != b.base_color[3].to_bits() {
            return Some("alpha");
        }
        if !self.same_texture_alpha(a.base_color_texture, b.base_color_texture) {
            return Some("base-colour texture's alpha");
        }
        // Where the alpha varies, the coordinates it is sampled at move it.
        if self.texture_alpha_varies(a.base_color_texture)
            || self.texture_alpha_varies(b.base_color_texture)
        {
            if a.base_color_tex_coord != b.base_color_tex_coord {
                return Some("base-colour texture coordinate set (it moves the alpha)");
            }
            let bits = |t: &TextureTransform| {
                [t.offset[0], t.offset[1], t.rotation, t.scale[0], t.scale[1]].map(f32::to_bits)
            };
            if bits(&a.base_color_transform) != bits(&b.base_color_transform) {
                return Some("base-colour texture transform (it moves the alpha)");
            }
        }
        None
    }

    /// Whether texture `t` exists and has a texel with alpha below 255.
    fn texture_alpha_varies(&self, t: Option<u32>) -> bool {
        t.and_then(|t| self.textures.get(t as usize))
            .is_some_and(|t| t.rgba8.iter().skip(3).step_by(4).any(|&a| a != 255))
    }

    /// Whether two base-colour textures (or none, alpha 1) give the same alpha everywhere.
    fn same_texture_alpha(&self, a: Option<u32>, b: Option<u32>) -> bool {
        if a == b {
            return true;
        }
        let texture = |t: Option<u32>| t.and_then(|t| self.textures.get(t as usize));
        let alphas = |t: &Texture| {
            t.rgba8
                .iter()
                .skip(3)
                .step_by(4)
                .copied()
                .collect::<Vec<u8>>()
        };
        match (texture(a), texture(b)) {
            (None, None) => true,
            (Some(t), None) | (None, Some(t)) => alphas(t).iter().all(|&x| x == 255),
            (Some(s), Some(t)) => {
                s.width == t.width && s.height == t.height && alphas(s) == alphas(t)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::tests::texture_of;

    /// Slots 0 (opaque red) and 1 (masked, textured), and the materials variants may use:
    /// 2 opaque blue, 3 blend, 4 masked with another cutoff, 5 masked with a texture of the
    /// same alpha, 6 masked with a texture of another alpha, 7 single-sided red, 8 glass.
    fn geometry(variant: Vec<u32>) -> Geometry {
        let m = |name: &str, rgba: [f32; 4], mode: AlphaMode| Material {
            name: name.into(),
            base_color: rgba,
            alpha_mode: mode,
            double_sided: true,
            ..Material::default()
        };
        let texture = |alpha: u8, rgb: u8| {
            let rgba8 = vec![rgb, rgb, rgb, alpha, 0, 0, 0, 255];
            texture_of("", 2, 1, rgba8)
        };
        let masked = |name: &str, t: u32| Material {
            base_color_texture: Some(t),
            ..m(name, [1.0; 4], AlphaMode::Mask)
        };
        Geometry {
            materials: vec![
                m("red", [1.0, 0.0, 0.0, 1.0], AlphaMode::Opaque),
                masked("leaf", 0),
                m("blue", [0.0, 0.0, 1.0, 0.5], AlphaMode::Opaque),
                m("veil", [1.0; 4], AlphaMode::Blend),
                Material {
                    alpha_cutoff: 0.25,
                    ..masked("leaf low", 0)
                },
                masked("leaf recoloured", 1),
                masked("leaf holed", 2),
                Material {
                    double_sided: false,
                    ..m("red one side", [1.0, 0.0, 0.0, 1.0], AlphaMode::Opaque)
                },
                Material {
                    transmission: 1.0,
                    ..m("glass", [1.0; 4], AlphaMode::Opaque)
                },
            ],
            textures: vec![texture(128, 10), texture(128, 200), texture(0, 10)],
            variants: vec![MaterialVariant {
                name: "v".into(),
                materials: variant,
            }],
            ..Geometry::default()
        }
    }

    fn with(slot0: u32, slot1: u32) -> Geometry {
        let mut map: Vec<u32> = (0..9).collect();
        map[0] = slot0;
        map[1] = slot1;
        geometry(map)
    }

    #[test]
    fn a_variant_changing_colour_only_applies() {
        for (slot0, slot1) in [(2, 1), (0, 5), (2, 5), (0, 1)] {
            let g = with(slot0, slot1);
            g.check_structure().unwrap();
            let table = g.variant_materials(Some("v")).unwrap();
            assert_eq!(table[0], g.materials[slot0 as usize]);
            assert_eq!(table[1], g.materials[slot1 as usize]);
            assert_eq!(table[2..], g.materials[2..]);
            assert_eq!(g.variant_materials(None).unwrap(), g.materials);
        }
    }

    #[test]
    fn a_variant_changing_what_decides_visibility_is_refused_naming_it() {
        for (slot0, slot1, field, from, to) in [
            (3, 1, "alpha mode", "red", "veil"),
            (7, 1, "double-sidedness", "red", "red one side"),
            (8, 1, "transmission", "red", "glass"),
            (0, 4, "alpha cutoff", "leaf", "leaf low"),
            (0, 6, "texture's alpha", "leaf", "leaf holed"),
        ] {
            let err = with(slot0, slot1).variant_materials(Some("v")).unwrap_err();
            let VariantError::ChangesVisibility { field: f, .. } = &err else {
                panic!("{err:?}");
            };
            assert!(f.contains(field), "{err}");
            let text = err.to_string();
            for needle in ["\"v\"", &format!("{from:?}"), &format!("{to:?}"), "exact"] {
                assert!(text.contains(needle), "{text} lacks {needle}");
            }
        }
        // An alpha factor change on a blend material is refused too.
        let mut g = with(0, 1);
        g.materials[2] = Material {
            base_color: [1.0, 1.0, 1.0, 0.5],
            ..g.materials[3].clone()
        };
        g.variants[0].materials[3] = 2;
        let err = g.variant_materials(Some("v")).unwrap_err();
        assert!(err.to_string().contains("its alpha;"), "{err}");
    }

    #[test]
    fn an_unknown_variant_lists_the_files_variants() {
        let err = with(0, 1).variant_materials(Some("w")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "no material variant \"w\": the file's variants are \"v\""
        );
        let none = Geometry::default()
            .variant_materials(Some("w"))
            .unwrap_err();
        assert!(
            none.to_string().ends_with("the file has no variants"),
            "{none}"
        );
    }

    #[test]
    fn check_structure_refuses_variants_that_do_not_map_every_slot() {
        let mut g = with(0, 1);
        g.variants[0].materials.pop();
        assert!(g
            .check_structure()
            .unwrap_err()
            .problem
            .contains("maps 8 material slots"));
        let mut g = with(0, 1);
        g.variants[0].materials[0] = 9;
        assert!(g
            .check_structure()
            .unwrap_err()
            .problem
            .contains("missing material 9"));
    }

    #[test]
    fn a_variant_moving_a_varying_alpha_is_refused() {
        // Slot 1 ("leaf") is masked with texture 0, whose alpha varies.
        let mut g = with(0, 5);
        g.materials[5].base_color_tex_coord = 1;
        let err = g.variant_materials(Some("v")).unwrap_err();
        assert!(err.to_string().contains("texture coordinate set"), "{err}");
        let mut g = with(0, 5);
        g.materials[5].base_color_transform.rotation = 0.5;
        let err = g.variant_materials(Some("v")).unwrap_err();
        assert!(err.to_string().contains("texture transform"), "{err}");
        // Opaque materials may move their texture freely.
        let mut g = with(2, 1);
        g.materials[2].base_color_texture = Some(0);
        g.materials[2].base_color_transform.offset = [0.5, 0.0];
        g.variant_materials(Some("v")).unwrap();
    }
}
