//! Shape functions: the body's roof line, underside and superelliptic cross-sections, and the
//! superellipsoids and tori of the other parts.

use std::f64::consts::FRAC_PI_2;

use glam::{DMat4, DVec3};

use super::surface::SurfaceFn;
use super::{
    ARCH_RADIUS, BELT, BODY_BOTTOM, BODY_HALF_WIDTH, FRONT_AXLE_Z, FRONT_CAP, FRONT_FLAT_Z,
    REAR_AXLE_Z, REAR_CAP, REAR_FLAT_Z, ROOF, SECTION_E,
};

/// Signed power: sign(v)·|v|^e (0 near 0, so poles collapse exactly).
fn sp(v: f64, e: f64) -> f64 {
    if v.abs() < 1e-12 {
        0.0
    } else {
        v.signum() * v.abs().powf(e)
    }
}

fn smoothstep(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Height of the top of the body at `z`.
fn roof(z: f64) -> f64 {
    if z <= ROOF[0].0 {
        return ROOF[0].1;
    }
    for w in ROOF.windows(2) {
        let ((z0, y0), (z1, y1)) = (w[0], w[1]);
        if z <= z1 {
            return y0 + (y1 - y0) * smoothstep((z - z0) / (z1 - z0));
        }
    }
    ROOF[ROOF.len() - 1].1
}

/// Height of the underside of the body at `z`: flat, raised in a circular arch over each axle.
fn underside(z: f64) -> f64 {
    let mut y = BODY_BOTTOM;
    for axle in [FRONT_AXLE_Z, REAR_AXLE_Z] {
        let dz = z - axle;
        if dz.abs() < ARCH_RADIUS {
            y = y.max(BODY_BOTTOM + (ARCH_RADIUS * ARCH_RADIUS - dz * dz).sqrt());
        }
    }
    y
}

/// Body station `s` → (z, cap factor): s ∈ [−1, 0] rear cap (s = −1 is the rear tip),
/// [0, 1] the straight middle, [1, 2] front cap (s = 2 is the front tip).
fn station(s: f64) -> (f64, f64) {
    if s < 0.0 {
        let a = (-s).min(1.0) * FRAC_PI_2;
        let c = if s <= -1.0 { 0.0 } else { a.cos() };
        (REAR_FLAT_Z - REAR_CAP * a.sin(), c)
    } else if s <= 1.0 {
        (REAR_FLAT_Z + (FRONT_FLAT_Z - REAR_FLAT_Z) * s, 1.0)
    } else {
        let a = (s - 1.0).min(1.0) * FRAC_PI_2;
        let c = if s >= 2.0 { 0.0 } else { a.cos() };
        (FRONT_FLAT_Z + FRONT_CAP * a.sin(), c)
    }
}

/// The station of a z in the straight middle part.
pub(super) fn station_of_z(z: f64) -> f64 {
    (z - REAR_FLAT_Z) / (FRONT_FLAT_Z - REAR_FLAT_Z)
}

/// A point of the body's outer skin. `theta` goes around the cross-section: 0 is the +X side,
/// π/2 the top, π the −X side, 3π/2 the underside. ∂/∂θ × ∂/∂s points outwards.
pub(super) fn body_point(theta: f64, s: f64) -> DVec3 {
    let (z, c) = station(s);
    let (top, bottom) = (roof(z), underside(z));
    let centre = 0.5 * (top + bottom);
    let half_height = 0.5 * (top - bottom) * c;
    let y = centre + half_height * sp(theta.sin(), SECTION_E);
    let lean = if top > BELT {
        let t = ((y - BELT) / (top - BELT)).clamp(0.0, 1.0);
        1.0 - 0.12 * t * t * smoothstep((top - BELT) / 0.3)
    } else {
        1.0
    };
    let x = BODY_HALF_WIDTH * c * sp(theta.cos(), SECTION_E) * lean;
    DVec3::new(x, y, z)
}

/// Outward unit normal of the body's outer skin (finite differences).
pub(super) fn body_normal(theta: f64, s: f64) -> DVec3 {
    surface_normal(&body_point, theta, s)
}

/// Unit normal ∂f/∂u × ∂f/∂v by central differences, or zero where it vanishes (a pole).
pub(super) fn surface_normal(f: &dyn Fn(f64, f64) -> DVec3, u: f64, v: f64) -> DVec3 {
    const H: f64 = 1e-6;
    let du = f(u + H, v) - f(u - H, v);
    let dv = f(u, v + H) - f(u, v - H);
    du.cross(dv).normalize_or_zero()
}

/// The angle θ at which the cabin cross-section (the one at z = 0) reaches height `y` on the
/// +X side.
pub(super) fn theta_at_height(y: f64) -> f64 {
    let (top, bottom) = (roof(0.0), underside(0.0));
    let w = (y - 0.5 * (top + bottom)) / (0.5 * (top - bottom));
    sp(w, 1.0 / SECTION_E).asin()
}

/// The angle θ (in (0, π/2)) where the top of a cross-section reaches `fraction` of the half
/// width, ignoring the tumblehome.
pub(super) fn theta_at_width(fraction: f64) -> f64 {
    sp(fraction, 1.0 / SECTION_E).acos()
}

/// A superellipsoid with semi-axes `radii` (poles along local ±Y), exponents `e_lat`
/// (latitude) and `e_lon` (longitude), placed by `xform` (rotation and translation only).
/// Parameters: u = longitude in [0, 2π), v = latitude in [−π/2, π/2]; ∂/∂u × ∂/∂v points out.
pub(super) fn superellipsoid(radii: DVec3, e_lat: f64, e_lon: f64, xform: DMat4) -> SurfaceFn {
    Box::new(move |u, v| {
        let (cv, sv) = (sp(v.cos(), e_lat), sp(v.sin(), e_lat));
        let (cu, su) = (sp(u.cos(), e_lon), sp(u.sin(), e_lon));
        xform.transform_point3(DVec3::new(
            radii.x * cv * cu,
            radii.y * sv,
            -radii.z * cv * su,
        ))
    })
}

/// A torus around the local X axis: tube centre radius `major`, tube semi-axes `radial` and
/// `axial`, tube exponent `e`, placed by `xform`. Parameters: u = angle around the axis,
/// v = angle around the tube (both in [0, 2π)); ∂/∂u × ∂/∂v points out.
pub(super) fn torus(major: f64, radial: f64, axial: f64, e: f64, xform: DMat4) -> SurfaceFn {
    Box::new(move |u, v| {
        let ring = major + radial * sp(v.cos(), e);
        xform.transform_point3(DVec3::new(
            axial * sp(v.sin(), e),
            ring * u.cos(),
            ring * u.sin(),
        ))
    })
}
