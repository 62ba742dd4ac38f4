//! The `gltf` path: the scene's own node animations and first camera (or the animation and
//! camera `gltf:animation=NAME,camera=NAME` names), sampled at a fixed rate (glTF 2.0 § 3.11
//! "Animations" and Appendix C "Animation Sampler Interpolation Modes").

use glam::{DMat4, DQuat, DVec3, DVec4};
use trisort_format::{world_transforms, Camera, FrameState};
use trisort_scene::{Channel, Interpolation, Property, Scene, SceneCamera};

use crate::error::{Location, PathError, Problem};
use crate::keyframes::MAX_FRAMES;
use crate::poses::pose_if_moved;
use crate::view::{check_clip, check_fov_degrees, check_frames, framing_camera, Bounds};
use crate::Timeline;

/// What `gltf:animation=NAME,camera=NAME` chooses (`None`: every animation, the first
/// camera).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct Selection {
    /// Only the animations of this name play.
    pub animation: Option<String>,
    /// The camera of this name.
    pub camera: Option<String>,
}

/// Parses the parameters of `gltf:…` (after the colon).
pub(crate) fn parse_selection(params: &str) -> Result<Selection, Problem> {
    let mut out = Selection::default();
    for (k, v) in crate::generators::pairs(params, &["animation", "camera"])? {
        if v.is_empty() {
            return Err(Problem::BadParameter {
                name: k.into(),
                reason: "empty name".into(),
            });
        }
        match k {
            "animation" => out.animation = Some(v.into()),
            _ => out.camera = Some(v.into()),
        }
    }
    Ok(out)
}

/// `name` (or `#index` for an unnamed one) of each item, for messages.
fn listed<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let all: Vec<String> = names
        .enumerate()
        .map(|(i, n)| {
            if n.is_empty() {
                format!("#{i} (unnamed)")
            } else {
                format!("{n:?}")
            }
        })
        .collect();
    if all.is_empty() {
        "none".into()
    } else {
        all.join(", ")
    }
}

/// Samples the scene's animations and camera (those `select` names) at `fps`.
pub(crate) fn sample(scene: &Scene, fps: f64, select: &Selection) -> Result<Timeline, PathError> {
    // The spec is named where it selects something (it is at fault when that is missing).
    let at = || match (&select.animation, &select.camera) {
        (None, None) => Location::whole(format!("gltf path of scene {:?}", scene.name)),
        (animation, camera) => {
            let mut spec = String::from("gltf:");
            let parts: Vec<String> = [("animation", animation), ("camera", camera)]
                .into_iter()
                .filter_map(|(k, v)| v.as_ref().map(|v| format!("{k}={v}")))
                .collect();
            spec.push_str(&parts.join(","));
            Location::whole(format!("{spec} (gltf path of scene {:?})", scene.name))
        }
    };
    let err = |problem| PathError::Invalid { at: at(), problem };
    check_fps(fps).map_err(err)?;
    let nodes = &scene.geometry.nodes;
    let (animated, duration) = animated_nodes(scene, select, &err)?;

    let frame_count = if animated.is_empty() {
        1
    } else {
        let last = duration * fps;
        if !last.is_finite() || last >= MAX_FRAMES as f64 {
            return Err(err(Problem::Inconsistent(format!(
                "{duration} s at {fps} fps is more than {MAX_FRAMES} frames"
            ))));
        }
        (last + 1e-9).floor() as usize + 1
    };

    let scene_camera = chosen_camera(scene, select, &err)?;
    let fixed_camera = match scene_camera {
        Some(_) => None,
        None => Some(framing_camera(&Bounds::of_scene(scene).map_err(err)?)),
    };

    let rest_trs: Vec<(DVec3, DQuat, DVec3)> = animated
        .iter()
        .map(|(n, _)| {
            // A rest transform with a zero scale has no rotation to recover: use identity.
            let (s, r, t) =
                DMat4::from_cols_array(&nodes[*n as usize].rest).to_scale_rotation_translation();
            (s, if r.is_finite() { r } else { DQuat::IDENTITY }, t)
        })
        .collect();
    let mut frames = Vec::with_capacity(frame_count);
    for f in 0..frame_count {
        let t = f as f64 / fps;
        let mut poses = Vec::new();
        for ((node, channels), &(rest_s, rest_r, rest_t)) in animated.iter().zip(&rest_trs) {
            let [tr, rot, sc] = channels;
            let translation = tr.map_or(rest_t, |c| DVec3::from_slice(&sample_channel(c, t)));
            let rotation = rot.map_or(rest_r, |c| {
                let q = sample_channel(c, t);
                DQuat::from_xyzw(q[0], q[1], q[2], q[3]).normalize()
            });
            let scale = sc.map_or(rest_s, |c| DVec3::from_slice(&sample_channel(c, t)));
            let local = DMat4::from_scale_rotation_translation(scale, rotation, translation);
            poses.extend(pose_if_moved(*node, &nodes[*node as usize].rest, local));
        }
        let camera = match (scene_camera, fixed_camera) {
            (_, Some(c)) => c,
            (Some(c), None) => {
                let world = world_transforms(nodes, &poses)[c.node as usize];
                let (_, r, p) = world.to_scale_rotation_translation();
                let view = DMat4::from_rotation_translation(r.normalize(), p).inverse();
                Camera {
                    view: view.to_cols_array(),
                    yfov: c.yfov,
                    znear: c.znear,
                    zfar: c.zfar,
                }
            }
            (None, None) => unreachable!("either the scene's camera or the framing camera"),
        };
        frames.push(FrameState { camera, poses });
    }
    check_frames(&frames).map_err(err)?;
    Ok(Timeline { fps, frames })
}

