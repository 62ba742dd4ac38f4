//! The surface kit: parametric parts, how they are sampled (densities, breaks, gaps) and how
//! many triangles they give.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::DVec3;

use super::shapes::{body_normal, body_point};
use super::{GAP, SHELL};

/// A parametric surface: (u, v) ↦ point (less [`Surface::origin`], in its node's space).
pub(super) type SurfaceFn = Box<dyn Fn(f64, f64) -> DVec3>;

/// How a parametric surface becomes triangles.
pub(super) enum Kind {
    /// One closed surface (wrapped in u, poles or wrap in v).
    Closed,
    /// A solid shell: the surface, a copy moved `thickness` against its normal with reversed
    /// winding, and rims closing every boundary between them.
    Shell(f64),
    /// One open sheet (glass).
    Sheet,
}

/// Texture coordinates of a part.
pub(super) enum Uv {
    /// None (untextured material).
    None,
    /// Planar: uv = ((p − origin)·u_axis, (p − origin)·v_axis), axes pre-scaled.
    Planar {
        origin: DVec3,
        u_axis: DVec3,
        v_axis: DVec3,
    },
}

/// One part: a tessellated parametric surface.
pub(super) struct Surface {
    pub(super) f: SurfaceFn,
    /// Parameter samples along u (without the repeated end when `wrap_u`).
    pub(super) us: Vec<f64>,
    /// Parameter samples along v (with the repeated end when `wrap_v`: its row is the first).
    pub(super) vs: Vec<f64>,
    pub(super) wrap_u: bool,
    pub(super) wrap_v: bool,
    /// The first / last row of samples collapses to one point.
    pub(super) pole_lo: bool,
    pub(super) pole_hi: bool,
    /// Cells kept (index i + j·cells_u); `None` keeps all.
    pub(super) keep: Option<Vec<bool>>,
    pub(super) kind: Kind,
    pub(super) material: u32,
    pub(super) node: u32,
    /// Origin of the node's local space, in car coordinates.
    pub(super) origin: DVec3,
    pub(super) uv: Uv,
}

impl Surface {
    pub(super) fn cells_u(&self) -> usize {
        if self.wrap_u {
            self.us.len()
        } else {
            self.us.len() - 1
        }
    }

    pub(super) fn cells_v(&self) -> usize {
        self.vs.len() - 1
    }

    pub(super) fn kept(&self, i: isize, j: isize) -> bool {
        let (cu, cv) = (self.cells_u() as isize, self.cells_v() as isize);
        if j < 0 || j >= cv {
            return false;
        }
        let i = if self.wrap_u {
            i.rem_euclid(cu)
        } else if i < 0 || i >= cu {
            return false;
        } else {
            i
        };
        self.keep
            .as_ref()
            .is_none_or(|k| k[i as usize + j as usize * cu as usize])
    }

    fn pole_row(&self, j: usize) -> bool {
        (self.pole_lo && j == 0) || (self.pole_hi && j + 1 == self.cells_v())
    }

    /// Boundary edges of a kept cell, as (corner, corner) index pairs into [a, b, c, d]
    /// (counter-clockwise seen from outside): edges whose neighbour cell is not kept.
    pub(super) fn boundary_edges(
        &self,
        i: usize,
        j: usize,
    ) -> impl Iterator<Item = (usize, usize)> + '_ {
        let (i, j) = (i as isize, j as isize);
        let neighbours = [(i, j - 1), (i + 1, j), (i, j + 1), (i - 1, j)];
        (0..4).filter_map(move |k| {
            let (ni, nj) = neighbours[k];
            let degenerate = (k == 0 && self.pole_lo && j == 0)
                || (k == 2 && self.pole_hi && j + 1 == self.cells_v() as isize);
            (!degenerate && !self.kept(ni, nj)).then_some((k, (k + 1) % 4))
        })
    }

    pub(super) fn triangle_count(&self) -> u64 {
        let (mut tris, mut rims) = (0u64, 0u64);
        let shell = matches!(self.kind, Kind::Shell(_));
        for j in 0..self.cells_v() {
            let per_cell = if self.pole_row(j) { 1 } else { 2 };
            for i in 0..self.cells_u() {
                if self.kept(i as isize, j as isize) {
                    tris += per_cell;
                    if shell {
                        rims += self.boundary_edges(i, j).count() as u64;
                    }
                }
            }
        }
        if shell {
            2 * tris + 2 * rims
        } else {
            tris
        }
    }
}

/// Subdivides each interval between consecutive `breaks` into ⌈length · density⌉ (at least
/// `min`) equal parameter steps; `length(a, b)` measures an interval in metres. Returns the
/// samples (both ends included) and the sample index of every break.
pub(super) fn subdivide(
    breaks: &[f64],
    density: f64,
    min: usize,
    length: impl Fn(f64, f64) -> f64,
) -> (Vec<f64>, Vec<usize>) {
    let mut samples = vec![breaks[0]];
    let mut at = vec![0];
    for w in breaks.windows(2) {
        let n = ((length(w[0], w[1]) * density).ceil() as usize).max(min);
        for k in 1..=n {
            samples.push(if k == n {
                w[1]
            } else {
                w[0] + (w[1] - w[0]) * k as f64 / n as f64
            });
        }
        at.push(samples.len() - 1);
    }
    (samples, at)
}

