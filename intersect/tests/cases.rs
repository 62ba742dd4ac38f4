//! Hand-built crossings, touches and ties with known answers.

use glam::{DMat4, DVec3};
use trisort_format::Geometry;
use trisort_intersect::{
    find_intersections, rigid_groups, split_intersections, SplitOptions, SplitScene,
};

use crate::common::{
    check, frame, geometry, grid, irregular_pair, node, one_node, pose, quad, t_junctions, tri,
    x_quads, Expect, X_QUAD_A, X_QUAD_B,
};

/// Both triangles of each crossing pair cut (the default cuts one): these cases check the
/// cuts on both sides.
fn both_sides() -> SplitOptions {
    SplitOptions {
        cut_both_sides: true,
        ..SplitOptions::default()
    }
}

fn split(g: &Geometry) -> SplitScene {
    split_intersections(g, &[], &both_sides())
}

/// One node holding triangle `a` (material 0) and triangle `b` (material 1), and the split of
/// both sides.
fn two_triangles(a: [[f32; 3]; 3], b: [[f32; 3]; 3]) -> (Geometry, SplitScene) {
    let mut g = one_node();
    tri(&mut g, a, 0, 0);
    tri(&mut g, b, 0, 1);
    let out = split(&g);
    (g, out)
}

/// Exact where the cut points are representable in f32.
const EXACT: Expect = Expect {
    area: 1e-9,
    interpolation: Some(1e-6),
};

/// Where they are not: the pieces' total area moves by the rounding of the new vertices.
const ROUNDED: Expect = Expect {
    area: 1e-9,
    interpolation: Some(1e-5),
};

/// Nothing crossing: the same geometry back, byte for byte, and nothing reported.
fn assert_untouched(g: &Geometry, out: &SplitScene) {
    assert_eq!(out.geometry, *g);
    assert_eq!(
        bytemuck::cast_slice::<_, u8>(&out.geometry.vertices),
        bytemuck::cast_slice::<_, u8>(&g.vertices)
    );
    assert_eq!(
        out.origin,
        (0..g.triangles.len() as u32).collect::<Vec<_>>()
    );
    assert_eq!(out.report.pairs_split, 0);
    assert_eq!(out.report.triangles_added, 0);
    assert_eq!(out.report.rounds, 0);
    assert!(out.skipped.is_empty());
}

#[test]
fn x_quads_are_split_along_their_crossing_and_cross_no_more() {
    let mut g = one_node();
    x_quads(&mut g, 0, |p| p);
    let before = find_intersections(&g, &[]);
    assert!(before.pairs.len() >= 2, "{:?}", before.pairs);
    let out = split(&g);
    check(&g, &[], &out, &EXACT);
    assert_eq!(out.report.pairs_split, before.pairs.len() as u64);
    assert_eq!(out.report.pairs_skipped_sliver, 0);
    assert_eq!(
        out.report.triangles_split, 4,
        "every triangle crosses the other quad"
    );
    assert!(out.report.triangles_added >= 4);
    assert!(find_intersections(&out.geometry, &[]).pairs.is_empty());
    // Every cut point is on the line x = z = 0, and the pieces are on one side of it.
    for v in &out.geometry.vertices[g.vertices.len()..] {
        assert_eq!((v.position[0], v.position[2]), (0.0, 0.0), "{v:?}");
    }
    for t in &out.geometry.triangles {
        let xs = t.map(|i| out.geometry.vertices[i as usize].position[0]);
        assert!(xs.iter().all(|&x| x <= 0.0) || xs.iter().all(|&x| x >= 0.0));
    }
}

#[test]
fn irregular_crossing_interpolates_at_rounded_cut_points() {
    let mut g = one_node();
    irregular_pair(&mut g, 0, |p| p);
    let out = split(&g);
    assert_eq!(out.report.pairs_split, 1);
    assert_eq!(out.report.triangles_split, 2);
    check(&g, &[], &out, &ROUNDED);
    assert!(find_intersections(&out.geometry, &[]).pairs.is_empty());
}