/// The channels that drive a node's translation, rotation and scale (`None`: its rest value).
type Drivers<'s> = [Option<&'s Channel>; 3];

/// The animated nodes of the animations `select` plays, each with the channel that drives
/// its translation, rotation and scale (later animations and channels override earlier ones),
/// and the longest channel's duration in seconds. Errors (through `err`) where `select` names
/// an animation the scene lacks or a channel is malformed.
fn animated_nodes<'s>(
    scene: &'s Scene,
    select: &Selection,
    err: &dyn Fn(Problem) -> PathError,
) -> Result<(Vec<(u32, Drivers<'s>)>, f64), PathError> {
    let nodes = &scene.geometry.nodes;
    let plays = |name: &str| {
        select
            .animation
            .as_deref()
            .is_none_or(|wanted| wanted == name)
    };
    if let Some(wanted) = &select.animation {
        if !scene.animations.iter().any(|a| a.name == *wanted) {
            return Err(err(Problem::BadParameter {
                name: "animation".into(),
                reason: format!(
                    "the scene has no animation named {wanted:?} (its animations: {})",
                    listed(scene.animations.iter().map(|a| a.name.as_str()))
                ),
            }));
        }
    }

    // The channel that drives each (node, property); later animations and channels override
    // earlier ones.
    let mut driver: Vec<[Option<&Channel>; 3]> = vec![[None; 3]; nodes.len()];
    let mut duration: f64 = 0.0;
    for (a, anim) in scene.animations.iter().enumerate() {
        if !plays(&anim.name) {
            continue;
        }
        for (c, ch) in anim.channels.iter().enumerate() {
            check_channel(ch, nodes.len()).map_err(|reason| {
                err(Problem::Inconsistent(format!(
                    "animation {a} ({:?}) channel {c}: {reason}",
                    anim.name
                )))
            })?;
            driver[ch.node as usize][property_slot(ch.property)] = Some(ch);
            duration = duration.max(*ch.times.last().expect("checked non-empty") as f64);
        }
    }
    let animated = driver
        .into_iter()
        .enumerate()
        .filter(|(_, d)| d.iter().any(Option::is_some))
        .map(|(n, d)| (n as u32, d))
        .collect();
    Ok((animated, duration))
}

/// The scene camera `select` names (by default the first, `None` where the scene has none),
/// checked: on an existing node, with a valid field of view and clip range. Errors go
/// through `err`.
fn chosen_camera<'s>(
    scene: &'s Scene,
    select: &Selection,
    err: &dyn Fn(Problem) -> PathError,
) -> Result<Option<&'s SceneCamera>, PathError> {
    let scene_camera = match &select.camera {
        None => scene.cameras.first(),
        Some(wanted) => Some(
            (scene.cameras.iter())
                .find(|c| c.name == *wanted)
                .ok_or_else(|| {
                    err(Problem::BadParameter {
                        name: "camera".into(),
                        reason: format!(
                            "the scene has no camera named {wanted:?} (its cameras: {})",
                            listed(scene.cameras.iter().map(|c| c.name.as_str()))
                        ),
                    })
                })?,
        ),
    };
    if let Some(c) = scene_camera {
        if c.node as usize >= scene.geometry.nodes.len() {
            return Err(err(Problem::Inconsistent(format!(
                "camera {:?} is on node {}, which does not exist",
                c.name, c.node
            ))));
        }
        check_fov_degrees(c.yfov.to_degrees()).map_err(err)?;
        check_clip(c.znear, c.zfar).map_err(err)?;
    }
    Ok(scene_camera)
}

