//! Cameras from eye, target and up; the scene's bounding sphere; default clip planes and the
//! default framing camera; the checks every camera of a timeline passes.

use glam::{DMat4, DVec3};
use trisort_format::{Camera, FrameState};
use trisort_scene::Scene;

use crate::error::Problem;

/// Default vertical field of view of generated cameras and TOML paths: 45°.
pub(crate) const DEFAULT_YFOV_DEGREES: f64 = 45.0;

/// The scene's rest-pose bounding box and its bounding sphere (centre, radius = half the
/// diagonal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Bounds {
    /// Box minimum.
    pub min: DVec3,
    /// Box maximum.
    pub max: DVec3,
    /// Box centre.
    pub centre: DVec3,
    /// Half the box diagonal; 1 for a box of zero size (a scene of one point).
    pub radius: f64,
}

impl Bounds {
    /// Bounds of a box.
    pub(crate) fn from_box(min: DVec3, max: DVec3) -> Self {
        let radius = (max - min).length() * 0.5;
        Bounds {
            min,
            max,
            centre: (min + max) * 0.5,
            radius: if radius > 0.0 { radius } else { 1.0 },
        }
    }

    /// The scene's bounds, or [`Problem::EmptyScene`] for a scene without triangles.
    pub(crate) fn of_scene(scene: &Scene) -> Result<Self, Problem> {
        let (min, max) = scene.bounds().ok_or(Problem::EmptyScene)?;
        if !(min.is_finite() && max.is_finite()) {
            return Err(Problem::NonFinite {
                what: "the scene's bounding box".into(),
            });
        }
        Ok(Bounds::from_box(min, max))
    }

    /// Distance from `p` to the box (0 inside).
    fn distance_to(&self, p: DVec3) -> f64 {
        (self.min - p).max(p - self.max).max(DVec3::ZERO).length()
    }

    /// Distance from `p` to the box's farthest corner.
    fn farthest_corner(&self, p: DVec3) -> f64 {
        (self.min - p).abs().max((self.max - p).abs()).length()
    }
}

/// Clip planes derived from the bounds for a path whose eye positions are `eyes`:
///
/// - `znear` = max(¼ × the smallest eye-to-box distance, 0.002 × radius): the near plane
///   never cuts the rest-pose scene while the eye stays outside the box (¼ leaves room for
///   points up to 75° off the view axis), and stays positive with the eye inside the box;
/// - `zfar` = the largest eye-to-farthest-corner distance + radius (room for animated parts
///   that leave the rest-pose box by up to its radius).
pub(crate) fn default_clip(bounds: &Bounds, eyes: impl IntoIterator<Item = DVec3>) -> (f64, f64) {
    let mut near = f64::INFINITY;
    let mut far: f64 = 0.0;
    for eye in eyes {
        near = near.min(bounds.distance_to(eye));
        far = far.max(bounds.farthest_corner(eye));
    }
    let znear = (0.25 * near).max(0.002 * bounds.radius);
    let zfar = (far + bounds.radius).max(2.0 * znear);
    (znear, zfar)
}

/// The view matrix looking from `eye` at `target` with `up` as the up direction (glam's
/// `look_at_rh`: the camera looks down its −Z), or why there is none: a non-finite input, the
/// eye at the target, or an up vector that is zero or parallel to the view direction.
pub(crate) fn look_at(
    eye: DVec3,
    target: DVec3,
    up: DVec3,
    frame: usize,
) -> Result<DMat4, Problem> {
    for (what, v) in [("eye", eye), ("target", target), ("up", up)] {
        if !v.is_finite() {
            return Err(Problem::NonFinite {
                what: format!("{what} at frame {frame}"),
            });
        }
    }
    let dir = target - eye;
    let scale = eye
        .abs()
        .max_element()
        .max(target.abs().max_element())
        .max(1.0);
    if dir.length() <= 1e-12 * scale {
        return Err(Problem::EyeAtTarget { frame });
    }
    let up_len = up.length();
    if up_len == 0.0 || dir.normalize().cross(up / up_len).length() < 1e-6 {
        return Err(Problem::UpParallel { frame });
    }
    Ok(DMat4::look_at_rh(eye, target, up))
}

/// Checks a field of view given in degrees.
pub(crate) fn check_fov_degrees(degrees: f64) -> Result<(), Problem> {
    if !degrees.is_finite() {
        return Err(Problem::NonFinite {
            what: "yfov".into(),
        });
    }
    if degrees <= 0.0 || degrees >= 180.0 {
        return Err(Problem::FovOutOfRange { degrees });
    }
    Ok(())
}

/// Checks clip planes: 0 < znear < zfar (zfar `None` = infinite), all finite.
pub(crate) fn check_clip(znear: f64, zfar: Option<f64>) -> Result<(), Problem> {
    if !znear.is_finite() {
        return Err(Problem::NonFinite {
            what: "znear".into(),
        });
    }
    if let Some(z) = zfar {
        if !z.is_finite() {
            return Err(Problem::NonFinite {
                what: "zfar".into(),
            });
        }
    }
    if znear <= 0.0 || zfar.is_some_and(|z| z <= znear) {
        return Err(Problem::ClipPlanes { znear, zfar });
    }
    Ok(())
}

