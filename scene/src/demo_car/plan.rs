//! The plan: every part of the car, where it sits and how finely it is sampled.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::{DMat4, DQuat, DVec3};

use super::shapes::{
    body_point, station_of_z, superellipsoid, theta_at_height, theta_at_width, torus,
};
use super::surface::{
    body_patch, closed_part, curve_length, param_gap, subdivide, Kind, Placement, Surface, Uv,
};
use super::{
    BELT, DASHBOARD, DOOR_NODE_INDEX, DOOR_WINDOW_NODE_INDEX, DOOR_Z, FIRST_WHEEL_NODE, GLASS,
    PAINT, PLATE, REAR_SIDE_Z, REAR_WINDOW_Z, RIM, ROOT_NODE, SCREEN_WIDTH_FRACTION, SEAT, SHELL,
    SILL, STEERING, TYRE, WHEELS, WINDOW_TOP, WINDSCREEN_Z,
};

/// θ values of the openings.
pub(super) struct Openings {
    belt: f64,
    window_top: f64,
    screen: f64,
    sill: f64,
}

impl Openings {
    pub(super) fn new() -> Openings {
        Openings {
            belt: theta_at_height(BELT),
            window_top: theta_at_height(WINDOW_TOP),
            screen: theta_at_width(SCREEN_WIDTH_FRACTION),
            sill: theta_at_height(SILL),
        }
    }
}

/// The door's θ range, station range and hinge point.
pub(super) fn door_frame(o: &Openings) -> ((f64, f64), (f64, f64), DVec3) {
    let u = (PI - o.window_top, PI - o.sill);
    let v = (station_of_z(DOOR_Z.0), station_of_z(DOOR_Z.1));
    // The door's front edge after its gap; the hinge is its outermost point (smallest x), at
    // mid height.
    let f = |t: f64, s: f64| body_point(t, s);
    let front = v.1 - param_gap(&f, (PI - o.belt, u.1), v, false);
    let (mut hinge_x, mut hinge_z) = (f64::INFINITY, 0.0);
    for k in 0..=256 {
        let p = body_point(u.0 + (u.1 - u.0) * k as f64 / 256.0, front);
        if p.x < hinge_x {
            hinge_x = p.x;
            hinge_z = p.z;
        }
    }
    let mid_y = body_point(PI - o.belt, front).y;
    (u, v, DVec3::new(hinge_x - 1e-4, mid_y, hinge_z))
}

/// An opening in the body: its θ range and its z range.
type Opening = ((f64, f64), (f64, f64));

/// Every part of the car at tessellation density `r` (segments per metre), in part order:
/// body, fixed glass panes, door and its window, wheels, interior, licence plates.
pub(super) fn plan(r: f64) -> Vec<Surface> {
    let o = Openings::new();
    let openings = openings(&o);
    let mut parts = vec![body(&o, &openings, r)];

    // Glass panes in the fixed openings (all but the door's).
    for ((t0, t1), (z0, z1)) in &openings[..5] {
        parts.push(body_patch(
            (*t0, *t1),
            (station_of_z(*z0), station_of_z(*z1)),
            [true; 4],
            Kind::Sheet,
            r,
            Placement {
                material: GLASS,
                node: ROOT_NODE,
                origin: DVec3::ZERO,
            },
        ));
    }
    door(&o, r, &mut parts);
    wheels(r, &mut parts);
    seats_and_dashboard(r, &mut parts);
    steering_wheel(r, &mut parts);
    licence_plates(r, &mut parts);
    parts
}

/// The openings of the body: windscreen, rear window, the side windows on the +X side, then
/// the rear side window and the driver door on the −X side (the door's opening last).
fn openings(o: &Openings) -> [Opening; 6] {
    [
        ((o.screen, PI - o.screen), WINDSCREEN_Z),
        ((o.screen, PI - o.screen), REAR_WINDOW_Z),
        ((o.belt, o.window_top), DOOR_Z),
        ((o.belt, o.window_top), REAR_SIDE_Z),
        ((PI - o.window_top, PI - o.belt), REAR_SIDE_Z),
        ((PI - o.window_top, PI - o.sill), DOOR_Z),
    ]
}

