//! Animations: translation, rotation and scale channels, remapped to the new node order.

use gltf::accessor::Dimensions;

use super::{label, Importer};
use crate::{Animation, Channel, Interpolation, Property, SceneError};

impl Importer<'_> {
    /// Animations with their target nodes remapped to the new node order.
    pub(super) fn animations(&mut self, new_index: &[u32]) -> Result<Vec<Animation>, SceneError> {
        let mut animations = Vec::new();
        let mut morph_channels = 0;
        for anim in self.doc.animations() {
            let mut channels = Vec::new();
            // Channel targets are not checked by gltf-json's validation (1.4.1) and
            // `gltf::animation::Target` unwraps them: check them on the JSON first.
            let json = &self.doc.as_json().animations[anim.index()];
            for (ch, json_ch) in anim.channels().zip(&json.channels) {
                let name = label("animation", anim.index(), anim.name());
                let target_node = json_ch.target.node.value();
                if target_node >= new_index.len() {
                    return Err(self.malformed(format!(
                        "{name} channel {} targets node {target_node}, which does not exist",
                        ch.index()
                    )));
                }
                let gltf::json::validation::Checked::Valid(path) = json_ch.target.path else {
                    return Err(self.malformed(format!(
                        "{name} channel {} has an unknown target path",
                        ch.index()
                    )));
                };
                let (property, shape) = match path {
                    gltf::animation::Property::Translation => {
                        (Property::Translation, Dimensions::Vec3)
                    }
                    gltf::animation::Property::Rotation => (Property::Rotation, Dimensions::Vec4),
                    gltf::animation::Property::Scale => (Property::Scale, Dimensions::Vec3),
                    gltf::animation::Property::MorphTargetWeights => {
                        morph_channels += 1;
                        continue;
                    }
                };
                let sampler = ch.sampler();
                let interpolation = match sampler.interpolation() {
                    gltf::animation::Interpolation::Linear => Interpolation::Linear,
                    gltf::animation::Interpolation::Step => Interpolation::Step,
                    gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
                };
                let usage = format!(
                    "{} channel {}",
                    label("animation", anim.index(), anim.name()),
                    ch.index()
                );
                let input = sampler.input();
                let times =
                    self.read_floats(&input, &format!("{usage} input"), &[Dimensions::Scalar])?;
                let output = sampler.output();
                let values = self.read_floats(&output, &format!("{usage} output"), &[shape])?;
                let per_key = shape.multiplicity()
                    * if interpolation == Interpolation::CubicSpline {
                        3
                    } else {
                        1
                    };
                let bad =
                    |acc: &gltf::Accessor, what: &str, problem: String| SceneError::Accessor {
                        file: self.file.clone(),
                        accessor: acc.index(),
                        usage: format!("{usage} {what}"),
                        problem,
                    };
                if times.is_empty() {
                    return Err(bad(&input, "input", "no keyframes".into()));
                }
                if !times.iter().all(|t| t.is_finite()) || times.windows(2).any(|w| w[1] < w[0]) {
                    return Err(bad(
                        &input,
                        "input",
                        "key times must be finite and ascending".into(),
                    ));
                }
                if values.len() != times.len() * per_key {
                    return Err(bad(
                        &output,
                        "output",
                        format!(
                            "{} values for {} keys, expected {per_key} per key",
                            values.len(),
                            times.len()
                        ),
                    ));
                }
                if !values.iter().all(|v| v.is_finite()) {
                    return Err(bad(&output, "output", "non-finite key value".into()));
                }
                channels.push(Channel {
                    node: new_index[target_node],
                    property,
                    interpolation,
                    times,
                    values,
                });
            }
            animations.push(Animation {
                name: anim.name().unwrap_or("").to_string(),
                channels,
            });
        }
        if morph_channels > 0 {
            self.notes.push(format!(
                "skipped {morph_channels} morph-weight animation channel(s) (no morph targets)"
            ));
        }
        Ok(animations)
    }
}
