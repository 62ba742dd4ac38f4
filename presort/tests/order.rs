//! The presort's promise checked on the CPU, independently of how the lists were built: from
//! random cameras outside the polyhedron, every ray meets the drawn copies back to front, and
//! every triangle the camera can see is drawn exactly once.

use glam::DVec3;
use trisort_format::{AlphaMode, Environment, Geometry, Material, Presorted};
use trisort_presort::{presort, PresortOptions};
use trisort_testkit::fixtures::{scene, tri};

/// A small deterministic generator (xorshift), so failures reproduce.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

fn material(double_sided: bool) -> Material {
    Material {
        base_color: [0.5, 0.5, 0.9, 0.5],
        alpha_mode: AlphaMode::Blend,
        double_sided,
        ..Material::default()
    }
}

/// One large random triangle per cell of an `n × n × m` grid (cells apart, so no two
/// intersect and no camera sees a cycle, but the occlusion graph over a partition has
/// cycles), alternately single- and double-sided, plus one opaque triangle.
fn soup(n: u32, m: u32, seed: u64) -> Geometry {
    let mut rng = Rng(seed);
    let mut g = scene(vec![material(false), material(true), Material::default()]);
    let mut push = |corners: [[f32; 3]; 3], material: u32| tri(&mut g, corners, material);
    let mut k = 0;
    for x in 0..n {
        for y in 0..n {
            for z in 0..m {
                let cell = DVec3::new(x as f64, y as f64, z as f64 * 1.0);
                let corner = |rng: &mut Rng| {
                    let p = cell
                        + DVec3::new(
                            rng.range(0.05, 0.95),
                            rng.range(0.05, 0.95),
                            rng.range(0.05, 0.95),
                        );
                    [p.x as f32, p.y as f32, p.z as f32]
                };
                let c = [corner(&mut rng), corner(&mut rng), corner(&mut rng)];
                push(c, k % 2);
                k += 1;
            }
        }
    }
    push(
        [
            [-1.0, -1.0, -0.5],
            [n as f32 + 1.0, -1.0, -0.5],
            [-1.0, n as f32 + 1.0, -0.5],
        ],
        2,
    );
    g
}

fn environment() -> Environment {
    Environment {
        name: "test".into(),
        width: 1,
        height: 1,
        levels: vec![vec![0x3c00; 4]],
        sh: [[0.0; 3]; 9],
        sun: None,
        exposure: 1.0,
    }
}

fn world(g: &Geometry, t: u32) -> [DVec3; 3] {
    g.triangles[t as usize].map(|v| DVec3::from(g.vertices[v as usize].position.map(f64::from)))
}

