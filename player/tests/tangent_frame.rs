//! The tangent frame a normal map is read in (real renders on the test GPU): a mirroring node
//! mirrors the shading and nothing else, a `KHR_texture_transform` that turns or mirrors the
//! normal texture turns its normals with it, and a double-sided back face reverses the mapped
//! normal whole.

use glam::{DMat4, DVec3};
use trisort_format::{Baked, Node, Sun};
use trisort_testkit::gpu;

use crate::shading::{flat_texture, max_diff, pbr, slot, textured, with};
use crate::support::SIZE;

/// The tangent-space normal (x, y) the maps below encode, z from unit length.
const TILT: [f64; 2] = [-0.5, 0.5];

/// A linear normal texture of one tangent-space normal `xy` (z from unit length).
fn normal_texel(xy: [f64; 2]) -> [u8; 4] {
    let z = (1.0 - xy[0] * xy[0] - xy[1] * xy[1]).max(0.0).sqrt();
    let byte = |c: f64| ((c * 0.5 + 0.5) * 255.0).round() as u8;
    [byte(xy[0]), byte(xy[1]), byte(z), 255]
}

/// [`textured`]'s grey quad with a normal map of the one normal `xy`.
fn mapped(xy: [f64; 2]) -> Baked {
    with(&textured(), |b| {
        b.geometry.textures = vec![flat_texture(normal_texel(xy), 4, false)];
        b.geometry.materials[2].normal_texture = slot(0);
    })
}

/// An RGBA8 image `SIZE` wide mirrored left to right.
fn mirrored_image(rgba8: &[u8]) -> Vec<u8> {
    let row = (SIZE * 4) as usize;
    rgba8
        .chunks(row)
        .flat_map(|r| r.chunks(4).rev().flatten().copied().collect::<Vec<u8>>())
        .collect()
}

#[test]
fn a_mirrored_node_draws_its_normal_map_mirrored() {
    let Some(gpu) = gpu() else { return };
    // Light symmetric under x → −x: the uniform environment and a sun in the y-z plane.
    let plain = with(&mapped(TILT), |b| {
        b.environment.sun = Some(Sun {
            direction: [0.0, 0.6, 1.0],
            color: [2.0, 2.0, 2.0],
        });
    });
    // The same quad (the whole view) under a node that mirrors x, stored as the importer
    // stores a mirrored instance: local attributes, reversed winding.
    let twin = with(&plain, |b| {
        let g = &mut b.geometry;
        g.nodes.push(Node {
            name: "mirror".into(),
            parent: None,
            rest: DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)).to_cols_array(),
        });
        for v in g.vertices.iter_mut().filter(|v| v.material == 2) {
            v.node = 1;
        }
        reverse_winding(g, 2);
    });
    let image = pbr(&gpu, &plain);
    let d = max_diff(&pbr(&gpu, &twin), &mirrored_image(&image));
    assert!(
        d <= 1,
        "the mirrored twin is {d}/255 off the mirrored image"
    );
    // The check can fail: the map's y reversed (what a reversed bitangent draws) shows.
    let flipped = with(&plain, |b| {
        b.geometry.textures = vec![flat_texture(normal_texel([TILT[0], -TILT[1]]), 4, false)];
    });
    let d = max_diff(&pbr(&gpu, &flipped), &image);
    assert!(d >= 8, "the map's y changes the image by only {d}/255");
}

/// `xy` (x along +u, y along −v) of a map pre-turned for a slot transform whose linear part is
/// `[[a, b], [c, d]]` (u' = a·u + b·v, v' = c·u + d·v), where that part is orthogonal: the
/// normal the transformed map shows at uv is the one the untransformed map has there.
fn pre_turned(m: [[f32; 3]; 2], xy: [f64; 2]) -> [f64; 2] {
    // The linear part in the (u, −v) frame the normal's xy lives in.
    let (a, b, c, d) = (
        m[0][0] as f64,
        -m[0][1] as f64,
        -m[1][0] as f64,
        m[1][1] as f64,
    );
    [a * xy[0] + b * xy[1], c * xy[0] + d * xy[1]]
}