#[test]
fn a_pierced_triangle_is_split_with_the_piercing_one() {
    let (g, out) = two_triangles(
        [[-2.0, 0.0, 2.0], [2.0, 0.0, 2.0], [0.0, 0.0, -2.0]],
        [[-0.2, -0.5, 0.0], [0.2, -0.5, 0.0], [0.0, 0.5, 0.1]],
    );
    assert_eq!(out.report.pairs_split, 1);
    assert_eq!(out.report.triangles_split, 2);
    check(&g, &[], &out, &ROUNDED);
    assert!(find_intersections(&out.geometry, &[]).pairs.is_empty());
}

#[test]
fn coplanar_overlap_is_a_tie_and_left_alone() {
    let (g, out) = two_triangles(
        [[-1.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 0.0, -1.0]],
        [[-0.5, 0.0, 2.0], [0.5, 0.0, 2.0], [0.0, 0.0, -0.5]],
    );
    assert_untouched(&g, &out);
    assert_eq!(out.report.pairs_below_precision, 0);
}

#[test]
fn touching_at_an_edge_or_a_vertex_is_not_crossing() {
    let floor = [[-2.0, 0.0, 2.0], [2.0, 0.0, 2.0], [0.0, 0.0, -2.0]];
    let touches: [[[f32; 3]; 3]; 4] = [
        // Standing on the floor: an edge in the floor's interior (a T-junction).
        [[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, 1.0, 0.0]],
        // Resting on one vertex.
        [[0.0, 0.0, 0.0], [0.5, 1.0, 0.0], [-0.5, 1.0, 0.3]],
        // Sharing an edge, folded up.
        [[2.0, 0.0, 2.0], [-2.0, 0.0, 2.0], [0.0, 1.0, 3.0]],
        // Hanging below, touching the floor's edge at one point with its vertex.
        [[0.0, 0.0, 2.0], [0.3, -1.0, 2.5], [-0.3, -1.0, 1.5]],
    ];
    for (k, other) in touches.into_iter().enumerate() {
        let mut g = one_node();
        tri(&mut g, floor, 0, 0);
        tri(&mut g, other, 0, 1);
        let out = split(&g);
        assert_untouched(&g, &out);
        assert_eq!(out.report.pairs_below_precision, 0, "case {k}");
    }
}

/// Two crossing quads on nodes 1 and 2 (children of the root), over `frames`.
fn two_nodes(frames: &[trisort_format::FrameState]) -> (Geometry, SplitScene) {
    let mut g = geometry(vec![
        node("root", None, DMat4::IDENTITY),
        node("a", Some(0), DMat4::from_translation(DVec3::X)),
        node("b", Some(0), DMat4::from_translation(DVec3::X)),
    ]);
    quad(&mut g, X_QUAD_A, 1, 0);
    quad(&mut g, X_QUAD_B, 2, 1);
    let out = split_intersections(&g, frames, &both_sides());
    (g, out)
}

/// Nodes moving relative to each other are two groups: their crossing at the first frame is
/// split by the pass across groups (as posed there), not by the pass within groups, and the
/// pieces cross no more; without that pass they are left alone.
#[test]
fn nodes_moving_relative_to_each_other_are_split_as_the_first_frame_poses_them() {
    let moved = DMat4::from_translation(DVec3::new(1.0, 0.5, 0.0));
    let frames = [frame(vec![]), frame(vec![pose(2, moved)])];
    let (g, out) = two_nodes(&frames);
    assert_eq!(out.report.groups, 2);
    assert_eq!(out.report.pairs_split, 0, "nothing crosses within a group");
    assert!(
        out.report.pairs_split_across_groups >= 2,
        "{:?}",
        out.report
    );
    check(&g, &frames, &out, &EXACT);
    let again = split_intersections(&out.geometry, &frames, &both_sides());
    assert_eq!(again.report.pairs_split_across_groups, 0);
    assert_eq!(again.report.triangles_added, 0);
    let within_only = SplitOptions {
        across_groups: false,
        ..both_sides()
    };
    assert_untouched(&g, &split_intersections(&g, &frames, &within_only));
}