/// Checks a sampling rate.
pub(crate) fn check_fps(fps: f64) -> Result<(), Problem> {
    if !fps.is_finite() {
        return Err(Problem::NonFinite { what: "fps".into() });
    }
    if fps <= 0.0 {
        return Err(Problem::BadParameter {
            name: "fps".into(),
            reason: format!("must be positive, not {fps}"),
        });
    }
    Ok(())
}

fn property_slot(p: Property) -> usize {
    match p {
        Property::Translation => 0,
        Property::Rotation => 1,
        Property::Scale => 2,
    }
}

fn components(p: Property) -> usize {
    match p {
        Property::Rotation => 4,
        Property::Translation | Property::Scale => 3,
    }
}

/// Why a channel cannot be sampled, if it cannot: a missing node, no keys, times that are not
/// finite and ascending, the wrong number of values, non-finite values.
fn check_channel(ch: &Channel, node_count: usize) -> Result<(), String> {
    if ch.node as usize >= node_count {
        return Err(format!("targets node {}, which does not exist", ch.node));
    }
    if ch.times.is_empty() {
        return Err("has no keys".into());
    }
    if !ch.times.iter().all(|t| t.is_finite() && *t >= 0.0) {
        return Err("has a key time that is negative or not finite".into());
    }
    if ch.times.windows(2).any(|w| w[1] < w[0]) {
        return Err("key times are not ascending".into());
    }
    let per_key = components(ch.property)
        * if ch.interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
    if ch.values.len() != ch.times.len() * per_key {
        return Err(format!(
            "has {} values for {} keys ({per_key} per key expected)",
            ch.values.len(),
            ch.times.len()
        ));
    }
    if !ch.values.iter().all(|v| v.is_finite()) {
        return Err("has a value that is not finite".into());
    }
    Ok(())
}

