//! Precision: depth ties, sub-pixel triangles, far from the origin, extreme clip planes,
//! surfaces closer than f32 resolves.

use super::*;
use trisort_format::ProfileName;

/// Coplanar decals: where two opaque surfaces share a plane, the lower id is in front, so a
/// decal is visible only if its ids are lower than its base's. Left: decal before its base
/// (ids 0–1, base 2–3): the decal shows, every decal → base edge is a tie. Right: decal after
/// its base (base 4–5, decal 6–7): hidden. That holds exactly where the rasterized depths are
/// bit-equal: here, in the frontal frame, where the plane's depth is constant. Two oblique
/// frames follow, where triangles with different vertices in one plane z-fight at the last
/// bit (printed: the number of samples the later decal wins); every frame passes the rules.
#[test]
fn coplanar_decals_lower_id_in_front() {
    let dir = tempfile::tempdir().unwrap();
    let mut left = quad(-0.7, -0.3, -0.2, 0.2, -2.0);
    left.extend(quad(-1.9, -0.1, -1.0, 1.0, -2.0));
    let mut right = quad(0.1, 1.9, -1.0, 1.0, -2.0);
    right.extend(quad(0.3, 0.7, -0.2, 0.2, -2.0));
    let scene = glb(
        &[part(0, left), part(0, right)],
        &[Mat([0.8, 0.2, 0.2, 1.0])],
    );
    let path = path_toml(
        90.0,
        Some((0.1, 10.0)),
        &[
            (EYE0, [0.0, 0.0, -2.0]),
            ([0.7, 0.3, 0.0], [0.0, 0.0, -2.0]),
            ([-0.9, -0.2, 0.3], [0.0, 0.0, -2.0]),
        ],
    );
    let Some(b) = bake(dir.path(), "decal", &scene, &path, 48, 4) else {
        return;
    };
    let f0 = &b.rec.frames[0];
    assert!(
        f0.visible.contains(&0) && f0.visible.contains(&1),
        "decal with lower ids shows: {:?}",
        f0.visible
    );
    assert!(
        f0.visible.contains(&2) || f0.visible.contains(&3),
        "its base shows around it"
    );
    assert!(edge_weight(&b.rec, 0, &[0, 1], &[2, 3]) > 0, "decal → base");
    assert_eq!(
        edge_weight(&b.rec, 0, &[2, 3], &[0, 1]),
        0,
        "never base → decal"
    );
    for e in f0.edges.iter().filter(|e| e.from <= 1) {
        assert!(
            f0.ties.contains(e),
            "frontal view: decal → base is an exact depth tie: {e:?}"
        );
    }
    assert!(
        !f0.visible.contains(&6) && !f0.visible.contains(&7),
        "frontal view: a coplanar decal with higher ids than its base is hidden"
    );
    // Oblique views: the two quads' triangles are set up from different vertices, so their
    // interpolated depths may differ in the last bit and the decal can win some samples
    // (z-fighting). The recording follows the depth buffer sample by sample; the bake
    // reproduces it (the rules pass), whatever the geometry intended.
    for f in 1..b.rec.frames.len() {
        eprintln!(
            "frame {f}: decal after its base wins {} samples, decal before its base loses {}",
            edge_weight(&b.rec, f, &[6, 7], &[4, 5]),
            edge_weight(&b.rec, f, &[2, 3], &[0, 1])
        );
    }
    assert_verifies(dir.path(), "decal");
}

/// Pixel-space corner → world point on the plane z = −1 seen by the identity camera with
/// a 90° field of view at `size`².
fn px_to_world(p: [f64; 2], size: u32) -> [f32; 3] {
    let s = size as f64;
    [
        (p[0] / s * 2.0 - 1.0) as f32,
        (1.0 - p[1] / s * 2.0) as f32,
        -1.0,
    ]
}

/// Signed distances (pixels) of `q` from the three edges of `t`, positive inside.
fn edge_distances(t: &[[f64; 2]; 3], q: [f64; 2]) -> [f64; 3] {
    let area =
        (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
    let sign = area.signum();
    let mut d = [0.0; 3];
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        d[k] = sign * ((b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0])) / len;
    }
    d
}

