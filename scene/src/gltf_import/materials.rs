//! Materials and their base-colour images, decoded to RGBA8 textures.

use std::borrow::Cow;
use std::collections::HashMap;

use trisort_format::{AlphaMode, Material, MaterialVariant, Texture};

use super::container::read_uri;
use super::{label, Importer};
use crate::SceneError;

/// The materials of the file at their own indices, then the default material once some
/// primitive needs it, with the base-colour textures they use.
pub(super) struct Materials {
    /// The materials.
    pub(super) list: Vec<Material>,
    /// The decoded base-colour textures, in order of first use.
    pub(super) textures: Vec<Texture>,
    /// The texture coordinate set each material's base-colour texture samples (`None` when
    /// untextured).
    pub(super) uv_set: Vec<Option<u32>>,
    /// Index of the default material once appended.
    default: Option<u32>,
    /// Per slot of `list`, once a primitive uses it: the material each variant shows there.
    targets: Vec<Option<Vec<u32>>>,
    /// Slots added for a material that primitives map differently: `(material, targets)`.
    copies: HashMap<(u32, Vec<u32>), u32>,
}

impl Materials {
    /// The material index of a primitive: its own, or the default material, appended on first
    /// use.
    pub(super) fn of(&mut self, prim: &gltf::Primitive) -> u32 {
        match prim.material().index() {
            Some(i) => i as u32,
            None => *self.default.get_or_insert_with(|| {
                self.list.push(Material {
                    name: "default".to_string(),
                    ..Material::default()
                });
                self.uv_set.push(None);
                (self.list.len() - 1) as u32
            }),
        }
    }
}

impl Materials {
    /// The slot a primitive with material `material` draws with, given the material each
    /// variant shows on it (`targets`, one per variant): `material` itself for the first such
    /// primitive and every one mapped alike; a copy of it, in a slot of its own, for a
    /// primitive mapped differently.
    pub(super) fn slot(&mut self, material: u32, targets: Vec<u32>) -> u32 {
        self.targets.resize(self.list.len(), None);
        match &self.targets[material as usize] {
            None => {
                self.targets[material as usize] = Some(targets);
                material
            }
            Some(t) if *t == targets => material,
            Some(_) => {
                if let Some(&slot) = self.copies.get(&(material, targets.clone())) {
                    return slot;
                }
                self.list.push(self.list[material as usize].clone());
                self.uv_set.push(self.uv_set[material as usize]);
                let slot = (self.list.len() - 1) as u32;
                self.targets.push(Some(targets.clone()));
                self.copies.insert((material, targets), slot);
                slot
            }
        }
    }

    /// One table per variant (named by `names`): per slot, the material the variant shows
    /// there (the slot itself where no primitive maps it).
    pub(super) fn variant_tables(&self, names: &[String]) -> Vec<MaterialVariant> {
        let slots = self.list.len();
        (names.iter().enumerate())
            .map(|(v, name)| MaterialVariant {
                name: name.clone(),
                materials: (0..slots)
                    .map(|s| match self.targets.get(s) {
                        Some(Some(t)) => t[v],
                        _ => s as u32,
                    })
                    .collect(),
            })
            .collect()
    }
}

