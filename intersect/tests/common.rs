//! Scene builders and the invariants every split must keep.

use glam::{DMat4, DVec3};
use trisort_format::{Camera, FrameState, Geometry, Material, Node, NodePose, Vertex};
use trisort_intersect::{find_intersections, SplitScene};

/// A geometry with these nodes and two materials.
pub fn geometry(nodes: Vec<Node>) -> Geometry {
    Geometry {
        materials: vec![
            Material::default(),
            Material {
                name: "second".into(),
                ..Material::default()
            },
        ],
        nodes,
        ..Geometry::default()
    }
}

/// A node with this parent and rest transform.
pub fn node(name: &str, parent: Option<u32>, rest: DMat4) -> Node {
    Node {
        name: name.into(),
        parent,
        rest: rest.to_cols_array(),
    }
}

/// One root node at the identity.
pub fn one_node() -> Geometry {
    geometry(vec![node("root", None, DMat4::IDENTITY)])
}

/// Uv as an affine function of the position, so that interpolation can be checked.
fn uv_at(p: [f32; 3]) -> [f32; 2] {
    [
        0.3 * p[0] + 0.1 * p[1] - 0.2 * p[2] + 0.5,
        -0.1 * p[0] + 0.4 * p[1] + 0.25 * p[2],
    ]
}

/// A unit normal that differs from corner to corner.
fn normal_at(p: [f32; 3]) -> [f32; 3] {
    let n = DVec3::new(0.2 + 0.1 * p[0] as f64, 1.0, 0.3 - 0.2 * p[2] as f64).normalize();
    n.as_vec3().to_array()
}

/// Adds a triangle with three vertices of its own (uv and normal varying with the position).
pub fn tri(g: &mut Geometry, corners: [[f32; 3]; 3], node: u32, material: u32) {
    let base = push_corners(g, &corners, node, material);
    g.triangles.push([base, base + 1, base + 2]);
}

/// Appends a vertex per corner (uv and normal varying with the position); returns the first
/// one's index.
fn push_corners(g: &mut Geometry, corners: &[[f32; 3]], node: u32, material: u32) -> u32 {
    let base = g.vertices.len() as u32;
    for &position in corners {
        g.vertices.push(Vertex {
            position,
            normal: normal_at(position),
            uv: uv_at(position),
            material,
            node,
            tangent: [0.0; 4],
            uv1: [0.0; 2],
        });
    }
    base
}

/// Adds a quad with four shared vertices: triangles (0, 1, 2) and (0, 2, 3).
pub fn quad(g: &mut Geometry, corners: [[f32; 3]; 4], node: u32, material: u32) {
    let base = push_corners(g, &corners, node, material);
    g.triangles.push([base, base + 1, base + 2]);
    g.triangles.push([base, base + 2, base + 3]);
}

/// Two 2 × 2 quads crossing like an X seen from +Y: one in the plane z = x, one in z = −x,
/// mapped by `f`. Their intersection is the line x = z = 0, through edge midpoints.
pub fn x_quads(g: &mut Geometry, node: u32, f: impl Fn([f32; 3]) -> [f32; 3]) {
    quad(g, X_QUAD_A.map(&f), node, 0);
    quad(g, X_QUAD_B.map(&f), node, 1);
}

/// The quad of [`x_quads`] in the plane z = x.
pub const X_QUAD_A: [[f32; 3]; 4] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, -1.0],
];

/// The quad of [`x_quads`] in the plane z = −x.
pub const X_QUAD_B: [[f32; 3]; 4] = [
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, 1.0],
];

/// Two triangles crossing at an angle with intersection points that f32 cannot represent.
pub fn irregular_pair(g: &mut Geometry, node: u32, f: impl Fn([f32; 3]) -> [f32; 3]) {
    tri(
        g,
        [[0.1, 0.2, 0.3], [1.7, 0.4, -0.2], [0.3, 1.9, 0.1]].map(&f),
        node,
        0,
    );
    tri(
        g,
        [[0.8, 0.9, -1.1], [0.6, 1.1, 1.3], [1.2, 0.2, 0.9]].map(&f),
        node,
        1,
    );
}

/// A frame with a fixed camera and these poses.
pub fn frame(poses: Vec<NodePose>) -> FrameState {
    FrameState {
        camera: Camera {
            view: DMat4::look_at_rh(DVec3::new(0.0, 0.0, 10.0), DVec3::ZERO, DVec3::Y)
                .to_cols_array(),
            yfov: 1.0,
            znear: 0.1,
            zfar: Some(100.0),
        },
        poses,
    }
}

