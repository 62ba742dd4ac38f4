//! Per-frame camera and node poses, and the f64 transform chain shared by every stage.

use glam::{DMat4, Mat4};
use serde::{Deserialize, Serialize};

use crate::geometry::Node;

/// A perspective camera.
///
/// Right-handed view space looking down −Z; clip-space depth in [0, 1] (wgpu's convention)
/// with the near plane at 0. The projection is built in f64 and cast to f32 once, so every
/// pipeline that uses [`Camera::projection`] and the same node matrices rasterizes the same
/// positions.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    /// World → view transform, column-major 4×4.
    pub view: [f64; 16],
    /// Vertical field of view in radians, in (0, π).
    pub yfov: f64,
    /// Near plane distance, > 0.
    pub znear: f64,
    /// Far plane distance (> znear), or `None` for an infinite far plane.
    pub zfar: Option<f64>,
}

impl Camera {
    /// The view matrix as glam.
    pub fn view_matrix(&self) -> DMat4 {
        DMat4::from_cols_array(&self.view)
    }

    /// The projection matrix for an image of the given aspect ratio (width / height).
    pub fn projection(&self, aspect: f64) -> DMat4 {
        match self.zfar {
            Some(far) => DMat4::perspective_rh(self.yfov, aspect, self.znear, far),
            None => DMat4::perspective_infinite_rh(self.yfov, aspect, self.znear),
        }
    }

    /// The camera's position in world space.
    pub fn eye(&self) -> glam::DVec3 {
        self.view_matrix().inverse().w_axis.truncate()
    }
}

/// A node's animated local transform for one frame (replaces its rest transform).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NodePose {
    /// Node index.
    pub node: u32,
    /// Local transform, column-major 4×4.
    pub local: [f64; 16],
}

/// Everything that changes from frame to frame: the camera and the animated nodes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameState {
    /// The camera.
    pub camera: Camera,
    /// Poses of the nodes that differ from their rest transform, ascending node index.
    pub poses: Vec<NodePose>,
}

/// World transforms of every node for one frame, in f64: a node's world transform is its
/// parent's world transform times its local one (its pose if it has one, else its rest).
///
/// Requires parents to come before children (as [`Node::parent`] guarantees) and `poses` to
/// name existing nodes. O(nodes + poses).
pub fn world_transforms(nodes: &[Node], poses: &[NodePose]) -> Vec<DMat4> {
    let mut local: Vec<DMat4> = nodes
        .iter()
        .map(|n| DMat4::from_cols_array(&n.rest))
        .collect();
    for p in poses {
        local[p.node as usize] = DMat4::from_cols_array(&p.local);
    }
    let mut world: Vec<DMat4> = Vec::with_capacity(nodes.len());
    for (i, n) in nodes.iter().enumerate() {
        let w = match n.parent {
            Some(p) => {
                debug_assert!((p as usize) < i, "parents must precede children");
                world[p as usize] * local[i]
            }
            None => local[i],
        };
        world.push(w);
    }
    world
}

/// Checks what every reader relies on in one frame's state: a finite, invertible view; yfov
/// in (0, π); 0 < znear < zfar (or an infinite far plane), all finite; poses that name one of
/// `nodes` nodes (skipped when `nodes` is `None`), ascending, with finite matrices. Returns
/// the first problem found, naming frame `f`.
pub fn check_frame_state(
    f: usize,
    s: &FrameState,
    nodes: Option<usize>,
) -> Result<(), crate::StructureError> {
    let c = &s.camera;
    if !c.view.iter().all(|x| x.is_finite()) {
        return Err(crate::Part::Camera.at_frame(
            f as u32,
            format!("frame {f}: the camera's view matrix is not finite"),
        ));
    }
    let det = c.view_matrix().determinant();
    if !(det.is_finite() && det.abs() > 1e-300) {
        return Err(crate::Part::Camera.at_frame(
            f as u32,
            format!("frame {f}: the camera's view matrix is not invertible"),
        ));
    }
    if !(c.yfov > 0.0 && c.yfov < std::f64::consts::PI) {
        return Err(crate::Part::Camera.at_frame(
            f as u32,
            format!("frame {f}: yfov {} is outside (0, π)", c.yfov),
        ));
    }
    if !(c.znear > 0.0 && c.znear.is_finite()) {
        return Err(crate::Part::Camera.at_frame(
            f as u32,
            format!("frame {f}: znear {} is not a positive number", c.znear),
        ));
    }
    if let Some(far) = c.zfar {
        if !(far.is_finite() && far > c.znear) {
            return Err(crate::Part::Camera.at_frame(
                f as u32,
                format!(
                    "frame {f}: zfar {far} is not a finite number above znear {}",
                    c.znear
                ),
            ));
        }
    }
    for (k, p) in s.poses.iter().enumerate() {
        if nodes.is_some_and(|n| p.node as usize >= n) {
            return Err(crate::Part::Camera
                .at_frame(f as u32, format!("frame {f} poses missing node {}", p.node)));
        }
        if k > 0 && s.poses[k - 1].node >= p.node {
            return Err(crate::Part::Camera.at_frame(
                f as u32,
                format!("frame {f}: poses are not in ascending node order"),
            ));
        }
        if !p.local.iter().all(|x| x.is_finite()) {
            return Err(crate::Part::Camera.at_frame(
                f as u32,
                format!("frame {f}: node {}'s pose is not finite", p.node),
            ));
        }
    }
    Ok(())
}

/// Camera-relative node matrices (view × world, computed in f64, then cast to f32): what the
/// shared vertex transform multiplies local positions by. Computing the product in f64 keeps
/// precision for scenes far from the origin.
pub fn node_view_matrices(nodes: &[Node], frame: &FrameState) -> Vec<Mat4> {
    let view = frame.camera.view_matrix();
    world_transforms(nodes, &frame.poses)
        .into_iter()
        .map(|w| (view * w).as_mat4())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn child_follows_parent_pose() {
        let nodes = vec![
            Node {
                name: "root".into(),
                parent: None,
                rest: DMat4::IDENTITY.to_cols_array(),
            },
            Node {
                name: "child".into(),
                parent: Some(0),
                rest: DMat4::from_translation(DVec3::X).to_cols_array(),
            },
        ];
        let pose = NodePose {
            node: 0,
            local: DMat4::from_translation(DVec3::new(0.0, 2.0, 0.0)).to_cols_array(),
        };
        let w = world_transforms(&nodes, &[pose]);
        assert_eq!(
            w[1].transform_point3(DVec3::ZERO),
            DVec3::new(1.0, 2.0, 0.0)
        );
    }

    #[test]
    fn far_from_origin_camera_relative_is_precise() {
        let far = 1.0e6;
        let nodes = vec![Node {
            name: "n".into(),
            parent: None,
            rest: DMat4::from_translation(DVec3::splat(far)).to_cols_array(),
        }];
        let view = DMat4::look_at_rh(
            DVec3::splat(far) + DVec3::Z * 2.0,
            DVec3::splat(far),
            DVec3::Y,
        );
        let frame = FrameState {
            camera: Camera {
                view: view.to_cols_array(),
                yfov: 1.0,
                znear: 0.1,
                zfar: None,
            },
            poses: vec![],
        };
        let m = node_view_matrices(&nodes, &frame)[0];
        let p = m.transform_point3(glam::Vec3::new(1.0e-3, 0.0, 0.0));
        assert!(
            (p.x - 1.0e-3).abs() < 1e-9 && (p.z + 2.0).abs() < 1e-6,
            "{p:?}"
        );
    }
}