impl Importer<'_> {
    /// Converts every material of the file, decoding its base-colour texture.
    pub(super) fn materials(&mut self) -> Result<Materials, SceneError> {
        let mut materials = Materials {
            list: Vec::new(),
            textures: Vec::new(),
            uv_set: Vec::new(),
            default: None,
            targets: Vec::new(),
            copies: HashMap::new(),
        };
        let mut texture_of_image: HashMap<usize, u32> = HashMap::new();
        for m in self.doc.materials() {
            let (material, set) =
                self.material(&m, &mut materials.textures, &mut texture_of_image)?;
            materials.list.push(material);
            materials.uv_set.push(set);
        }
        Ok(materials)
    }

    /// Converts a material; returns it with the texture coordinate set its base-colour texture
    /// samples (`None` when untextured). Decodes its texture on first use.
    fn material(
        &mut self,
        m: &gltf::Material,
        textures: &mut Vec<Texture>,
        texture_of_image: &mut HashMap<usize, u32>,
    ) -> Result<(Material, Option<u32>), SceneError> {
        let pbr = m.pbr_metallic_roughness();
        let name = m.name().unwrap_or("").to_string();
        let mut texture = None;
        let mut set = None;
        if let Some(info) = pbr.base_color_texture() {
            let image = info.texture().source();
            let slot = match texture_of_image.get(&image.index()) {
                Some(&slot) => slot,
                None => {
                    textures.push(self.decode_image(&image)?);
                    let slot = (textures.len() - 1) as u32;
                    texture_of_image.insert(image.index(), slot);
                    slot
                }
            };
            texture = Some(slot);
            set = Some(info.tex_coord());
            if info.tex_coord() != 0 {
                self.notes.push(format!(
                    "{} samples its base-colour texture with TEXCOORD_{}; imported as the \
                     vertex uv",
                    label("material", m.index().unwrap_or(0), m.name()),
                    info.tex_coord()
                ));
            }
        }
        let strength = m.emissive_strength().unwrap_or(1.0);
        let material = Material {
            name,
            base_color: pbr.base_color_factor(),
            base_color_texture: texture,
            alpha_mode: match m.alpha_mode() {
                gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                gltf::material::AlphaMode::Mask => AlphaMode::Mask,
                gltf::material::AlphaMode::Blend => AlphaMode::Blend,
            },
            alpha_cutoff: m.alpha_cutoff().unwrap_or(0.5),
            double_sided: m.double_sided(),
            emissive: m.emissive_factor().map(|c| c * strength),
            transmission: m.transmission().map_or(0.0, |t| t.transmission_factor()),
            ..Material::default()
        };
        Ok((material, set))
    }

    /// Loads and decodes an image to RGBA8.
    fn decode_image(&self, image: &gltf::Image) -> Result<Texture, SceneError> {
        // Read the JSON directly: `gltf::Image::source` unwraps a missing mimeType or URI.
        let json = &self.doc.as_json().images[image.index()];
        let (bytes, uri): (Cow<[u8]>, Option<&str>) = match (&json.buffer_view, &json.uri) {
            (Some(view), _) => {
                let view = self.doc.views().nth(view.value()).ok_or_else(|| {
                    self.image_error(image, "", "dangling buffer view".to_string())
                })?;
                (
                    Cow::Borrowed(
                        self.view_bytes(&view)
                            .map_err(|p| self.image_error(image, "", p))?,
                    ),
                    None,
                )
            }
            (None, Some(uri)) => (
                Cow::Owned(
                    read_uri(uri, self.base.as_deref())
                        .map_err(|p| self.image_error(image, uri, p))?,
                ),
                Some(uri.as_str()),
            ),
            (None, None) => {
                return Err(self.image_error(
                    image,
                    "",
                    "has neither a URI nor a buffer view".to_string(),
                ))
            }
        };
        let name = image
            .name()
            .or(uri.filter(|u| !u.starts_with("data:")))
            .map_or_else(|| format!("image {}", image.index()), str::to_string);
        let decoded = ::image::load_from_memory(&bytes)
            .map_err(|e| self.image_error(image, &name, format!("cannot decode: {e}")))?
            .into_rgba8();
        Ok(Texture {
            name,
            width: decoded.width(),
            height: decoded.height(),
            rgba8: decoded.into_raw(),
            srgb: true,
            mips: Vec::new(),
        })
    }

    fn image_error(&self, image: &gltf::Image, uri: &str, problem: String) -> SceneError {
        let name = image
            .name()
            .unwrap_or(if uri.starts_with("data:") { "" } else { uri });
        SceneError::Image {
            file: self.file.clone(),
            image: image.index(),
            name: name.to_string(),
            problem,
        }
    }
}