/// A pose of `node`.
pub fn pose(node: u32, local: DMat4) -> NodePose {
    NodePose {
        node,
        local: local.to_cols_array(),
    }
}

fn local(v: &Vertex) -> DVec3 {
    DVec3::from(v.position.map(f64::from))
}

/// Barycentric coordinates of `x` in the triangle `p` (projected onto its plane).
fn barycentric(p: [DVec3; 3], x: DVec3) -> [f64; 3] {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let l = |i: usize| n.dot((p[(i + 1) % 3] - x).cross(p[(i + 2) % 3] - x)) / n.length_squared();
    [l(0), l(1), l(2)]
}

/// How to check a split.
pub struct Expect {
    /// Largest relative error of the total area of each original triangle's pieces.
    pub area: f64,
    /// Largest error of an interpolated uv or normal component, if checked (for uv, relative
    /// to 1 + its magnitude).
    pub interpolation: Option<f64>,
}

/// Checks the invariants of a split of `input` over `frames`:
/// - the output is well formed, keeps materials, textures, nodes and the input vertices;
/// - `origin` is non-decreasing and covers every input triangle; untouched triangles keep
///   their indices; pieces keep the material, node and winding of their origin;
/// - each original triangle's pieces have its area (to `expect.area`, relative, plus the
///   f32 rounding of the new vertices);
/// - new vertices lie in their origin triangle with uv and normal interpolated from it;
/// - the detector finds no crossing pair in the output except of the counted skipped ones.
pub fn check(input: &Geometry, frames: &[FrameState], out: &SplitScene, expect: &Expect) {
    let g = &out.geometry;
    g.check_structure().expect("well-formed output");
    assert_eq!(g.materials, input.materials);
    assert_eq!(g.nodes, input.nodes);
    assert_eq!(g.textures, input.textures);
    assert_eq!(g.vertices[..input.vertices.len()], input.vertices[..]);
    assert_eq!(out.origin.len(), g.triangles.len());
    assert!(
        out.origin.windows(2).all(|w| w[0] <= w[1]),
        "origin ascends"
    );
    let mut pieces = vec![Vec::new(); input.triangles.len()];
    for (k, &t) in out.origin.iter().enumerate() {
        pieces[t as usize].push(k);
    }
    let mut added = 0;
    for (t, list) in pieces.iter().enumerate() {
        assert!(!list.is_empty(), "triangle {t} has no output");
        added += list.len() - 1;
        if list.len() == 1 {
            assert_eq!(g.triangles[list[0]], input.triangles[t], "untouched {t}");
        } else {
            check_pieces(input, g, t, list, expect);
        }
    }
    assert_eq!(added as u64, out.report.triangles_added);
    let left = find_intersections(g, frames);
    for &[a, b] in &left.pairs {
        let (a, b) = (out.origin[a as usize], out.origin[b as usize]);
        assert!(
            out.skipped.binary_search(&[a.min(b), a.max(b)]).is_ok(),
            "output pair from {a}, {b} crosses and was not counted as skipped"
        );
    }
    assert_eq!(out.skipped.len() as u64, out.report.pairs_skipped_sliver);
}

/// The per-piece checks of [`check`] for original triangle `t` split into `list`.
fn check_pieces(input: &Geometry, g: &Geometry, t: usize, list: &[usize], expect: &Expect) {
    let orig = input.triangles[t].map(|v| &input.vertices[v as usize]);
    let p = orig.map(local);
    let normal = (p[1] - p[0]).cross(p[2] - p[0]);
    let unit = normal.normalize();
    let diameter = (p[0] - p[1])
        .length()
        .max((p[1] - p[2]).length())
        .max((p[2] - p[0]).length());
    let mut area = 0.0;
    let mut rounding = 0.0;
    for &k in list {
        let v = g.triangles[k].map(|i| &g.vertices[i as usize]);
        for x in v {
            assert_eq!((x.material, x.node), (orig[0].material, orig[0].node));
        }
        let q = v.map(local);
        let cross = (q[1] - q[0]).cross(q[2] - q[0]);
        assert!(
            cross.dot(normal) > 0.0,
            "piece {k} of {t} keeps the winding"
        );
        area += cross.dot(unit) / 2.0;
        for (&i, x) in g.triangles[k].iter().zip(v) {
            if (i as usize) < input.vertices.len() {
                continue;
            }
            let magnitude = x.position.iter().fold(0.0f64, |m, c| m.max(c.abs() as f64));
            rounding += 3f64.sqrt() * 2f64.powi(-24) * magnitude * diameter;
            check_new_vertex(orig, p, x, expect);
        }
    }
    let expected = normal.length() / 2.0;
    assert!(
        (area - expected).abs() <= expect.area * expected + rounding,
        "triangle {t}: pieces cover {area}, the original {expected}"
    );
}