/// The channel's value at time `t` (seconds), 3 or 4 components (rotations not yet
/// normalized). Before the first key it holds the first value, after the last the last.
/// Requires a channel that passed [`check_channel`].
fn sample_channel(ch: &Channel, t: f64) -> Vec<f64> {
    let c = components(ch.property);
    let cubic = ch.interpolation == Interpolation::CubicSpline;
    let stride = if cubic { 3 * c } else { c };
    // Value of key k (for cubic splines the middle of in-tangent, value, out-tangent).
    let value = |k: usize| -> Vec<f64> {
        let start = k * stride + if cubic { c } else { 0 };
        ch.values[start..start + c]
            .iter()
            .map(|&v| v as f64)
            .collect()
    };
    let times = &ch.times;
    let n = times.len();
    if t <= times[0] as f64 {
        return value(0);
    }
    if t >= times[n - 1] as f64 {
        return value(n - 1);
    }
    let k = times.partition_point(|&tk| tk as f64 <= t) - 1;
    let (t0, t1) = (times[k] as f64, times[k + 1] as f64);
    let dt = t1 - t0;
    let s = (t - t0) / dt;
    match ch.interpolation {
        Interpolation::Step => value(k),
        Interpolation::Linear => {
            let (a, b) = (value(k), value(k + 1));
            if ch.property == Property::Rotation {
                let qa = DQuat::from_vec4(DVec4::from_slice(&a)).normalize();
                let qb = DQuat::from_vec4(DVec4::from_slice(&b)).normalize();
                let q = slerp(qa, qb, s);
                vec![q.x, q.y, q.z, q.w]
            } else {
                a.iter()
                    .zip(&b)
                    .map(|(a, b)| (1.0 - s) * a + s * b)
                    .collect()
            }
        }
        Interpolation::CubicSpline => {
            // p(s) = (2s³−3s²+1)·v_k + Δt(s³−2s²+s)·b_k + (−2s³+3s²)·v_{k+1} + Δt(s³−s²)·a_{k+1}
            // with b_k the out-tangent of key k and a_{k+1} the in-tangent of key k+1.
            let (s2, s3) = (s * s, s * s * s);
            let v0 = value(k);
            let v1 = value(k + 1);
            let out0 = &ch.values[k * stride + 2 * c..k * stride + 3 * c];
            let in1 = &ch.values[(k + 1) * stride..(k + 1) * stride + c];
            (0..c)
                .map(|i| {
                    (2.0 * s3 - 3.0 * s2 + 1.0) * v0[i]
                        + dt * (s3 - 2.0 * s2 + s) * out0[i] as f64
                        + (-2.0 * s3 + 3.0 * s2) * v1[i]
                        + dt * (s3 - s2) * in1[i] as f64
                })
                .collect()
        }
    }
}