#[test]
fn nodes_static_relative_to_each_other_are_split() {
    let moved = DMat4::from_translation(DVec3::new(1.0, 0.5, 0.0));
    let held = DMat4::from_translation(DVec3::new(1.0, 0.0, 0.25));
    let cases = [
        // No animation at all.
        vec![frame(vec![]), frame(vec![])],
        // Both moved the same way.
        vec![frame(vec![]), frame(vec![pose(1, moved), pose(2, moved)])],
        // One held away from its rest pose, the same on every frame.
        vec![frame(vec![pose(2, held)]), frame(vec![pose(2, held)])],
    ];
    for frames in cases {
        let (g, out) = two_nodes(&frames);
        let groups = rigid_groups(&g, &frames);
        assert_eq!(groups[1], groups[2]);
        assert!(out.report.pairs_split >= 2);
        check(&g, &frames, &out, &EXACT);
        assert!(find_intersections(&out.geometry, &frames).pairs.is_empty());
    }
}

#[test]
fn a_mirrored_node_keeps_the_winding() {
    let mirror = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
    let mut g = geometry(vec![node("mirrored", None, mirror)]);
    irregular_pair(&mut g, 0, |p| p);
    x_quads(&mut g, 0, |p| [p[0] + 5.0, p[1], p[2]]);
    let out = split(&g);
    assert_eq!(out.report.triangles_split, 6);
    // `check` compares each piece's winding with its origin's in the node's local space; the
    // world space has the same transform, negative determinant and all.
    check(&g, &[], &out, &ROUNDED);
}

#[test]
fn huge_coordinates() {
    // Local coordinates near 1e6 (f32 steps of 1/16), crossing by hundreds of units.
    let mut g = one_node();
    x_quads(&mut g, 0, |p| p.map(|c| 1e6 + 250.0 * c));
    irregular_pair(&mut g, 0, |p| p.map(|c| 1e6 + 300.0 * c + 1000.0));
    let out = split(&g);
    // The X has two crossing pairs (its halves meet at one point), the irregular pair one.
    assert_eq!(out.report.pairs_split, 3);
    // Uv values here are near 5e5 (an affine function of the position), where f32 steps
    // are 1/32; the 1/16 position steps move the interpolation weights by ~2.5e-4.
    let coarse = Expect {
        area: 1e-9,
        interpolation: Some(1e-3),
    };
    check(&g, &[], &out, &coarse);
    assert!(find_intersections(&out.geometry, &[]).pairs.is_empty());

    // A node translated by 1e6 with unit-sized local coordinates: exact as at the origin.
    let far = DMat4::from_translation(DVec3::splat(1e6));
    let mut g = geometry(vec![node("far", None, far)]);
    x_quads(&mut g, 0, |p| p);
    let out = split(&g);
    assert_eq!(out.report.triangles_split, 4);
    check(&g, &[], &out, &EXACT);

    // Crossing by less than f32 can resolve at 1e6 (a 0.5-unit X): below precision.
    let mut g = one_node();
    x_quads(&mut g, 0, |p| p.map(|c| 1e6 + 0.25 * c));
    let out = split(&g);
    assert_untouched(&g, &out);
    assert!(out.report.pairs_below_precision >= 2);
}

#[test]
fn tiny_triangles() {
    let mut g = one_node();
    x_quads(&mut g, 0, |p| p.map(|c| c * 1e-4));
    irregular_pair(&mut g, 0, |p| p.map(|c| c * 1e-5 + 0.01));
    let out = split(&g);
    assert_eq!(out.report.pairs_split, 3);
    assert_eq!(out.report.triangles_split, 6);
    check(&g, &[], &out, &ROUNDED);
    assert!(find_intersections(&out.geometry, &[]).pairs.is_empty());
}

#[test]
fn slivers_are_skipped_and_counted() {
    // Each pokes through the other by 1e-4 near a corner: every cut makes a piece of about
    // 1e-8 of its triangle's area.
    let mut g = one_node();
    tri(
        &mut g,
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        0,
        0,
    );
    let x = 1.0 - 1e-4;
    tri(
        &mut g,
        [[x, -0.5, -1.0], [x, 0.5, -1.0], [x, 0.0, 1e-4]],
        0,
        1,
    );
    let out = split(&g);
    assert_eq!(out.report.pairs_skipped_sliver, 1);
    assert_eq!(out.skipped, vec![[0, 1]]);
    assert_eq!(out.report.pairs_split, 0);
    assert_eq!(out.geometry, g);
    check(&g, &[], &out, &EXACT);

    let fine = SplitOptions {
        min_piece_area_fraction: 1e-12,
        ..both_sides()
    };
    let out = split_intersections(&g, &[], &fine);
    assert_eq!(out.report.pairs_split, 1);
    assert_eq!(out.report.pairs_skipped_sliver, 0);
    check(&g, &[], &out, &ROUNDED);
}

