//! Tessellation: a planned surface becomes vertices and triangles, with an inner skin and
//! rims for shells.

use glam::DVec3;
use trisort_format::{Geometry, Vertex};

use super::shapes::surface_normal;
use super::surface::{Kind, Surface, Uv};

/// Accumulates one part's vertices and triangles before they join the geometry.
#[derive(Default)]
struct PartMesh {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl PartMesh {
    fn vertex(&mut self, p: DVec3) -> u32 {
        self.positions.push(p);
        self.positions.len() as u32 - 1
    }

    fn quad(&mut self, [a, b, c, d]: [u32; 4]) {
        if a != b && b != c && a != c {
            self.triangles.push([a, b, c]);
        }
        if a != c && c != d && a != d {
            self.triangles.push([a, c, d]);
        }
    }

    /// Appends to `geometry` with area-weighted smooth normals.
    fn flush(self, s: &Surface, geometry: &mut Geometry) {
        let mut normals = vec![DVec3::ZERO; self.positions.len()];
        for t in &self.triangles {
            let [a, b, c] = t.map(|v| self.positions[v as usize]);
            let n = (b - a).cross(c - a);
            for &v in t {
                normals[v as usize] += n;
            }
        }
        let base = geometry.vertices.len() as u32;
        for (p, n) in self.positions.iter().zip(&normals) {
            let uv = match &s.uv {
                Uv::None => [0.0; 2],
                Uv::Planar {
                    origin,
                    u_axis,
                    v_axis,
                } => [
                    (*p - *origin).dot(*u_axis) as f32,
                    (*p - *origin).dot(*v_axis) as f32,
                ],
            };
            geometry.vertices.push(Vertex {
                position: (*p - s.origin).as_vec3().to_array(),
                normal: n.normalize_or_zero().as_vec3().to_array(),
                uv,
                material: s.material,
                node: s.node,
                tangent: [0.0; 4],
                uv1: [0.0; 2],
            });
        }
        geometry
            .triangles
            .extend(self.triangles.iter().map(|t| t.map(|v| v + base)));
    }
}

/// Tessellates one surface into `geometry`.
pub(super) fn tessellate(s: &Surface, geometry: &mut Geometry) {
    let (nu, nv) = (s.us.len(), s.vs.len());
    let point = |i: usize, j: usize| (s.f)(s.us[i % nu], s.vs[j]);
    let mut grid_points: Vec<DVec3> = (0..nv)
        .flat_map(|j| (0..nu).map(move |i| (i, j)))
        .map(|(i, j)| point(i, j))
        .collect();
    // Poles collapse to their first point.
    for (pole, j) in [(s.pole_lo, 0), (s.pole_hi, nv - 1)] {
        if pole {
            let p = grid_points[j * nu];
            grid_points[j * nu..(j + 1) * nu].fill(p);
        }
    }
    // A v-wrapped surface's last row is its first.
    let rows = if s.wrap_v { nv - 1 } else { nv };
    let index = |i: usize, j: usize| (i % nu) + (j % rows) * nu;
    // Which grid points are used.
    let mut used = vec![false; nu * nv];
    for j in 0..s.cells_v() {
        for i in 0..s.cells_u() {
            if s.kept(i as isize, j as isize) {
                for (ci, cj) in [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)] {
                    used[index(ci, cj)] = true;
                }
            }
        }
    }
    let pole_of = |j: usize| (s.pole_lo && j == 0) || (s.pole_hi && j == nv - 1);
    let corners = |i: usize, j: usize| {
        [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)].map(|(ci, cj)| {
            if pole_of(cj) {
                (0, cj)
            } else {
                (ci % nu, cj)
            }
        })
    };

    let mut outer = PartMesh::default();
    let mut outer_ids = vec![u32::MAX; nu * nv];
    for j in 0..rows {
        for i in 0..nu {
            let k = index(i, j);
            if used[k] && !(pole_of(j) && i > 0) {
                outer_ids[k] = outer.vertex(grid_points[k]);
            }
        }
    }
    let id = |ids: &[u32], (i, j): (usize, usize)| ids[index(i, j)];
    for j in 0..s.cells_v() {
        for i in 0..s.cells_u() {
            if s.kept(i as isize, j as isize) {
                outer.quad(corners(i, j).map(|c| id(&outer_ids, c)));
            }
        }
    }

    let Kind::Shell(thickness) = s.kind else {
        outer.flush(s, geometry);
        return;
    };

    // The inner skin: every used point moved inwards along the surface normal.
    let mut inner_points = vec![DVec3::ZERO; nu * nv];
    for j in 0..rows {
        for i in 0..nu {
            let k = index(i, j);
            if !used[k] {
                continue;
            }
            let n = if pole_of(j) {
                let neighbour = if j == 0 { 1 } else { nv - 2 };
                let ring: DVec3 = (0..nu).map(|q| grid_points[index(q, neighbour)]).sum();
                (grid_points[k] - ring / nu as f64).normalize()
            } else {
                surface_normal(&s.f, s.us[i], s.vs[j])
            };
            inner_points[k] = grid_points[k] - n * thickness;
        }
    }
    let mut inner = PartMesh::default();
    let mut inner_ids = vec![u32::MAX; nu * nv];
    for j in 0..rows {
        for i in 0..nu {
            let k = index(i, j);
            if used[k] && !(pole_of(j) && i > 0) {
                inner_ids[k] = inner.vertex(inner_points[k]);
            }
        }
    }
    let mut rims = PartMesh::default();
    for j in 0..s.cells_v() {
        for i in 0..s.cells_u() {
            if !s.kept(i as isize, j as isize) {
                continue;
            }
            let c = corners(i, j);
            let [a, b, cc, d] = c.map(|c| id(&inner_ids, c));
            inner.quad([d, cc, b, a]);
            for (p, q) in s.boundary_edges(i, j) {
                let (p, q) = (index(c[p].0, c[p].1), index(c[q].0, c[q].1));
                let quad = [
                    rims.vertex(grid_points[q]),
                    rims.vertex(grid_points[p]),
                    rims.vertex(inner_points[p]),
                    rims.vertex(inner_points[q]),
                ];
                rims.quad(quad);
            }
        }
    }
    outer.flush(s, geometry);
    inner.flush(s, geometry);
    rims.flush(s, geometry);
}