#[test]
fn a_texture_transform_turns_the_normal_map_s_frame() {
    let Some(gpu) = gpu() else { return };
    let plain = pbr(&gpu, &mapped(TILT));
    // (rotation, scale, offset, tolerance): a quarter turn and a mirroring scale keep the
    // 8-bit texel exact; any other angle rounds it.
    let cases = [
        (std::f32::consts::FRAC_PI_2, [1.0, 1.0], [0.0, 0.0], 1),
        (0.0, [-1.0, 1.0], [0.3, 0.0], 1),
        (0.7, [1.0, 1.0], [0.1, 0.2], 2),
        (-2.3, [1.0, -1.0], [0.0, 0.5], 2),
    ];
    for (rotation, scale, offset, tolerance) in cases {
        let slot_of = |b: &mut Baked, scale: [f32; 2], xy: [f64; 2]| {
            let t = b.geometry.materials[2].normal_texture.as_mut().unwrap();
            t.transform.rotation = rotation;
            t.transform.scale = scale;
            t.transform.offset = offset;
            let m = t.transform.matrix();
            let xy = pre_turned(m, xy);
            b.geometry.textures = vec![flat_texture(normal_texel(xy), 4, false)];
        };
        let turned = with(&mapped(TILT), |b| slot_of(b, scale, TILT));
        let d = max_diff(&pbr(&gpu, &turned), &plain);
        assert!(
            d <= tolerance,
            "rotation {rotation}, scale {scale:?}: {d}/255 from the untransformed map"
        );
        // Scale only tiles: a non-uniform one on top draws the same normals.
        let stretched = with(&turned, |b| {
            let m = b.geometry.materials[2].normal_texture.as_mut().unwrap();
            m.transform.scale = [scale[0] * 3.0, scale[1] * 0.5];
        });
        let d = max_diff(&pbr(&gpu, &stretched), &plain);
        assert!(
            d <= tolerance,
            "rotation {rotation}, scale {scale:?} × (3, 0.5): {d}/255 from the untransformed map"
        );
    }
    // The check can fail: the quarter-turned texel read unturned is another normal.
    let unturned = with(&mapped(TILT), |b| {
        b.geometry.textures = vec![flat_texture(normal_texel([-TILT[1], TILT[0]]), 4, false)];
    });
    let d = max_diff(&pbr(&gpu, &unturned), &plain);
    assert!(d >= 8, "a turned normal changes the image by only {d}/255");
}

#[test]
fn a_double_sided_back_face_reverses_the_mapped_normal() {
    let Some(gpu) = gpu() else { return };
    // The quad's front faces away (normal −Z, clockwise from the camera), double-sided, tangent
    // +X: from the camera its back shows, whose normal is minus the front's mapped normal.
    let back = with(&mapped(TILT), |b| {
        let g = &mut b.geometry;
        g.materials[2].double_sided = true;
        for v in g.vertices.iter_mut().filter(|v| v.material == 2) {
            v.normal = [0.0, 0.0, -1.0];
            v.tangent = [1.0, 0.0, 0.0, 1.0];
        }
        reverse_winding(g, 2);
    });
    // −(t·x + b·y + n·z) with t = +X, b = cross(−Z, +X) = −Y, n = −Z is (−x, y, z): a
    // front face with normal +Z, tangent −X and handedness −1 (b = +Y) maps to the same.
    let front = with(&mapped(TILT), |b| {
        for v in b.geometry.vertices.iter_mut().filter(|v| v.material == 2) {
            v.tangent = [-1.0, 0.0, 0.0, -1.0];
        }
    });
    let d = max_diff(&pbr(&gpu, &back), &pbr(&gpu, &front));
    assert!(d <= 1, "the back face is {d}/255 off its front-facing twin");
    // The check can fail: the sun (from +X) tells the map's x from its mirror.
    let d = max_diff(&pbr(&gpu, &front), &pbr(&gpu, &mapped(TILT)));
    assert!(d >= 8, "the map's x changes the image by only {d}/255");
}

/// Reverses the winding of material `material`'s triangles in `g` (as the importer does for a
/// mirrored instance, or to turn a face around).
fn reverse_winding(g: &mut trisort_format::Geometry, material: u32) {
    let vertices = &g.vertices;
    for t in g
        .triangles
        .iter_mut()
        .filter(|t| vertices[t[0] as usize].material == material)
    {
        t.swap(1, 2);
    }
}