/// Spherical linear interpolation along the shorter arc (glTF Appendix C), falling back to a
/// normalized lerp when the quaternions are nearly equal.
fn slerp(a: DQuat, b: DQuat, s: f64) -> DQuat {
    let mut d = a.dot(b);
    let b = if d < 0.0 {
        d = -d;
        -b
    } else {
        b
    };
    if d > 1.0 - 1e-9 {
        return DQuat::from_vec4(DVec4::from(a) * (1.0 - s) + DVec4::from(b) * s).normalize();
    }
    let theta = d.acos();
    let sin = theta.sin();
    let wa = ((1.0 - s) * theta).sin() / sin;
    let wb = (s * theta).sin() / sin;
    DQuat::from_vec4(DVec4::from(a) * wa + DVec4::from(b) * wb)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(
        property: Property,
        interpolation: Interpolation,
        times: &[f32],
        values: &[f32],
    ) -> Channel {
        Channel {
            node: 0,
            property,
            interpolation,
            times: times.to_vec(),
            values: values.to_vec(),
        }
    }

    #[test]
    fn linear_step_and_clamping() {
        let ch = channel(
            Property::Translation,
            Interpolation::Linear,
            &[1.0, 3.0],
            &[0.0, 0.0, 0.0, 4.0, -2.0, 1.0],
        );
        assert_eq!(sample_channel(&ch, 0.0), vec![0.0, 0.0, 0.0]);
        assert_eq!(sample_channel(&ch, 2.0), vec![2.0, -1.0, 0.5]);
        assert_eq!(sample_channel(&ch, 9.0), vec![4.0, -2.0, 1.0]);
        let step = Channel {
            interpolation: Interpolation::Step,
            ..ch
        };
        assert_eq!(sample_channel(&step, 2.9), vec![0.0, 0.0, 0.0]);
        assert_eq!(sample_channel(&step, 3.0), vec![4.0, -2.0, 1.0]);
    }

    #[test]
    fn slerp_takes_the_short_arc_at_constant_speed() {
        let a = DQuat::IDENTITY;
        let b = DQuat::from_rotation_y(170f64.to_radians());
        let close = |q: DQuat, e: DQuat| (q - e).length().min((q + e).length()) < 1e-12;
        let q = slerp(a, b, 0.5);
        assert!(
            close(q, DQuat::from_rotation_y(85f64.to_radians())),
            "{q:?}"
        );
        // −b is the same rotation; slerp must still go the short way.
        let q = slerp(a, -b, 0.25);
        assert!(
            close(q, DQuat::from_rotation_y(42.5f64.to_radians())),
            "{q:?}"
        );
        let q = slerp(a, a, 0.3);
        assert!(close(q, a), "{q:?}");
    }

    #[test]
    fn linear_rotation_channel_slerps() {
        let b = DQuat::from_rotation_x(120f64.to_radians());
        let ch = channel(
            Property::Rotation,
            Interpolation::Linear,
            &[0.0, 1.0],
            &[
                0.0, 0.0, 0.0, 1.0, b.x as f32, b.y as f32, b.z as f32, b.w as f32,
            ],
        );
        let v = sample_channel(&ch, 0.25);
        let q = DQuat::from_xyzw(v[0], v[1], v[2], v[3]);
        assert!((q.length() - 1.0).abs() < 1e-6);
        assert!(q.angle_between(DQuat::from_rotation_x(30f64.to_radians())) < 1e-6);
    }

    #[test]
    fn cubic_spline_is_hermite_with_scaled_tangents() {
        // One component of a translation: keys at t = 0 (value 0, out-tangent 3) and t = 2
        // (in-tangent 1, value 4). Tangents are per second, scaled by the 2 s interval.
        let values = [
            0.0, 0.0, 0.0, /* in */ 0.0, 0.0, 0.0, /* value */ 3.0, 0.0,
            0.0, /* out */
            1.0, 0.0, 0.0, /* in */ 4.0, 0.0, 0.0, /* value */ 0.0, 0.0,
            0.0, /* out */
        ];
        let ch = channel(
            Property::Translation,
            Interpolation::CubicSpline,
            &[0.0, 2.0],
            &values,
        );
        assert_eq!(sample_channel(&ch, 0.0)[0], 0.0);
        assert_eq!(sample_channel(&ch, 2.0)[0], 4.0);
        // s = 0.5: h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = −0.125.
        let expected = 0.5 * 0.0 + 2.0 * 0.125 * 3.0 + 0.5 * 4.0 - 2.0 * 0.125 * 1.0;
        assert!((sample_channel(&ch, 1.0)[0] - expected).abs() < 1e-12);
        // The derivative at the start is the out-tangent.
        let h = 1e-6;
        let d = (sample_channel(&ch, h)[0] - sample_channel(&ch, 0.0)[0]) / h;
        assert!((d - 3.0).abs() < 1e-4, "{d}");
    }

    #[test]
    fn malformed_channels_are_rejected() {
        let good = channel(
            Property::Scale,
            Interpolation::Linear,
            &[0.0],
            &[1.0, 1.0, 1.0],
        );
        assert!(check_channel(&good, 1).is_ok());
        assert!(check_channel(&good, 0).is_err());
        let short = channel(
            Property::Rotation,
            Interpolation::Linear,
            &[0.0],
            &[1.0, 1.0, 1.0],
        );
        assert!(check_channel(&short, 1).is_err());
        let cubic = channel(
            Property::Scale,
            Interpolation::CubicSpline,
            &[0.0],
            &[1.0, 1.0, 1.0],
        );
        assert!(check_channel(&cubic, 1).is_err());
        let back = channel(Property::Scale, Interpolation::Step, &[1.0, 0.0], &[1.0; 6]);
        assert!(check_channel(&back, 1).is_err());
        let nan = channel(Property::Scale, Interpolation::Step, &[f32::NAN], &[1.0; 3]);
        assert!(check_channel(&nan, 1).is_err());
        let none = channel(Property::Scale, Interpolation::Step, &[], &[]);
        assert!(check_channel(&none, 1).is_err());
    }
}
