//! Cameras: perspective cameras on nodes of the scene.

use super::{label, node_label, Importer};
use crate::SceneCamera;

impl Importer<'_> {
    /// Perspective cameras on nodes of the scene, in node order.
    pub(super) fn cameras(
        &mut self,
        order: &[usize],
        in_scene: &[bool],
        file_nodes: &[gltf::Node],
    ) -> Vec<SceneCamera> {
        let mut cameras = Vec::new();
        for (new, &n) in order.iter().enumerate() {
            let node = &file_nodes[n];
            let Some(camera) = node.camera().filter(|_| in_scene[n]) else {
                continue;
            };
            // Read the JSON directly: `gltf::Camera::projection` unwraps a missing
            // perspective object when the type says perspective.
            let json = &self.doc.as_json().cameras[camera.index()];
            let perspective = matches!(
                json.type_,
                gltf::json::validation::Checked::Valid(gltf::json::camera::Type::Perspective)
            );
            match json.perspective.as_ref().filter(|_| perspective) {
                Some(p) => cameras.push(SceneCamera {
                    name: camera.name().unwrap_or("").to_string(),
                    node: new as u32,
                    yfov: f64::from(p.yfov),
                    znear: f64::from(p.znear),
                    zfar: p.zfar.map(f64::from),
                    aspect: p.aspect_ratio.map(f64::from),
                }),
                None => self.notes.push(format!(
                    "skipped {} on {}: {}",
                    label("camera", camera.index(), camera.name()),
                    node_label(node),
                    if perspective {
                        "no perspective parameters"
                    } else {
                        "orthographic cameras are not supported"
                    }
                )),
            }
        }
        cameras
    }
}