/// Sub-pixel triangles: 256 opaque triangles with legs of 0.3–0.95 px in front of a background, one per
/// 2×2-pixel cell at a pseudo-random place. At the standard sample positions (1×: the pixel
/// centre; 4×: (⅜,⅛), (⅞,⅜), (⅛,⅝), (⅝,⅞)), every triangle that contains a sample with a
/// margin of 0.02 px (beyond the rasterizer's sub-pixel snapping) must be in V_f, and every
/// triangle that misses all samples by that margin must have no fragment (not in G). Sampled
/// ones are never lost; unsampled ones cost nothing.
#[test]
fn sub_pixel_triangles_covering_a_sample_are_never_lost() {
    let dir = tempfile::tempdir().unwrap();
    let size = 32u32;
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut tiny_px = vec![];
    for cy in 0..size / 2 {
        for cx in 0..size / 2 {
            let scale = 0.3 + 0.65 * rnd();
            let (ox, oy) = (
                cx as f64 * 2.0 + 0.05 + 0.95 * rnd(),
                cy as f64 * 2.0 + 0.05 + 0.95 * rnd(),
            );
            let t: [[f64; 2]; 3] = [
                [ox, oy],
                [ox + scale, oy + scale * 0.3 * rnd()],
                [ox + scale * 0.3 * rnd(), oy + scale],
            ];
            tiny_px.push(t);
        }
    }
    let background = quad(-3.0, 3.0, -3.0, 3.0, -2.0); // ids 0, 1
    let tiny: Vec<[[f32; 3]; 3]> = tiny_px
        .iter()
        .map(|t| t.map(|p| px_to_world(p, size)))
        .collect();
    let scene = glb(
        &[part(0, background), part(1, tiny)],
        &[Mat([0.2, 0.2, 0.2, 1.0]), Mat([0.9, 0.9, 0.1, 1.0])],
    );
    let path = path_toml(90.0, Some((0.1, 10.0)), &[(EYE0, AHEAD)]);
    for (samples, pattern) in [
        (1u32, vec![[0.5, 0.5]]),
        (
            4,
            vec![
                [0.375, 0.125],
                [0.875, 0.375],
                [0.125, 0.625],
                [0.625, 0.875],
            ],
        ),
    ] {
        let name = format!("subpixel{samples}");
        let Some(b) = bake(dir.path(), &name, &scene, &path, size, samples) else {
            return;
        };
        let visible = set(&b.rec.frames[0].visible);
        let (mut sure_in, mut sure_out) = (0, 0);
        for (k, t) in tiny_px.iter().enumerate() {
            let id = 2 + k as u32;
            let mut covers = false;
            let mut near = false;
            for py in 0..size {
                for px in 0..size {
                    for s in &pattern {
                        let d = edge_distances(t, [px as f64 + s[0], py as f64 + s[1]]);
                        let min = d.iter().cloned().fold(f64::INFINITY, f64::min);
                        covers |= min >= 0.02;
                        near |= min > -0.02;
                    }
                }
            }
            if covers {
                sure_in += 1;
                assert!(
                    visible.contains(&id),
                    "{samples}x: triangle {id} covers a sample but is not in V_0"
                );
            } else if !near {
                sure_out += 1;
                assert!(
                    !b.rec.unique_visible.contains(&id),
                    "{samples}x: triangle {id} misses every sample but is in G"
                );
            }
        }
        eprintln!(
            "{samples}x: {sure_in} triangles surely sampled, {sure_out} surely missed, of {}",
            tiny_px.len()
        );
        assert!(
            sure_in >= 20 && sure_out >= 20,
            "the scene tests both sides: {sure_in} in, {sure_out} out"
        );
        assert_verifies(dir.path(), &name);
    }
}