/// Length of the curve t ↦ f(t) over [a, b], as a 32-segment polyline.
pub(super) fn curve_length(f: impl Fn(f64) -> DVec3, a: f64, b: f64) -> f64 {
    const N: usize = 32;
    let mut prev = f(a);
    let mut len = 0.0;
    for k in 1..=N {
        let p = f(a + (b - a) * k as f64 / N as f64);
        len += p.distance(prev);
        prev = p;
    }
    len
}

/// Samples for a surface: u and v broken at the given parameters, intervals measured along
/// the probe lines (the longest probe counts).
fn grid(
    f: &dyn Fn(f64, f64) -> DVec3,
    u_breaks: &[f64],
    v_breaks: &[f64],
    density: f64,
    min: usize,
) -> (Vec<f64>, Vec<usize>, Vec<f64>, Vec<usize>) {
    let (v0, v1) = (v_breaks[0], v_breaks[v_breaks.len() - 1]);
    let (u0, u1) = (u_breaks[0], u_breaks[u_breaks.len() - 1]);
    let probes = [0.25, 0.5, 0.75];
    let (us, u_at) = subdivide(u_breaks, density, min, |a, b| {
        probes
            .iter()
            .map(|p| curve_length(|u| f(u, v0 + (v1 - v0) * p), a, b))
            .fold(0.0, f64::max)
    });
    let (vs, v_at) = subdivide(v_breaks, density, min, |a, b| {
        probes
            .iter()
            .map(|p| curve_length(|v| f(u0 + (u1 - u0) * p, v), a, b))
            .fold(0.0, f64::max)
    });
    (us, u_at, vs, v_at)
}

/// A closed superellipsoid or torus part.
pub(super) fn closed_part(
    f: SurfaceFn,
    torus_like: bool,
    density: f64,
    material: u32,
    node: u32,
    uv: Uv,
) -> Surface {
    let u_breaks = [0.0, FRAC_PI_2, PI, 1.5 * PI, TAU];
    let v_breaks: &[f64] = if torus_like {
        &u_breaks
    } else {
        &[-FRAC_PI_2, 0.0, FRAC_PI_2]
    };
    let (mut us, _, vs, _) = grid(&f, &u_breaks, v_breaks, density, 2);
    us.pop();
    Surface {
        f,
        us,
        vs,
        wrap_u: true,
        wrap_v: torus_like,
        pole_lo: !torus_like,
        pole_hi: !torus_like,
        keep: None,
        kind: Kind::Closed,
        material,
        node,
        origin: DVec3::ZERO,
        uv,
    }
}

/// The parameter step (along u, or along v) that moves at least [`GAP`] metres everywhere on
/// the edges of the parameter rectangle `u` × `v`.
pub(super) fn param_gap(
    f: &dyn Fn(f64, f64) -> DVec3,
    u: (f64, f64),
    v: (f64, f64),
    along_u: bool,
) -> f64 {
    const H: f64 = 1e-6;
    let mut min_speed = f64::INFINITY;
    for k in 0..=16 {
        let t = k as f64 / 16.0;
        let points = [
            (u.0 + (u.1 - u.0) * t, v.0),
            (u.0 + (u.1 - u.0) * t, v.1),
            (u.0, v.0 + (v.1 - v.0) * t),
            (u.1, v.0 + (v.1 - v.0) * t),
        ];
        for (pu, pv) in points {
            let d = if along_u {
                f(pu + H, pv) - f(pu - H, pv)
            } else {
                f(pu, pv + H) - f(pu, pv - H)
            };
            min_speed = min_speed.min(d.length() / (2.0 * H));
        }
    }
    GAP / min_speed
}

/// What a part is drawn with and where it moves: its material, its node, and the origin of
/// that node's local space in car coordinates ([`Surface`]'s fields of the same names).
#[derive(Clone, Copy)]
pub(super) struct Placement {
    pub(super) material: u32,
    pub(super) node: u32,
    pub(super) origin: DVec3,
}

/// A rectangular patch of the body surface (θ range `u`, station range `v`), shrunk by the
/// gap on the sides listed in `gaps` (θ low, θ high, s low, s high).
pub(super) fn body_patch(
    u: (f64, f64),
    v: (f64, f64),
    gaps: [bool; 4],
    kind: Kind,
    density: f64,
    place: Placement,
) -> Surface {
    let Placement {
        material,
        node,
        origin,
    } = place;
    let inset = if matches!(kind, Kind::Sheet) {
        0.5 * SHELL
    } else {
        0.0
    };
    let f: SurfaceFn = Box::new(move |t, s| body_point(t, s) - body_normal(t, s) * inset);
    let gu = param_gap(&f, u, v, true);
    let gv = param_gap(&f, u, v, false);
    let u = (
        u.0 + if gaps[0] { gu } else { 0.0 },
        u.1 - if gaps[1] { gu } else { 0.0 },
    );
    let v = (
        v.0 + if gaps[2] { gv } else { 0.0 },
        v.1 - if gaps[3] { gv } else { 0.0 },
    );
    let (us, _, vs, _) = grid(&f, &[u.0, u.1], &[v.0, v.1], density, 1);
    Surface {
        f,
        us,
        vs,
        wrap_u: false,
        wrap_v: false,
        pole_lo: false,
        pole_hi: false,
        keep: None,
        kind,
        material,
        node,
        origin,
        uv: Uv::None,
    }
}