/// The body: a thick shell with `openings` cut out of it.
fn body(o: &Openings, openings: &[Opening], r: f64) -> Surface {
    let theta_breaks = [
        0.0,
        o.belt,
        o.window_top,
        o.screen,
        PI - o.screen,
        PI - o.window_top,
        PI - o.belt,
        PI,
        PI - o.sill,
        TAU + o.sill,
        TAU,
    ];
    let mut z_breaks = vec![
        -1.74, -1.30, -1.15, -1.05, -0.86, -0.80, -0.62, -0.55, -0.47, -0.35, 0.30, 0.38, 0.62,
        0.91, 0.98, 1.05, 1.35, 1.79,
    ];
    z_breaks.sort_by(f64::total_cmp);
    let mut s_breaks = vec![-1.0, 0.0];
    s_breaks.extend(z_breaks.iter().map(|&z| station_of_z(z)));
    s_breaks.extend([1.0, 2.0]);
    let (mut us, u_at) = subdivide(&theta_breaks, r, 1, |a, b| {
        curve_length(|t| body_point(t, station_of_z(0.0)), a, b)
    });
    us.pop();
    let (vs, v_at) = subdivide(&s_breaks, r, 1, |a, b| {
        [0.0, FRAC_PI_2, 1.5 * PI]
            .iter()
            .map(|&t| curve_length(|s| body_point(t, s), a, b))
            .fold(0.0, f64::max)
    });
    let cells_u = us.len();
    let mut keep = vec![true; cells_u * (vs.len() - 1)];
    let col = |theta: f64| u_at[theta_breaks.iter().position(|&t| t == theta).unwrap()];
    let row = |z: f64| {
        let s = station_of_z(z);
        v_at[s_breaks.iter().position(|&b| b == s).unwrap()]
    };
    for &((t0, t1), (z0, z1)) in openings {
        for j in row(z0)..row(z1) {
            for i in col(t0)..col(t1) {
                keep[i + j * cells_u] = false;
            }
        }
    }
    Surface {
        f: Box::new(body_point),
        us,
        vs,
        wrap_u: true,
        wrap_v: false,
        pole_lo: true,
        pole_hi: true,
        keep: Some(keep),
        kind: Kind::Shell(SHELL),
        material: PAINT,
        node: ROOT_NODE,
        origin: DVec3::ZERO,
        uv: Uv::None,
    }
}

/// The driver door and its window, in the door's local space (origin at the hinge).
fn door(o: &Openings, r: f64, parts: &mut Vec<Surface>) {
    let (du, dv, hinge) = door_frame(o);
    parts.push(body_patch(
        (PI - o.belt, du.1),
        dv,
        [false, true, true, true],
        Kind::Shell(SHELL),
        r,
        Placement {
            material: PAINT,
            node: DOOR_NODE_INDEX,
            origin: hinge,
        },
    ));
    parts.push(body_patch(
        (du.0, PI - o.belt),
        dv,
        [true; 4],
        Kind::Sheet,
        r,
        Placement {
            material: GLASS,
            node: DOOR_WINDOW_NODE_INDEX,
            origin: hinge,
        },
    ));
}

/// Wheels (tyre and rim each), in wheel-local space (axle along X).
fn wheels(r: f64, parts: &mut Vec<Surface>) {
    for k in 0..WHEELS.len() {
        let node = FIRST_WHEEL_NODE + k as u32;
        parts.push(closed_part(
            torus(0.25, 0.08, 0.11, 0.5, DMat4::IDENTITY),
            true,
            r,
            TYRE,
            node,
            Uv::None,
        ));
        let axle_x = DMat4::from_rotation_z(-FRAC_PI_2);
        parts.push(closed_part(
            superellipsoid(DVec3::new(0.16, 0.075, 0.16), 0.2, 1.0, axle_x),
            false,
            r,
            RIM,
            node,
            Uv::None,
        ));
    }
}