/// A deterministic soup of random triangles in a unit box, many crossing.
fn soup(n: usize) -> Geometry {
    let mut seed = 0x9e3779b97f4a7c15u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) as f32
    };
    let mut g = one_node();
    for k in 0..n {
        let c = [next(), next(), next()];
        let corner = |r: &mut dyn FnMut() -> f32| [0, 1, 2].map(|i| c[i] + 0.3 * (r() - 0.5));
        let corners = [corner(&mut next), corner(&mut next), corner(&mut next)];
        tri(&mut g, corners, 0, (k % 2) as u32);
    }
    g
}

#[test]
fn a_random_soup_keeps_every_invariant() {
    let g = soup(300);
    let out = split(&g);
    assert!(out.report.pairs_split > 100, "{:?}", out.report);
    check(&g, &[], &out, &ROUNDED);
}

#[test]
fn output_is_identical_whatever_the_threads() {
    let g = soup(200);
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let one = pool(1).install(|| split(&g));
    let four = pool(4).install(|| split(&g));
    assert_eq!(one, four);
    assert_eq!(
        bytemuck::cast_slice::<_, u8>(&one.geometry.vertices),
        bytemuck::cast_slice::<_, u8>(&four.geometry.vertices)
    );
    assert_eq!(split(&g), one, "and from one run to the next");
}

/// A horizontal grid and a tilted one crossing it: cuts run through shared edges.
fn crossing_grids() -> Geometry {
    let mut g = one_node();
    grid(&mut g, 5, 0, 0, |u, v| [2.0 * u - 1.0, 0.0, 2.0 * v - 1.0]);
    grid(&mut g, 4, 0, 1, |u, v| {
        [1.3 * u - 0.6, 0.7 * v - 0.4, 0.9 * u - 0.5 + 0.2 * v]
    });
    g
}

#[test]
fn cut_points_are_shared_across_edges() {
    let g = crossing_grids();
    let out = split(&g);
    assert!(out.report.pairs_split > 10, "{:?}", out.report);
    assert!(out.report.neighbours_split > 0, "{:?}", out.report);
    assert_eq!(out.report.t_junctions_left, 0);
    check(&g, &[], &out, &ROUNDED);
    assert_eq!(t_junctions(&out.geometry), vec![]);

    let keep = SplitOptions {
        close_t_junctions: false,
        ..both_sides()
    };
    let open = split_intersections(&g, &[], &keep);
    assert_eq!(open.report.neighbours_split, 0);
    assert!(!t_junctions(&open.geometry).is_empty());
    check(&g, &[], &open, &ROUNDED);
}

#[test]
fn one_side_is_enough_to_remove_the_crossings() {
    let one_side = SplitOptions {
        cut_both_sides: false,
        ..SplitOptions::default()
    };
    let mut g = one_node();
    x_quads(&mut g, 0, |p| p);
    let out = split_intersections(&g, &[], &one_side);
    assert_eq!(out.report.pairs_split, 2);
    // Each pair is cut on one triangle; the quads' other triangles take the cut points on
    // the shared diagonal.
    assert!(out.report.triangles_added < split(&g).report.triangles_added);
    check(&g, &[], &out, &EXACT);
    assert!(find_intersections(&out.geometry, &[]).pairs.is_empty());

    let g = soup(300);
    let both = split(&g);
    let out = split_intersections(&g, &[], &one_side);
    assert_eq!(out.report.pairs_split, both.report.pairs_split);
    assert!(out.report.triangles_added < both.report.triangles_added);
    check(&g, &[], &out, &ROUNDED);

    let g = crossing_grids();
    let out = split_intersections(&g, &[], &one_side);
    check(&g, &[], &out, &ROUNDED);
    assert_eq!(t_junctions(&out.geometry), vec![]);
}
