//! The bounding polyhedron and its viewpoint partitions (paper 000, § 4.2).
//!
//! Partition `f` is the set of viewpoints whose ray from the centre leaves the polyhedron
//! through face `f`: outside face `f`'s plane, and on `f`'s side of each cone boundary
//! `(n_f / h_f − n_g / h_g) · x = 0`, cut at the reach (a cube around the centre).

use glam::DVec3;

use crate::geom::{facets, region, Plane};

/// Outward unit normals of the polyhedron's faces: a tetrahedron (4), a cube (6), an
/// octahedron (8), else `n` directions spread over the sphere (a Fibonacci lattice).
pub fn face_normals(n: u32) -> Vec<DVec3> {
    let s = |x: f64, y: f64, z: f64| DVec3::new(x, y, z).normalize();
    match n {
        4 => vec![
            s(1., 1., 1.),
            s(1., -1., -1.),
            s(-1., 1., -1.),
            s(-1., -1., 1.),
        ],
        6 => vec![
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ],
        8 => (0..8)
            .map(|k| {
                let b = |i: u32| if k & (1 << i) == 0 { 1.0 } else { -1.0 };
                s(b(0), b(1), b(2))
            })
            .collect(),
        _ => {
            let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
            (0..n)
                .map(|k| {
                    let y = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
                    let r = (1.0 - y * y).sqrt();
                    let phi = golden * k as f64;
                    DVec3::new(r * phi.cos(), y, r * phi.sin())
                })
                .collect()
        }
    }
}

/// The partition counts `presort` accepts.
pub fn valid_partitions(n: u32) -> bool {
    matches!(n, 4 | 6 | 8) || (10..=256).contains(&n)
}

/// One viewpoint partition, in normalised space.
#[derive(Clone, Debug)]
pub struct Partition {
    /// Its bounding planes (positive inside), redundant ones dropped.
    pub planes: Vec<Plane>,
    /// Its vertices.
    pub vertices: Vec<DVec3>,
    /// A viewpoint inside it (the preliminary order is a depth sort from there).
    pub viewpoint: DVec3,
    /// Its face's outward normal: every camera of the partition is beyond the face along it,
    /// and the scene is not.
    pub normal: DVec3,
}

/// The partitions of the polyhedron with faces `faces` (unit normal, distance `h > 0` from the
/// origin) within `reach` of the origin per axis; `None` for a face whose partition is empty
/// or unbounded (a malformed polyhedron).
pub fn partitions(faces: &[(DVec3, f64)], reach: f64) -> Option<Vec<Partition>> {
    faces
        .iter()
        .enumerate()
        .map(|(f, &(nf, hf))| {
            let mut planes = vec![Plane { n: nf, d: hf }];
            for (g, &(ng, hg)) in faces.iter().enumerate() {
                if g == f {
                    continue;
                }
                let n = nf / hf - ng / hg;
                let l = n.length();
                if l > 1e-12 {
                    planes.push(Plane { n: n / l, d: 0.0 });
                }
            }
            for k in 0..3 {
                let mut e = DVec3::ZERO;
                e[k] = 1.0;
                planes.push(Plane { n: e, d: -reach });
                planes.push(Plane { n: -e, d: -reach });
            }
            let vertices = region(&planes)?;
            let planes = facets(&planes, &vertices);
            // The face's own polygon, pushed out: inside the cone and outside the face.
            let on_face: Vec<DVec3> = vertices
                .iter()
                .copied()
                .filter(|v| (nf.dot(*v) - hf).abs() < 1e-7)
                .collect();
            let centre = if on_face.is_empty() {
                nf * hf
            } else {
                on_face.iter().copied().sum::<DVec3>() / on_face.len() as f64
            };
            Some(Partition {
                planes,
                vertices,
                viewpoint: centre * 3.0,
                normal: nf,
            })
        })
        .collect()
}