/// The interior except the steering wheel: two seats (cushion and backrest) and the
/// dashboard.
fn seats_and_dashboard(r: f64, parts: &mut Vec<Surface>) {
    for x in [-0.40, 0.40] {
        parts.push(closed_part(
            superellipsoid(
                DVec3::new(0.24, 0.07, 0.25),
                0.35,
                0.35,
                DMat4::from_translation(DVec3::new(x, 0.50, -0.14)),
            ),
            false,
            r,
            SEAT,
            ROOT_NODE,
            Uv::None,
        ));
        parts.push(closed_part(
            superellipsoid(
                DVec3::new(0.23, 0.30, 0.07),
                0.35,
                0.35,
                DMat4::from_translation(DVec3::new(x, 0.93, -0.50))
                    * DMat4::from_rotation_x(-12f64.to_radians()),
            ),
            false,
            r,
            SEAT,
            ROOT_NODE,
            Uv::None,
        ));
    }
    parts.push(closed_part(
        superellipsoid(
            DVec3::new(0.62, 0.10, 0.14),
            0.3,
            0.3,
            DMat4::from_translation(DVec3::new(0.0, 0.80, 0.78)),
        ),
        false,
        r,
        DASHBOARD,
        ROOT_NODE,
        Uv::None,
    ));
}

/// The steering wheel: rim, hub and column, on the steering axis in front of the driver.
fn steering_wheel(r: f64, parts: &mut Vec<Surface>) {
    let wheel_centre = DVec3::new(-0.40, 0.95, 0.42);
    // The steering axis points from the dashboard towards the driver, tilted 25° up.
    let axis = DVec3::new(0.0, 25f64.to_radians().sin(), -25f64.to_radians().cos());
    let towards_axis = |d: DVec3| DQuat::from_rotation_arc(d, axis);
    parts.push(closed_part(
        torus(
            0.17,
            0.018,
            0.018,
            1.0,
            DMat4::from_rotation_translation(towards_axis(DVec3::X), wheel_centre),
        ),
        true,
        r,
        STEERING,
        ROOT_NODE,
        Uv::None,
    ));
    parts.push(closed_part(
        superellipsoid(
            DVec3::new(0.055, 0.015, 0.055),
            0.3,
            1.0,
            DMat4::from_rotation_translation(towards_axis(DVec3::Y), wheel_centre),
        ),
        false,
        r,
        STEERING,
        ROOT_NODE,
        Uv::None,
    ));
    let (column_start, column_end) = (0.035, 0.20);
    parts.push(closed_part(
        superellipsoid(
            DVec3::new(0.022, 0.5 * (column_end - column_start), 0.022),
            0.2,
            1.0,
            DMat4::from_rotation_translation(
                towards_axis(DVec3::Y),
                wheel_centre - axis * 0.5 * (column_start + column_end),
            ),
        ),
        false,
        r,
        STEERING,
        ROOT_NODE,
        Uv::None,
    ));
}

/// Licence plates, textured on the face pointing away from the car.
fn licence_plates(r: f64, parts: &mut Vec<Surface>) {
    let (plate_w, plate_h) = (0.26, 0.06);
    for (z, facing) in [(-2.125, -1.0), (2.125, 1.0)] {
        let tip = if facing > 0.0 { 2.0 } else { -1.0 };
        let centre = DVec3::new(0.0, body_point(0.0, tip).y, z);
        parts.push(closed_part(
            superellipsoid(
                DVec3::new(plate_w, plate_h, 0.008),
                0.15,
                0.15,
                DMat4::from_translation(centre),
            ),
            false,
            r,
            PLATE,
            ROOT_NODE,
            Uv::Planar {
                // Left to right as seen from outside; rows top to bottom.
                origin: centre + DVec3::new(-facing * plate_w, plate_h, 0.0),
                u_axis: DVec3::new(facing / (2.0 * plate_w), 0.0, 0.0),
                v_axis: DVec3::new(0.0, -1.0 / (2.0 * plate_h), 0.0),
            },
        ));
    }
}
