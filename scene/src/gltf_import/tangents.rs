//! MikkTSpace tangents (the `mikktspace` crate) for normal-mapped primitives without TANGENT.

use super::primitives::unit_tangent;

/// A triangle list as MikkTSpace reads it; tangents are written per triangle corner.
struct Faces<'a> {
    positions: &'a [[f32; 3]],
    normals: &'a [[f32; 3]],
    uvs: &'a [[f32; 2]],
    triangles: &'a [[u32; 3]],
    /// Per corner (3 per triangle): the tangent MikkTSpace gives it.
    corners: Vec<[f32; 4]>,
}

impl Faces<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.triangles[face][vert] as usize
    }
}

impl mikktspace::Geometry for Faces<'_> {
    fn num_faces(&self) -> usize {
        self.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.vertex(face, vert)]
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[self.vertex(face, vert)]
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        // Non-finite coordinates would poison the groups MikkTSpace builds.
        self.uvs[self.vertex(face, vert)].map(|c| if c.is_finite() { c } else { 0.0 })
    }

    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        self.corners[3 * face + vert] = tangent;
    }
}

/// The MikkTSpace tangent of every triangle corner (3 per triangle, in order) of a triangle
/// list with counter-clockwise front faces about its unit `normals`: xyz unit (zero where
/// MikkTSpace gives none or a non-finite one), w the handedness ±1.
pub(super) fn generate(
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
    uvs: &[[f32; 2]],
    triangles: &[[u32; 3]],
) -> Vec<[f32; 4]> {
    let mut faces = Faces {
        positions,
        normals,
        uvs,
        triangles,
        corners: vec![[0.0; 4]; 3 * triangles.len()],
    };
    // `false` only for an empty list or one MikkTSpace cannot allocate for; corners it did not
    // reach stay zero either way.
    let _ = mikktspace::generate_tangents(&mut faces);
    faces.corners.into_iter().map(unit_tangent).collect()
}