/// A scene and camera 10⁶ units from the origin record exactly what they record at the
/// origin: the same V_f, C_f, edges, ties and layers, and the same sorted copies and draws.
/// Node matrices are composed with the camera in f64 and cast once, so the camera-relative
/// positions the GPU sees are the same as at the origin (f32 world positions would be
/// quantized to 1/16 unit there).
#[test]
fn far_from_the_origin_records_what_the_origin_records() {
    let dir = tempfile::tempdir().unwrap();
    let mats = [Mat([0.2, 0.5, 0.9, 1.0]), Mat([0.9, 0.4, 0.1, 0.5])];
    let eyes = [
        [0.0, 0.0, 4.0],
        [2.5, 1.0, 3.0],
        [-3.0, -0.5, 2.0],
        [0.5, 2.5, 3.5],
    ];
    let mut results = vec![];
    for (name, off) in [("origin", 0.0), ("far", 1.0e6)] {
        let o = [off; 3];
        let scene = glb(&layered_parts(o), &mats);
        let keys: Vec<_> = eyes
            .iter()
            .map(|e| ([e[0] + off, e[1] + off, e[2] + off], [off, off, off - 0.3]))
            .collect();
        let path = path_toml(50.0, Some((0.5, 20.0)), &keys);
        let Some(b) = bake(dir.path(), name, &scene, &path, 48, 4) else {
            return;
        };
        assert_verifies(dir.path(), name);
        results.push(b);
    }
    let (a, b) = (&results[0], &results[1]);
    assert!(
        a.rec.frames.iter().all(|f| !f.edges.is_empty()),
        "a scene with edges"
    );
    assert_eq!(a.rec.unique_visible, b.rec.unique_visible);
    for (fa, fb) in a.rec.frames.iter().zip(&b.rec.frames) {
        assert_eq!(
            fa, fb,
            "frame {} differs 10⁶ units from the origin",
            fa.frame
        );
    }
    assert_eq!(a.baked.copies, b.baked.copies);
    assert_eq!(a.baked.draws, b.baked.draws);
}

/// znear = 10⁻³ and zfar = 10⁶ (a ratio of 10⁹) with a standard [0, 1] f32 depth: pairs of
/// opaque strips at distance z and z + Δz, the farther strip with the lower ids, one pair per
/// image column. Depth is d = far/(far−near)·(1 − near/z), so the pair's depths differ by
/// ≈ near·Δz/z², and f32 resolves that only where it exceeds the spacing of floats below 1
/// (2⁻²⁴ ≈ 6·10⁻⁸): Δz ≳ limit(z) = 2⁻²⁴·z²/near (6·10⁻⁵ at z = 1, 0.6 at z = 100 for
/// near = 10⁻³). Pairs 16× above the limit must be ordered by distance (the nearer strip
/// visible, the farther hidden); pairs 1000× below it are an exact depth tie, and the
/// recording follows the depth buffer, not the geometry: the lower id, the farther strip,
/// shows. Between, the outcome depends on rounding (printed; on lavapipe: ordered at ≥ 1× the
/// limit at z = 1 and 100 and at 0.25× at z = 0.01, tied at 0.25× at z = 1 and 100). No
/// reversed Z: the limit is that of a standard f32 depth buffer. Recorder, player and
/// reference compare the same f32 depths, so the bake stays exact either way (verify
/// --scene passes in every mode).
#[test]
fn extreme_clip_planes_order_what_f32_depth_resolves() {
    let dir = tempfile::tempdir().unwrap();
    let (near, far) = (1.0e-3, 1.0e6);
    let limit = |z: f64| 2f64.powi(-24) * z * z / near;
    let distances = [0.01f64, 1.0, 100.0];
    let factors = [16.0, 4.0, 1.0, 0.25, 1.0e-3];
    let mut parts = vec![];
    let mut pairs = vec![]; // (z, factor, far ids, near ids)
    let columns = distances.len() * factors.len();
    for &z in &distances {
        for &factor in &factors {
            let column = pairs.len();
            let dz = limit(z) * factor;
            // Column k of the image at distance z (90° field of view: half-width z).
            let x0 = (-1.0 + 2.0 * column as f64 / columns as f64) * z;
            let x1 = (-1.0 + 2.0 * (column + 1) as f64 / columns as f64) * z;
            let first = 2 * parts.len() as u32;
            for depth in [z + dz, z] {
                parts.push(part(
                    0,
                    quad(
                        x0 as f32,
                        x1 as f32,
                        (-0.5 * z) as f32,
                        (0.5 * z) as f32,
                        -depth as f32,
                    ),
                ));
            }
            pairs.push((z, factor, [first, first + 1], [first + 2, first + 3]));
        }
    }
    let scene = glb(&parts, &[Mat([0.5, 0.5, 0.5, 1.0])]);
    let path = path_toml(90.0, Some((near, far)), &[(EYE0, AHEAD)]);
    let Some(b) = bake(dir.path(), "clip", &scene, &path, 60, 1) else {
        return;
    };
    assert_verifies(dir.path(), "clip");
    let vis = set(&b.rec.frames[0].visible);
    for (z, factor, far_ids, near_ids) in pairs {
        let shows = |ids: [u32; 2]| ids.iter().any(|t| vis.contains(t));
        eprintln!(
            "znear {near:e}, zfar {far:e}: z = {z}, Δz = {:.3e} ({factor}x the limit): nearer strip visible {}, farther strip visible {}",
            limit(z) * factor,
            shows(near_ids),
            shows(far_ids)
        );
        assert!(
            shows(near_ids) != shows(far_ids),
            "z = {z}, {factor}x: one opaque strip hides the other"
        );
        if factor >= 16.0 {
            assert!(
                shows(near_ids),
                "z = {z}, {factor}x the limit: f32 depth resolves it, the nearer strip must show"
            );
        }
        if factor <= 1.0e-3 {
            assert!(
                shows(far_ids),
                "z = {z}, {factor}x the limit: a depth tie, the lower id (farther strip) shows"
            );
        }
    }
}

