//! The demo car's default path: an orbit while the driver door opens and closes.

use glam::{DMat4, DVec3};
use trisort_format::world_transforms;
use trisort_scene::Scene;

use crate::generators::Orbit;
use crate::interpolate::{Interpolation, Track};
use crate::poses::{pivot_pose, pose_if_moved};
use crate::view::Bounds;
use crate::Timeline;

/// Name of the demo car's driver door node (origin at the hinge, opening about local +Y).
pub(crate) const DOOR: &str = "DriverDoor";
/// Frames of the demo path.
const FRAMES: usize = 48;
/// Door angle keys (frame, degrees): closed, open 60°, hold, closed; eased.
const DOOR_KEYS: [(f64, f64); 4] = [(8.0, 0.0), (20.0, 60.0), (28.0, 60.0), (40.0, 0.0)];

/// See [`crate::demo_default`].
pub(crate) fn demo_default(scene: &Scene, fps: f64) -> Timeline {
    let bounds = Bounds::of_scene(scene)
        .unwrap_or_else(|_| Bounds::from_box(DVec3::splat(-1.0), DVec3::splat(1.0)));
    let door = scene.node_by_name(DOOR);
    let mut orbit = Orbit {
        frames: FRAMES,
        elevation: 15.0,
        ..Orbit::default()
    };
    // Put the camera on the door's side while the door is open (frame 24 is half a turn
    // after frame 0).
    let door_side = door.and_then(|d| door_geometry(scene, d, &bounds));
    if let Some(g) = &door_side {
        let az = g.outward.x.atan2(g.outward.z).to_degrees();
        orbit.start = az - 180.0;
    }
    let mut frames = orbit
        .frames(&bounds)
        .expect("an orbit at 15° elevation and 2.75 radii always has a valid camera");
    if let Some(d) = door {
        let sign = door_side.map_or(1.0, |g| g.opening_sign);
        let rest = DMat4::from_cols_array(&scene.geometry.nodes[d as usize].rest);
        let track = Track::new(
            DOOR_KEYS.iter().map(|&(f, a)| (f, [a])).collect(),
            Interpolation::EaseInOut,
        );
        for (f, frame) in frames.iter_mut().enumerate() {
            let angle = sign * track.sample(f as f64)[0].to_radians();
            let local = pivot_pose(rest, DVec3::ZERO, DVec3::ZERO, DVec3::Y, angle);
            frame
                .poses
                .extend(pose_if_moved(d, &rest.to_cols_array(), local));
        }
    }
    Timeline { fps, frames }
}

/// Where a door is and which way it opens.
pub(crate) struct DoorGeometry {
    /// Horizontal direction from the scene's centre to the door's centroid (unit, y = 0).
    pub outward: DVec3,
    /// +1 when a positive rotation about the door's local +Y moves it away from the scene's
    /// centre, −1 otherwise.
    pub opening_sign: f64,
}

/// The door's outward direction and opening sign, from the rest-pose centroid of the
/// vertices of `door` and its descendants and where a 10° turn about local +Y moves it.
/// `None` when the door has no triangles or sits on the vertical axis through the centre.
pub(crate) fn door_geometry(scene: &Scene, door: u32, bounds: &Bounds) -> Option<DoorGeometry> {
    let g = &scene.geometry;
    let mut in_door = vec![false; g.nodes.len()];
    for (i, n) in g.nodes.iter().enumerate() {
        in_door[i] = i == door as usize || n.parent.is_some_and(|p| in_door[p as usize]);
    }
    let rest = DMat4::from_cols_array(&g.nodes[door as usize].rest);
    let turned = pivot_pose(rest, DVec3::ZERO, DVec3::ZERO, DVec3::Y, 10f64.to_radians());
    let pose = trisort_format::NodePose {
        node: door,
        local: turned.to_cols_array(),
    };
    let w0 = world_transforms(&g.nodes, &[]);
    let w1 = world_transforms(&g.nodes, &[pose]);
    let mut used = vec![false; g.vertices.len()];
    for t in &g.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let (mut c0, mut c1, mut n) = (DVec3::ZERO, DVec3::ZERO, 0usize);
    for (v, _) in g
        .vertices
        .iter()
        .zip(&used)
        .filter(|(v, u)| **u && in_door[v.node as usize])
    {
        let p = glam::Vec3::from(v.position).as_dvec3();
        c0 += w0[v.node as usize].transform_point3(p);
        c1 += w1[v.node as usize].transform_point3(p);
        n += 1;
    }
    if n == 0 {
        return None;
    }
    let (c0, c1) = (c0 / n as f64, c1 / n as f64);
    let outward = (c0 - bounds.centre) * DVec3::new(1.0, 0.0, 1.0);
    let outward = outward.try_normalize()?;
    let moved = (c1 - c0).dot(outward);
    Some(DoorGeometry {
        outward,
        opening_sign: if moved >= 0.0 { 1.0 } else { -1.0 },
    })
}