/// A new vertex lies in its origin triangle, with uv and normal interpolated from it.
fn check_new_vertex(orig: [&Vertex; 3], p: [DVec3; 3], x: &Vertex, expect: &Expect) {
    // Inside up to rounding (a few f32 steps of the coordinates; pieces of pieces round
    // again): the distance outside edge i is −λᵢ times the altitude onto it.
    let l = barycentric(p, local(x));
    let twice_area = (p[1] - p[0]).cross(p[2] - p[0]).length();
    let magnitude = p
        .iter()
        .chain([&local(x)])
        .fold(0.0f64, |m, q| m.max(q.abs().max_element()));
    for i in 0..3 {
        let altitude = twice_area / (p[(i + 1) % 3] - p[(i + 2) % 3]).length();
        let outside = -l[i] * altitude;
        let limit = 16.0 * 2f64.powi(-24) * magnitude;
        assert!(
            outside <= limit,
            "new vertex {outside} outside its triangle: {l:?}"
        );
    }
    let Some(tol) = expect.interpolation else {
        return;
    };
    let uv: [f64; 2] = [0, 1].map(|c| (0..3).map(|i| l[i] * orig[i].uv[c] as f64).sum::<f64>());
    for c in 0..2 {
        let close = (uv[c] - x.uv[c] as f64).abs() <= tol * (1.0 + uv[c].abs());
        assert!(close, "uv {:?} vs {uv:?}", x.uv);
    }
    let n: DVec3 = (0..3)
        .map(|i| DVec3::from(orig[i].normal.map(f64::from)) * l[i])
        .sum::<DVec3>()
        .normalize();
    let got = DVec3::from(x.normal.map(f64::from));
    assert!((got - n).abs().max_element() <= tol, "normal {got} vs {n}");
    assert!((got.length() - 1.0).abs() < 1e-6, "normal renormalised");
}

/// Adds an `n` × `n` grid of quads with shared vertices over the unit square of (u, v),
/// placed by `f`.
pub fn grid(
    g: &mut Geometry,
    n: usize,
    node: u32,
    material: u32,
    f: impl Fn(f32, f32) -> [f32; 3],
) {
    let base = g.vertices.len() as u32;
    for j in 0..=n {
        for i in 0..=n {
            let position = f(i as f32 / n as f32, j as f32 / n as f32);
            g.vertices.push(Vertex {
                position,
                normal: normal_at(position),
                uv: uv_at(position),
                material,
                node,
                tangent: [0.0; 4],
                uv1: [0.0; 2],
            });
        }
    }
    let at = |i: usize, j: usize| base + (j * (n + 1) + i) as u32;
    for j in 0..n {
        for i in 0..n {
            g.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            g.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
}

/// The T-junctions of `g`: (triangle, vertex) where the vertex, used by a triangle of the
/// same node and material (the same surface: two crossing surfaces meet along a line with
/// vertices of both on it), lies on an edge of the triangle strictly between its corners (to
/// within a few f32 steps).
pub fn t_junctions(g: &Geometry) -> Vec<(usize, usize)> {
    let mut surface = vec![None; g.vertices.len()];
    for tri in &g.triangles {
        for &v in tri {
            let x = &g.vertices[v as usize];
            surface[v as usize] = Some((x.node, x.material));
        }
    }
    let mut found = Vec::new();
    for (t, tri) in g.triangles.iter().enumerate() {
        let first = &g.vertices[tri[0] as usize];
        let here = Some((first.node, first.material));
        for k in 0..3 {
            let a = local(&g.vertices[tri[k] as usize]);
            let b = local(&g.vertices[tri[(k + 1) % 3] as usize]);
            let edge = b - a;
            let limit = 4.0 * 2f64.powi(-24) * a.abs().max(b.abs()).max_element();
            for (w, v) in g.vertices.iter().enumerate() {
                let x = local(v);
                if surface[w] != here || x == a || x == b {
                    continue;
                }
                let s = (x - a).dot(edge) / edge.length_squared();
                let off = (x - a - edge * s).length();
                if s > 0.0 && s < 1.0 && off <= limit {
                    found.push((t, w));
                }
            }
        }
    }
    found
}
