//! Materials and the images they use, decoded to RGBA8 textures with mip chains.

use std::borrow::Cow;
use std::collections::HashMap;

use serde_json::Value;
use trisort_format::{
    AlphaMode, Material, MaterialVariant, Texture, TextureSlot, TextureTransform,
};

use super::container::{read_uri, IMAGE_EXTENSIONS};
use super::{ktx2, label, Importer};
use crate::mips::texture_with_mips;
use crate::SceneError;

/// What the vertices of a material's primitives must carry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Needs {
    /// Texture coordinate sets 0 and 1: whether some texture slot samples them.
    pub(super) uv: [bool; 2],
    /// The texture coordinate set of the normal texture, when there is one: tangents are read
    /// (or generated from this set).
    pub(super) tangent_set: Option<u32>,
}

impl Needs {
    /// What a primitive showing any of several materials needs: every set any of them
    /// samples, and the tangents of the first with a normal texture.
    pub(super) fn union(self, other: Needs) -> Needs {
        Needs {
            uv: [self.uv[0] || other.uv[0], self.uv[1] || other.uv[1]],
            tangent_set: self.tangent_set.or(other.tangent_set),
        }
    }
}

/// The materials of the file at their own indices, then the default material once some
/// primitive needs it, with the textures they use.
pub(super) struct Materials {
    /// The materials.
    pub(super) list: Vec<Material>,
    /// The decoded textures, in order of first use.
    pub(super) textures: Vec<Texture>,
    /// Per material, what its vertices must carry.
    pub(super) needs: Vec<Needs>,
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
                self.needs.push(Needs::default());
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
                self.needs.push(self.needs[material as usize]);
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

/// The textures decoded so far: one per image and colour space.
#[derive(Default)]
struct TextureCache {
    textures: Vec<Texture>,
    by_image: HashMap<(usize, bool), u32>,
}

/// The texture reference of a material slot, as the file gives it.
struct SlotRef<'d> {
    /// What the slot is, for notes and errors ("normal").
    what: &'static str,
    texture: gltf::Texture<'d>,
    tex_coord: u32,
    /// The reference's `KHR_texture_transform` object, if any.
    transform: Option<Value>,
    /// Whether the slot holds colour (sRGB) rather than data.
    srgb: bool,
}

/// The slot reference of a texture info (base colour, metallic-roughness, emissive).
fn info<'d>(what: &'static str, info: gltf::texture::Info<'d>, srgb: bool) -> SlotRef<'d> {
    SlotRef {
        what,
        texture: info.texture(),
        tex_coord: info.tex_coord(),
        transform: info.extension_value("KHR_texture_transform").cloned(),
        srgb,
    }
}

/// The largest width or height a texture is stored at (see [`texture_with_mips`]).
const MAX_TEXTURE_SIZE: u32 = crate::mips::MAX_SIZE;

/// `KHR_materials_clearcoat`, read from the material's raw extension JSON.
const CLEARCOAT: &str = "KHR_materials_clearcoat";

/// Members of material extensions that trisort reads; any other member or extension of a
/// material is listed in a note.
const READ_MEMBERS: &[(&str, &[&str])] =
    &[(CLEARCOAT, &["clearcoatFactor", "clearcoatRoughnessFactor"])];

