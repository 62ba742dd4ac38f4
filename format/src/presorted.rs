//! The presorted file (`trisort presort`, paper 000): one list of triangle copies per viewpoint
//! partition, each copy with a half-space test, that draws depth-sorted from any camera outside
//! a bounding polyhedron and within its reach.
//!
//! What the list holds: the triangles that need an order (`BLEND` and transmissive materials;
//! [`Presorted::sorted`]), as copies in back-to-front order per partition. The opaque rest
//! ([`Presorted::opaque`]) is drawn first with the depth test, in ascending id order, as the
//! default pipeline does. A copy is drawn when the camera passes every one of its tests
//! ([`PlaneTest`]); for every camera in a partition, the copies that pass are back-to-front for
//! every pixel (the property `presort` builds and `verify` checks).

use serde::{Deserialize, Serialize};

use crate::{Environment, Geometry, Hash};

/// A plane `n · (x − centre) = d` (unit `n`, relative to [`Polyhedron::centre`]), in f32 as
/// the GPU evaluates it: `[nx, ny, nz, d]`.
pub type PlaneF32 = [f32; 4];

/// One half-space test of a copy: plane [`PlaneTest::plane`] of [`Presorted::planes`], passed
/// where `n · (eye − centre) − d ≥ 0`, or, [`PlaneTest::flipped`], where it is `< 0`. A plane and
/// its flip are exactly complementary in any arithmetic: a camera passes one of the two.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlaneTest {
    /// Index into [`Presorted::planes`].
    pub plane: u32,
    /// Whether the test is the plane's negative side.
    pub flipped: bool,
}

impl PlaneTest {
    /// The test as the GPU reads it: the plane index, with bit 31 set where flipped.
    pub fn packed(self) -> u32 {
        self.plane | if self.flipped { 1 << 31 } else { 0 }
    }
}

/// One entry of the list: a scene triangle and its tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PresortedCopy {
    /// Scene triangle (index into [`Geometry::triangles`]).
    pub triangle: u32,
    /// First test in [`Presorted::tests`].
    pub first_test: u32,
    /// Number of tests (0: always drawn).
    pub tests: u32,
}

/// The bounding polyhedron: cameras must lie outside it and within [`Polyhedron::reach`] of its
/// centre (per axis). Partition `f` holds the cameras whose ray from the centre leaves the
/// polyhedron through face `f`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Polyhedron {
    /// Centre (world space).
    pub centre: [f64; 3],
    /// Faces `n · (x − centre) = h` (unit outward `n`, `h > 0`): `[nx, ny, nz, h]`.
    pub faces: Vec<[f64; 4]>,
    /// Largest camera offset from the centre along any axis.
    pub reach: f64,
}

/// Why a camera cannot use a presorted file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OutsideError {
    /// The camera is inside the polyhedron (or on it).
    Inside,
    /// The camera is farther from the centre than the reach.
    BeyondReach,
    /// The camera position is not finite.
    NotFinite,
}

impl std::fmt::Display for OutsideError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            OutsideError::Inside => "the camera is inside the bounding polyhedron",
            OutsideError::BeyondReach => "the camera is beyond the presort's reach",
            OutsideError::NotFinite => "the camera position is not finite",
        })
    }
}

impl Polyhedron {
    /// The partition of camera `eye` (world space): the face through which the ray from the
    /// centre to the camera leaves the polyhedron, i.e. the largest `n · (eye − centre) / h`,
    /// which must be above 1 (outside).
    pub fn partition_of(&self, eye: [f64; 3]) -> Result<usize, OutsideError> {
        if eye.iter().any(|v| !v.is_finite()) {
            return Err(OutsideError::NotFinite);
        }
        let r = [
            eye[0] - self.centre[0],
            eye[1] - self.centre[1],
            eye[2] - self.centre[2],
        ];
        if r.iter().any(|v| v.abs() > self.reach) {
            return Err(OutsideError::BeyondReach);
        }
        let mut best = (f64::NEG_INFINITY, 0);
        for (k, f) in self.faces.iter().enumerate() {
            let s = (f[0] * r[0] + f[1] * r[1] + f[2] * r[2]) / f[3];
            if s > best.0 {
                best = (s, k);
            }
        }
        if best.0 <= 1.0 {
            return Err(OutsideError::Inside);
        }
        Ok(best.1)
    }
}

/// A partition's run of [`Presorted::copies`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Segment {
    /// First copy.
    pub first: u32,
    /// Number of copies.
    pub count: u32,
}

/// Figures of a presort.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PresortStats {
    /// Triangles of the (split) scene.
    pub triangles: u64,
    /// Of them, triangles that need an order (in the list).
    pub sorted_triangles: u64,
    /// Copies in all partitions' lists together.
    pub list_triangles: u64,
    /// Copies made by duplication (cutting planes), all partitions.
    pub duplicated: u64,
    /// Copies moved without duplication, all partitions.
    pub moved: u64,
    /// Occlusion regions computed (pairs of copies tested exactly).
    pub regions: u64,
    /// Separating-plane linear programs solved.
    pub linear_programs: u64,
    /// Seconds the presort took (split, graph and lists).
    pub seconds: f64,
}