/// Ray–triangle distance (Möller–Trumbore), either side.
fn hit(origin: DVec3, dir: DVec3, v: [DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-14 {
        return None;
    }
    let s = origin - v[0];
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let w = dir.dot(q) / det;
    let t = e2.dot(q) / det;
    // Keep clear of edges: a ray grazing an edge says nothing about order.
    let m = 1e-6;
    (u > m && w > m && u + w < 1.0 - m && t > 0.0).then_some(t)
}

/// Checks `file` from `views` random cameras with `rays` rays each; returns how many rays met
/// two drawn triangles or more.
fn check(file: &Presorted, views: u32, rays: u32, seed: u64) -> u64 {
    let g = &file.geometry;
    let mut rng = Rng(seed);
    let centre = DVec3::from(file.polyhedron.centre);
    let radius = file
        .polyhedron
        .faces
        .iter()
        .map(|f| f[3])
        .fold(0.0, f64::max);
    let mut overlapping = 0;
    for view in 0..views {
        // A camera outside the polyhedron: a random direction, 1.3 to 6 radii out.
        let eye = loop {
            let d = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            if d.length() > 0.1 && d.length() <= 1.0 {
                let e = centre + d.normalize() * radius * rng.range(1.8, 6.0);
                if file.drawn(e.to_array()).is_ok() {
                    break e;
                }
            }
        };
        let (_, drawn) = file.drawn(eye.to_array()).unwrap();
        // Each triangle the camera may see is drawn once: single-sided ones from the front.
        let mut times = vec![0u32; g.triangles.len()];
        for &c in &drawn {
            times[file.copies[c as usize].triangle as usize] += 1;
        }
        for &t in &file.sorted {
            let v = world(g, t);
            let front = (v[1] - v[0]).cross(v[2] - v[0]).dot(eye - v[0]) > 0.0;
            let m = &g.materials[g.triangle_material(t) as usize];
            let expected = u32::from(front || m.double_sided);
            // Edge-on cameras may go either way; a single-sided triangle seen from the back
            // may be selected (the shader culls it) but at most once.
            let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            if !front && !m.double_sided {
                assert!(
                    times[t as usize] <= 1,
                    "view {view}: triangle {t} drawn twice"
                );
            } else if n.dot((eye - v[0]).normalize()).abs() > 1e-4 {
                assert_eq!(
                    times[t as usize], expected,
                    "view {view}: triangle {t} drawn {} times",
                    times[t as usize]
                );
            }
        }
        for _ in 0..rays {
            // Through a random point of a random sorted triangle.
            let t =
                file.sorted[(rng.next() * file.sorted.len() as f64) as usize % file.sorted.len()];
            let v = world(g, t);
            let (a, b) = (rng.next(), rng.next());
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            let target = v[0] + (v[1] - v[0]) * a + (v[2] - v[0]) * b;
            let dir = (target - eye).normalize();
            let mut hits: Vec<(f64, usize)> = Vec::new();
            for (pos, &c) in drawn.iter().enumerate() {
                let t = file.copies[c as usize].triangle;
                let v = world(g, t);
                let front = (v[1] - v[0]).cross(v[2] - v[0]).dot(eye - v[0]) > 0.0;
                if !front && !g.materials[g.triangle_material(t) as usize].double_sided {
                    continue;
                }
                if let Some(d) = hit(eye, dir, v) {
                    hits.push((d, pos));
                }
            }
            hits.sort_by(|a, b| a.0.total_cmp(&b.0));
            if hits.len() > 1 {
                overlapping += 1;
            }
            for w in hits.windows(2) {
                assert!(
                    w[0].1 > w[1].1,
                    "view {view}: a nearer copy (list position {}) is drawn before a farther one ({})",
                    w[0].1,
                    w[1].1
                );
            }
        }
    }
    overlapping
}

#[test]
fn random_cells_are_back_to_front_from_every_side() {
    for (partitions, seed) in [(6, 7), (4, 11), (16, 13)] {
        let g = soup(4, 2, seed);
        let lists = presort(
            &g,
            PresortOptions {
                partitions,
                ..PresortOptions::default()
            },
            &|_, _| {},
        )
        .unwrap();
        let file = lists.into_presorted(g, environment(), 0.0, [0; 32]);
        file.check_structure().unwrap();
        assert_eq!(file.sorted.len(), 32);
        assert_eq!(file.opaque.len(), 1);
        assert!(file.stats.list_triangles >= file.sorted.len() as u64);
        let overlapping = check(&file, 64, 400, seed);
        assert!(
            overlapping > 800,
            "the check must see overlaps ({overlapping})"
        );
    }
}

#[test]
fn cycles_over_a_partition_are_cut() {
    // Pairs that occlude each other from different viewpoints of one partition need copies.
    let g = soup(5, 3, 5);
    let lists = presort(&g, PresortOptions::default(), &|_, _| {}).unwrap();
    let file = lists.into_presorted(g, environment(), 0.0, [0; 32]);
    assert!(
        file.stats.duplicated > 0,
        "the scene was meant to need cutting planes: {:?}",
        file.stats
    );
    check(&file, 48, 300, 99);
}

#[test]
fn cameras_inside_or_too_far_are_refused() {
    let g = soup(2, 1, 3);
    let file = presort(&g, PresortOptions::default(), &|_, _| {})
        .unwrap()
        .into_presorted(g, environment(), 0.0, [0; 32]);
    let c = file.polyhedron.centre;
    assert_eq!(file.drawn(c), Err(trisort_format::OutsideError::Inside));
    let far = [c[0] + file.polyhedron.reach * 2.0, c[1], c[2]];
    assert_eq!(
        file.drawn(far),
        Err(trisort_format::OutsideError::BeyondReach)
    );
    assert_eq!(
        file.drawn([f64::NAN, 0.0, 0.0]),
        Err(trisort_format::OutsideError::NotFinite)
    );
}

#[test]
fn bad_partition_counts_are_refused() {
    let g = soup(1, 1, 3);
    for n in [0, 3, 5, 7, 9, 1000] {
        let e = presort(
            &g,
            PresortOptions {
                partitions: n,
                ..PresortOptions::default()
            },
            &|_, _| {},
        )
        .unwrap_err();
        assert!(e.to_string().contains("--partitions"), "{e}");
    }
}

/// Three thin single-sided triangles in a pinwheel seen from above (+Z): each passes over the
/// next and under the one before, apart in space (no two intersect), so cameras above see a
/// cycle no order resolves (paper 000 assumes none; only splitting a triangle would).
fn pinwheel() -> Geometry {
    let mut g = scene(vec![material(false)]);
    let q = |k: usize| {
        let a = std::f64::consts::FRAC_PI_2 - k as f64 * 2.0 * std::f64::consts::FRAC_PI_3;
        DVec3::new(a.cos(), a.sin(), 0.0)
    };
    for i in 0..3 {
        // From the crossing with the one before (z = 0) to the one with the next (z = 1).
        let (from, to) = (q(i), q((i + 1) % 3));
        let at = |t: f64| from + (to - from) * t + DVec3::Z * t;
        let side = (to - from).cross(DVec3::Z).normalize() * 0.1;
        let mut c = [at(-0.5) + side, at(-0.5) - side, at(1.5)];
        if (c[1] - c[0]).cross(c[2] - c[0]).z < 0.0 {
            c.swap(1, 2);
        }
        tri(&mut g, c.map(|v| v.as_vec3().to_array()), 0);
    }
    g
}

#[test]
fn a_cycle_seen_from_one_camera_is_reported_or_refused() {
    let g = pinwheel();
    let lists = presort(&g, PresortOptions::default(), &|_, _| {}).unwrap();
    assert!(
        !lists.cycles.is_empty(),
        "the pinwheel is a cycle from above"
    );
    for c in &lists.cycles {
        assert!(
            c.triangle < 3 && c.occluded < 3 && c.triangle != c.occluded,
            "{c:?}"
        );
    }
    // The cycle is seen from above only: the partition whose face looks along +Z.
    let up = lists
        .polyhedron
        .faces
        .iter()
        .position(|f| f[2] > 0.9)
        .expect("a cube has a face up");
    assert!(
        lists.cycles.iter().all(|c| c.partition == up),
        "{:?}",
        lists.cycles
    );
    let strict = PresortOptions {
        strict: true,
        ..PresortOptions::default()
    };
    let e = presort(&g, strict, &|_, _| {}).unwrap_err();
    assert!(e.to_string().contains("occlusion cycle"), "{e}");
}