/// Two surfaces 10⁻⁵ apart at distance 10⁴: below f32 resolution there (one float step at
/// 10⁴ is ≈ 10⁻³), both transparent, the nearer one with the higher ids. The camera-relative
/// transform rounds both to the same depth, so every sample is an exact tie and the lower id
/// (the farther surface) is in front: every edge between them goes lower → higher and is a
/// tie. The baked order follows it and the graph rules pass; the player draws that order
/// (blend: reversed, so the lower id lands on top) and the reference peels the same ties:
/// `verify --scene` passes in every mode. Physically the nearer surface should win; no f32
/// pipeline can tell them apart, and all three agree on the same answer.
#[test]
fn surfaces_closer_than_f32_resolution_tie_by_id() {
    let dir = tempfile::tempdir().unwrap();
    let mut far_part = part(0, quad(-1000.0, 1000.0, -1000.0, 1000.0, -1.0e-5));
    far_part.translation = [0.0, 0.0, -1.0e4];
    let mut near_part = part(1, quad(-1000.0, 1000.0, -1000.0, 1000.0, 0.0));
    near_part.translation = [0.0, 0.0, -1.0e4];
    let scene = glb(
        &[far_part, near_part],
        &[Mat([0.9, 0.1, 0.1, 0.5]), Mat([0.1, 0.1, 0.9, 0.5])],
    );
    let path = path_toml(
        5.0,
        Some((1.0, 2.0e4)),
        &[(EYE0, AHEAD), ([30.0, -20.0, 0.0], [0.0, 0.0, -1.0e4])],
    );
    let Some(b) = bake(dir.path(), "sub_f32", &scene, &path, 32, 4) else {
        return;
    };
    assert_verifies(dir.path(), "sub_f32");
    for f in &b.rec.frames {
        assert_eq!(
            f.visible,
            vec![0, 1, 2, 3],
            "frame {}: both transparent surfaces visible",
            f.frame
        );
        let across: Vec<_> = f
            .edges
            .iter()
            .filter(|e| (e.from < 2) != (e.to < 2))
            .collect();
        assert!(!across.is_empty());
        for e in across {
            assert!(
                e.from < 2,
                "frame {}: the lower id is in front: {e:?}",
                f.frame
            );
            assert!(
                f.ties.contains(e),
                "frame {}: an exact depth tie: {e:?}",
                f.frame
            );
        }
    }
    // The baked order puts the far surface's copies before the near one's in every frame.
    for f in 0..b.baked.frames.len() {
        let order: Vec<u32> = b
            .baked
            .frame_draws(f)
            .iter()
            .flat_map(|d| {
                b.baked.copies
                    [(d.first_index / 3) as usize..((d.first_index + d.index_count) / 3) as usize]
                    .to_vec()
            })
            .map(|c| b.baked.scene_ids[c as usize])
            .collect();
        let last_far = order.iter().rposition(|&t| t < 2).unwrap();
        let first_near = order.iter().position(|&t| t >= 2).unwrap();
        assert!(last_far < first_near, "frame {f}: {order:?}");
    }
}