/// A presorted file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Presorted {
    /// trisort version that wrote it.
    pub tool_version: String,
    /// Hash of the scene as loaded (before the split).
    pub scene_hash: Hash,
    /// The scene, split where its triangles pass through each other, at its rest pose.
    pub geometry: Geometry,
    /// The light players shade with.
    pub environment: Environment,
    /// Opacity transmissive glass is drawn at (and was sorted for: glass at opacity 0 is
    /// still sorted, it shows nothing but costs nothing to keep in order).
    pub glass_opacity: f32,
    /// The bounding polyhedron and its partitions.
    pub polyhedron: Polyhedron,
    /// Triangles drawn first with the depth test, ascending (opaque and `MASK`).
    pub opaque: Vec<u32>,
    /// Triangles that need an order, ascending.
    pub sorted: Vec<u32>,
    /// Per partition (face of the polyhedron): its copies.
    pub segments: Vec<Segment>,
    /// Every partition's copies, back to front, one segment after another.
    pub copies: Vec<PresortedCopy>,
    /// Every copy's tests, a run per copy.
    pub tests: Vec<PlaneTest>,
    /// The test planes.
    pub planes: Vec<PlaneF32>,
    /// Figures.
    pub stats: PresortStats,
}

impl Presorted {
    /// The copies drawn from camera `eye` (world space): its partition, and the indices into
    /// [`Presorted::copies`] of the copies whose tests pass, in drawing order (back to front).
    /// The tests are evaluated as the GPU does: in f32, the camera relative to the centre.
    pub fn drawn(&self, eye: [f64; 3]) -> Result<(usize, Vec<u32>), OutsideError> {
        let k = self.polyhedron.partition_of(eye)?;
        let e = [0, 1, 2].map(|a| (eye[a] - self.polyhedron.centre[a]) as f32);
        let s = self.segments[k];
        let passes = |c: &PresortedCopy| {
            let tests = &self.tests[c.first_test as usize..(c.first_test + c.tests) as usize];
            tests.iter().all(|t| {
                let p = self.planes[t.plane as usize];
                let v = p[0] * e[0] + p[1] * e[1] + p[2] * e[2] - p[3];
                if t.flipped {
                    v < 0.0
                } else {
                    v >= 0.0
                }
            })
        };
        let drawn = (s.first..s.first + s.count)
            .filter(|&c| passes(&self.copies[c as usize]))
            .collect();
        Ok((k, drawn))
    }

    /// Checks that every index is in range: segments within the copies, copies' triangles in
    /// the scene and their tests in the test list, tests' planes in the plane list, the
    /// partitions one per face. Says what is wrong.
    pub fn check_structure(&self) -> Result<(), String> {
        self.geometry
            .check_structure()
            .map_err(|e| format!("geometry: {e}"))?;
        let n = self.geometry.triangles.len() as u64;
        if self.segments.len() != self.polyhedron.faces.len() {
            return Err(format!(
                "{} segments for {} polyhedron faces",
                self.segments.len(),
                self.polyhedron.faces.len()
            ));
        }
        if self.polyhedron.faces.len() < 4
            || self
                .polyhedron
                .faces
                .iter()
                .any(|f| f.iter().any(|v| !v.is_finite()) || f[3] <= 0.0)
            || !(self.polyhedron.reach.is_finite() && self.polyhedron.reach > 0.0)
        {
            return Err("the bounding polyhedron is malformed".into());
        }
        for (k, s) in self.segments.iter().enumerate() {
            if s.first as u64 + s.count as u64 > self.copies.len() as u64 {
                return Err(format!(
                    "segment {k} runs past the {} copies",
                    self.copies.len()
                ));
            }
        }
        for (c, copy) in self.copies.iter().enumerate() {
            if copy.triangle as u64 >= n {
                return Err(format!("copy {c} names triangle {} of {n}", copy.triangle));
            }
            if copy.first_test as u64 + copy.tests as u64 > self.tests.len() as u64 {
                return Err(format!("copy {c}'s tests run past the test list"));
            }
        }
        if let Some(t) = self
            .tests
            .iter()
            .find(|t| t.plane as usize >= self.planes.len() || t.plane >= 1 << 31)
        {
            return Err(format!(
                "a test names plane {} of {}",
                t.plane,
                self.planes.len()
            ));
        }
        for list in [&self.opaque, &self.sorted] {
            if let Some(t) = list.iter().find(|&&t| t as u64 >= n) {
                return Err(format!("triangle {t} is beyond the scene's {n}"));
            }
        }
        Ok(())
    }
}