impl Importer<'_> {
    /// Converts every material of the file, decoding the textures it uses.
    pub(super) fn materials(&mut self) -> Result<Materials, SceneError> {
        let mut cache = TextureCache::default();
        let mut list = Vec::new();
        let mut needs = Vec::new();
        for m in self.doc.materials() {
            let (material, need) = self.material(&m, &mut cache)?;
            list.push(material);
            needs.push(need);
        }
        Ok(Materials {
            list,
            textures: cache.textures,
            needs,
            default: None,
            targets: Vec::new(),
            copies: HashMap::new(),
        })
    }

    /// Converts a material; returns it with what its vertices must carry. Decodes each
    /// texture it uses on first use (per colour space).
    fn material(
        &mut self,
        m: &gltf::Material,
        cache: &mut TextureCache,
    ) -> Result<(Material, Needs), SceneError> {
        let who = label("material", m.index().unwrap_or(0), m.name());
        let pbr = m.pbr_metallic_roughness();
        let mut needs = Needs::default();
        let mut slot =
            |this: &mut Self, r: Option<SlotRef>| -> Result<Option<TextureSlot>, SceneError> {
                let Some(r) = r else { return Ok(None) };
                let slot = this.texture_slot(&who, r, cache)?;
                needs.uv[slot.tex_coord as usize] = true;
                Ok(Some(slot))
            };
        let base = slot(
            self,
            pbr.base_color_texture()
                .map(|i| info("base-colour", i, true)),
        )?;
        let metallic_roughness = slot(
            self,
            pbr.metallic_roughness_texture()
                .map(|i| info("metallic-roughness", i, false)),
        )?;
        let normal_ref = m.normal_texture();
        let normal = slot(
            self,
            normal_ref.as_ref().map(|n| SlotRef {
                what: "normal",
                texture: n.texture(),
                tex_coord: n.tex_coord(),
                transform: n.extension_value("KHR_texture_transform").cloned(),
                srgb: false,
            }),
        )?;
        let occlusion_ref = m.occlusion_texture();
        let occlusion = slot(
            self,
            occlusion_ref.as_ref().map(|o| SlotRef {
                what: "occlusion",
                texture: o.texture(),
                tex_coord: o.tex_coord(),
                transform: o.extension_value("KHR_texture_transform").cloned(),
                srgb: false,
            }),
        )?;
        let emissive = slot(
            self,
            m.emissive_texture().map(|i| info("emissive", i, true)),
        )?;
        needs.tangent_set = normal.map(|n| n.tex_coord);
        let (clearcoat, clearcoat_roughness) = self.clearcoat(m, &who)?;
        self.note_unrendered(m, &who);
        let strength = m.emissive_strength().unwrap_or(1.0);
        let material = Material {
            name: m.name().unwrap_or("").to_string(),
            base_color: pbr.base_color_factor(),
            base_color_texture: base.map(|s| s.texture),
            base_color_tex_coord: base.map_or(0, |s| s.tex_coord),
            base_color_transform: base.map_or_else(TextureTransform::default, |s| s.transform),
            alpha_mode: match m.alpha_mode() {
                gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                gltf::material::AlphaMode::Mask => AlphaMode::Mask,
                gltf::material::AlphaMode::Blend => AlphaMode::Blend,
            },
            alpha_cutoff: m.alpha_cutoff().unwrap_or(0.5),
            double_sided: m.double_sided(),
            emissive: m.emissive_factor().map(|c| c * strength),
            transmission: m.transmission().map_or(0.0, |t| t.transmission_factor()),
            metallic: pbr.metallic_factor(),
            roughness: pbr.roughness_factor(),
            metallic_roughness_texture: metallic_roughness,
            normal_texture: normal,
            normal_scale: normal_ref.as_ref().map_or(1.0, |n| n.scale()),
            occlusion_texture: occlusion,
            occlusion_strength: occlusion_ref.as_ref().map_or(1.0, |o| o.strength()),
            emissive_texture: emissive,
            clearcoat,
            clearcoat_roughness,
        };
        let factors = [
            material.metallic,
            material.roughness,
            material.normal_scale,
            material.occlusion_strength,
            material.alpha_cutoff,
            material.transmission,
        ];
        if !(factors
            .iter()
            .chain(&material.base_color)
            .chain(&material.emissive))
        .all(|x| x.is_finite())
        {
            return Err(self.malformed(format!("{who} has a factor that is not a finite number")));
        }
        Ok((material, needs))
    }

    /// A texture reference as a slot: its texture (decoded on first use in its colour
    /// space), its texture coordinate set (the transform's `texCoord` overrides the
    /// reference's; a set above 1 is noted and replaced by 0) and its transform.
    fn texture_slot(
        &mut self,
        who: &str,
        r: SlotRef,
        cache: &mut TextureCache,
    ) -> Result<TextureSlot, SceneError> {
        let (transform, override_set) = match &r.transform {
            None => (TextureTransform::default(), None),
            Some(v) => texture_transform(v).map_err(|problem| {
                self.malformed(format!(
                    "{who}: KHR_texture_transform of its {} texture: {problem}",
                    r.what
                ))
            })?,
        };
        let mut tex_coord = override_set.unwrap_or(r.tex_coord);
        if tex_coord > 1 {
            self.notes.push(format!(
                "{who} samples its {} texture with TEXCOORD_{tex_coord}; only TEXCOORD_0 and \
                 TEXCOORD_1 are read, so it samples TEXCOORD_0",
                r.what
            ));
            tex_coord = 0;
        }
        // An image extension's image when the texture has one (`container::image_sources`).
        let image = r.texture.source();
        let key = (image.index(), r.srgb);
        let texture = match cache.by_image.get(&key) {
            Some(&t) => t,
            None => {
                let mut via = label("texture", r.texture.index(), r.texture.name());
                if let Some(ext) =
                    (IMAGE_EXTENSIONS.iter()).find(|&&ext| r.texture.extension_value(ext).is_some())
                {
                    via = format!("{via} ({ext})");
                }
                let texture = self.decode_image(&image, r.srgb, &via)?;
                cache.textures.push(texture);
                let t = (cache.textures.len() - 1) as u32;
                cache.by_image.insert(key, t);
                t
            }
        };
        Ok(TextureSlot {
            texture,
            tex_coord,
            transform,
        })
    }

    /// `KHR_materials_clearcoat`'s factor and roughness factor (0 and 0 without it).
    fn clearcoat(&self, m: &gltf::Material, who: &str) -> Result<(f32, f32), SceneError> {
        let Some(ext) = m.extension_value(CLEARCOAT) else {
            return Ok((0.0, 0.0));
        };
        let bad = |problem: String| self.malformed(format!("{who}: {CLEARCOAT}: {problem}"));
        let Some(ext) = ext.as_object() else {
            return Err(bad("is not an object".to_string()));
        };
        let factor = |name: &str| -> Result<f32, SceneError> {
            match ext.get(name) {
                None => Ok(0.0),
                Some(v) => match v.as_f64().map(|x| x as f32) {
                    Some(x) if x.is_finite() && (0.0..=1.0).contains(&x) => Ok(x),
                    _ => Err(bad(format!("{name} is {v}, not a number from 0 to 1"))),
                },
            }
        };
        Ok((
            factor("clearcoatFactor")?,
            factor("clearcoatRoughnessFactor")?,
        ))
    }

    /// One note per material naming the extensions and members of it that are not rendered
    /// (clearcoat textures, iridescence, sheen, …, the transmission texture).
    fn note_unrendered(&mut self, m: &gltf::Material, who: &str) {
        let mut ignored = Vec::new();
        let json = &self.doc.as_json().materials[m.index().unwrap_or(0)];
        if let Some(others) = json.extensions.as_ref().map(|e| &e.others) {
            for (name, value) in others {
                match READ_MEMBERS.iter().find(|(ext, _)| ext == name) {
                    None => ignored.push(name.clone()),
                    Some((_, read)) => {
                        let members = value.as_object().into_iter().flatten();
                        ignored.extend(
                            members
                                .filter(|(k, _)| !read.contains(&k.as_str()))
                                .map(|(k, _)| format!("{name} {k}")),
                        );
                    }
                }
            }
        }
        if m.transmission()
            .and_then(|t| t.transmission_texture())
            .is_some()
        {
            ignored.push("KHR_materials_transmission transmissionTexture".to_string());
        }
        if !ignored.is_empty() {
            self.notes.push(format!(
                "{who}: not rendered, ignored: {}",
                ignored.join(", ")
            ));
        }
    }

    /// Loads and decodes an image to RGBA8 with its mip chain, stored from its first level no
    /// larger than [`MAX_TEXTURE_SIZE`] (noted, with the bytes): PNG, JPEG or WebP through the
    /// `image` crate, KTX2 (`KHR_texture_basisu`, by its MIME type or identifier) through
    /// [`ktx2::decode`], level 0 only. `via` names the texture that uses it, for errors.
    fn decode_image(
        &mut self,
        image: &gltf::Image,
        srgb: bool,
        via: &str,
    ) -> Result<Texture, SceneError> {
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
        let mime = json.mime_type.as_ref().map(|m| m.0.as_str());
        let (width, height, texels) = if mime == Some(ktx2::MIME_TYPE)
            || bytes.starts_with(&ktx2::IDENTIFIER)
        {
            ktx2::decode(&bytes)
                .map_err(|p| self.image_error(image, &name, format!("{via}: {p}")))?
        } else {
            let decoded = ::image::load_from_memory(&bytes)
                .map_err(|e| self.image_error(image, &name, format!("{via}: cannot decode: {e}")))?
                .into_rgba8();
            (decoded.width(), decoded.height(), decoded.into_raw())
        };
        if width == 0 || height == 0 {
            return Err(self.image_error(image, &name, format!("{via}: is empty")));
        }
        let (texture, dropped) =
            texture_with_mips(name, width, height, texels, srgb, MAX_TEXTURE_SIZE);
        if dropped > 0 {
            let full: u64 = (0..=Texture::mip_count(width, height) as u32)
                .map(|k| {
                    let (w, h) = Texture::level_size(width, height, k);
                    w as u64 * h as u64 * 4
                })
                .sum();
            self.notes.push(format!(
                "image {} {:?} ({width}x{height}) is stored from mip level {dropped} ({}x{}, at \
                 most {MAX_TEXTURE_SIZE} texels a side): {} bytes with its mips instead of {full}",
                image.index(),
                texture.name,
                texture.width,
                texture.height,
                texture.byte_len()
            ));
        }
        Ok(texture)
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

/// A `KHR_texture_transform` object: the transform and its `texCoord` override, or what is
/// wrong with it.
fn texture_transform(v: &Value) -> Result<(TextureTransform, Option<u32>), String> {
    let Some(obj) = v.as_object() else {
        return Err(format!("{v} is not an object"));
    };
    let number = |name: &str, v: &Value| -> Result<f32, String> {
        match v.as_f64().map(|x| x as f32) {
            Some(x) if x.is_finite() => Ok(x),
            _ => Err(format!("{name} {v} is not a finite number")),
        }
    };
    let pair = |name: &str, default: [f32; 2]| -> Result<[f32; 2], String> {
        match obj.get(name) {
            None => Ok(default),
            Some(Value::Array(a)) if a.len() == 2 => {
                Ok([number(name, &a[0])?, number(name, &a[1])?])
            }
            Some(v) => Err(format!("{name} {v} is not an array of two numbers")),
        }
    };
    let transform = TextureTransform {
        offset: pair("offset", [0.0; 2])?,
        rotation: obj
            .get("rotation")
            .map_or(Ok(0.0), |v| number("rotation", v))?,
        scale: pair("scale", [1.0; 2])?,
    };
    let tex_coord = match obj.get("texCoord") {
        None => None,
        Some(v) => match v.as_u64() {
            Some(n) => Some(u32::try_from(n).unwrap_or(u32::MAX)),
            None => return Err(format!("texCoord {v} is not a non-negative integer")),
        },
    };
    Ok((transform, tex_coord))
}