/// Checks what every camera of a finished timeline must satisfy: a finite, invertible view,
/// a field of view in (0, π), valid clip planes. Returns the first failing frame's problem.
pub(crate) fn check_frames(frames: &[FrameState]) -> Result<(), Problem> {
    if frames.is_empty() {
        return Err(Problem::ZeroFrames);
    }
    for (f, state) in frames.iter().enumerate() {
        let c = &state.camera;
        if !c.view.iter().all(|x| x.is_finite()) || c.view_matrix().determinant().abs() < 1e-12 {
            return Err(Problem::NonFinite {
                what: format!("the view matrix of frame {f}"),
            });
        }
        check_fov_degrees(c.yfov.to_degrees())?;
        check_clip(c.znear, c.zfar)?;
        for pose in &state.poses {
            if !pose.local.iter().all(|x| x.is_finite()) {
                return Err(Problem::NonFinite {
                    what: format!("the pose of node {} at frame {f}", pose.node),
                });
            }
        }
    }
    Ok(())
}

/// The default camera framing the bounds: it looks at the centre from the front-right-above
/// direction (1, 0.5, 2) (front = +Z, glTF's convention for a model's front), +Y up, at the
/// distance where the bounding sphere fits a 45° field of view with 10 % margin; clip planes
/// per [`default_clip`].
pub(crate) fn framing_camera(bounds: &Bounds) -> Camera {
    let yfov = DEFAULT_YFOV_DEGREES.to_radians();
    let distance = 1.1 * bounds.radius / (0.5 * yfov).sin();
    let eye = bounds.centre + DVec3::new(1.0, 0.5, 2.0).normalize() * distance;
    let view = DMat4::look_at_rh(eye, bounds.centre, DVec3::Y);
    let (znear, zfar) = default_clip(bounds, [eye]);
    Camera {
        view: view.to_cols_array(),
        yfov,
        znear,
        zfar: Some(zfar),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> Bounds {
        Bounds::from_box(DVec3::splat(-1.0), DVec3::splat(1.0))
    }

    #[test]
    fn look_at_rejects_degenerate_views() {
        let e = DVec3::new(0.0, 0.0, 5.0);
        assert!(look_at(e, DVec3::ZERO, DVec3::Y, 0).is_ok());
        assert_eq!(
            look_at(e, e, DVec3::Y, 3),
            Err(Problem::EyeAtTarget { frame: 3 })
        );
        assert_eq!(
            look_at(e, DVec3::ZERO, DVec3::Z, 4),
            Err(Problem::UpParallel { frame: 4 })
        );
        assert_eq!(
            look_at(e, DVec3::ZERO, -DVec3::Z * 3.0, 4),
            Err(Problem::UpParallel { frame: 4 })
        );
        assert_eq!(
            look_at(e, DVec3::ZERO, DVec3::ZERO, 5),
            Err(Problem::UpParallel { frame: 5 })
        );
        assert!(matches!(
            look_at(DVec3::new(f64::NAN, 0.0, 0.0), DVec3::ZERO, DVec3::Y, 0),
            Err(Problem::NonFinite { .. })
        ));
    }

    #[test]
    fn default_clip_contains_the_box() {
        let b = unit_box();
        let eye = DVec3::new(0.0, 0.0, 5.0);
        let (near, far) = default_clip(&b, [eye]);
        assert!((near - 1.0).abs() < 1e-12, "{near}");
        // Farthest corner at distance √(1 + 1 + 36), plus the radius √3.
        assert!((far - (38f64.sqrt() + 3f64.sqrt())).abs() < 1e-12, "{far}");
        // Eye inside the box: a small positive near plane.
        let (near, far) = default_clip(&b, [DVec3::ZERO, eye]);
        assert!((near - 0.002 * 3f64.sqrt()).abs() < 1e-12 && far > near);
    }

    #[test]
    fn framing_camera_sees_the_whole_sphere() {
        let b = unit_box();
        let c = framing_camera(&b);
        let eye = c.eye();
        let d = (eye - b.centre).length();
        assert!((b.radius / d).asin() < c.yfov * 0.5);
        // It looks at the centre: the centre is on the view axis.
        let p = c.view_matrix().transform_point3(b.centre);
        assert!(p.x.abs() < 1e-9 && p.y.abs() < 1e-9 && p.z < 0.0, "{p:?}");
        assert!(check_frames(&[FrameState {
            camera: c,
            poses: vec![]
        }])
        .is_ok());
    }

    #[test]
    fn lens_checks() {
        assert!(check_fov_degrees(45.0).is_ok());
        assert_eq!(
            check_fov_degrees(180.0),
            Err(Problem::FovOutOfRange { degrees: 180.0 })
        );
        assert_eq!(
            check_fov_degrees(0.0),
            Err(Problem::FovOutOfRange { degrees: 0.0 })
        );
        assert!(check_clip(0.1, None).is_ok());
        assert!(check_clip(0.1, Some(0.2)).is_ok());
        assert!(check_clip(0.0, None).is_err());
        assert!(check_clip(0.3, Some(0.3)).is_err());
        assert!(check_clip(f64::NAN, None).is_err());
        assert!(check_frames(&[]).is_err());
    }
}