/// The tie rule (`recorder/src/tie_rule/`: neighbours in one plane go lower id first) with the
/// default raster profile (conformant: the recorded pattern and every sample moved by up to its
/// tolerance): three scenes whose surfaces the rasterizer's depths cannot order verify exact
/// in every mode, with no unordered sample:
/// - a transparent decal on an opaque panel, in one plane, seen obliquely (their interpolated
///   depths cross in the last bit): the decal comes first in the file, so it is on top;
/// - transparent sheets 10⁻⁴ apart under a near plane of 10⁻⁴ and a far plane of 10⁵, where
///   f32 depth ties them: the sheet on the eye's side of the other's plane comes first;
/// - a transparent door touching its opaque frame along the hinge, open at 20°, seen across
///   the hinge: the two share an edge, and near it their depths cross in the last bits.
#[test]
fn ties_verify_exact_in_every_mode_with_the_default_profile() {
    let dir = tempfile::tempdir().unwrap();
    let red = Mat([0.9, 0.2, 0.1, 1.0]);
    let glass = Mat([0.1, 0.3, 0.9, 0.5]);
    let decal = glb(
        &[
            part(1, quad(-0.4, 0.4, -0.3, 0.3, -2.0)),
            part(0, quad(-1.5, 1.5, -1.0, 1.0, -2.0)),
        ],
        &[red, glass],
    );
    let oblique = |d: f64| {
        path_toml(
            70.0,
            Some((0.1, 10.0)),
            &[
                ([0.9 * d, 0.4 * d, 0.0], [0.0, 0.0, -2.0]),
                ([-0.7 * d, -0.3 * d, 0.2 * d], [0.0, 0.0, -2.0]),
            ],
        )
    };
    let mut sheets = vec![part(0, quad(-2.0, 2.0, -2.0, 2.0, -2.5))];
    for k in 0..3 {
        let dz = -2.0 + 1.0e-4 * k as f32;
        let x = -0.5 + 0.3 * k as f32;
        sheets.push(part(1, quad(x, x + 0.8, -0.5, 0.5, dz)));
    }
    let sheets = glb(&sheets, &[red, glass]);
    let far_clip = path_toml(
        60.0,
        Some((1.0e-4, 1.0e5)),
        &[
            ([0.6, 0.3, 0.0], [0.0, 0.0, -2.0]),
            ([-0.4, -0.2, 0.0], [0.0, 0.0, -2.0]),
        ],
    );
    // The frame: a panel in z = −2 left of the hinge (x = 0); the door: a panel from the hinge
    // swung 20° towards the eye.
    let (c, s) = (20f32.to_radians().cos(), 20f32.to_radians().sin());
    let door_far = [0.9 * c, 0.0, -2.0 + 0.9 * s];
    let door = vec![
        [
            [0.0, -0.6, -2.0],
            [door_far[0], -0.6, door_far[2]],
            [door_far[0], 0.6, door_far[2]],
        ],
        [
            [0.0, -0.6, -2.0],
            [door_far[0], 0.6, door_far[2]],
            [0.0, 0.6, -2.0],
        ],
    ];
    let hinge = glb(
        &[part(0, quad(-1.0, 0.0, -0.6, 0.6, -2.0)), part(1, door)],
        &[red, glass],
    );
    let across = path_toml(
        60.0,
        Some((0.1, 10.0)),
        &[
            ([-1.2, 0.2, -0.3], [0.2, 0.0, -2.0]),
            ([1.4, -0.3, -0.6], [-0.1, 0.0, -2.0]),
        ],
    );
    for (name, scene, path) in [
        ("tie_decal", &decal, oblique(1.0)),
        ("tie_clip", &sheets, far_clip),
        ("tie_hinge", &hinge, across),
    ] {
        let extra = ["--raster-profile", "conformant"];
        let Some(b) = bake_with(dir.path(), name, scene, &path, 64, 4, &extra) else {
            return;
        };
        assert_eq!(
            b.baked.settings.robust.profile.name,
            ProfileName::Conformant
        );
        let removed: u64 = b
            .baked
            .removed_edges
            .iter()
            .flatten()
            .map(|e| e.weight as u64)
            .sum();
        assert_eq!(removed, 0, "{name}: no unordered sample");
        let blend = assert_verifies(dir.path(), name);
        for f in blend["frames"].as_array().unwrap() {
            assert!(f["max_channel_diff"].as_u64().unwrap() <= 1, "{name}: {f}");
            assert_eq!(f["unordered_samples"], 0, "{name}: {f}");
        }
    }
}
