//! The validator on files written by hand (no merger involved).

use trisort_format::{
    Baked, Bridge, Camera, DrawIndexedIndirectArgs, Edge, FrameRecord, FrameState, FrameWindow,
    Geometry, Material, MergeInfo, MergeStats, Node, Phase, RecordSettings, Recording, Vertex,
};
use trisort_verify::check_graph;

const A: u32 = 10;
const H: u32 = 20;
const B: u32 = 30;

fn geometry(n: u32) -> Geometry {
    Geometry {
        vertices: (0..n + 2)
            .map(|k| Vertex {
                position: [k as f32, 0.0, 0.0],
                normal: [0.0, 0.0, 1.0],
                uv: [0.0; 2],
                material: 0,
                node: 0,
            })
            .collect(),
        triangles: (0..n).map(|k| [k, k + 1, k + 2]).collect(),
        materials: vec![Material::default()],
        textures: vec![],
        nodes: vec![Node {
            name: String::new(),
            parent: None,
            rest: [
                1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.,
            ],
        }],
    }
}

fn state() -> FrameState {
    FrameState {
        camera: Camera {
            view: [
                1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.,
            ],
            yfov: 1.0,
            znear: 0.1,
            zfar: None,
        },
        poses: vec![],
    }
}

/// Two frames over G = {A, H, B} (scene ids). Frame 0: A and B visible, H hidden between them
/// (A → H → B). Frame 1: all three visible, A → H → B.
fn recording() -> Recording {
    let chain = vec![
        Edge {
            from: A,
            to: H,
            weight: 2,
        },
        Edge {
            from: H,
            to: B,
            weight: 2,
        },
    ];
    Recording {
        tool_version: "test".into(),
        scene_hash: [1; 32],
        path_hash: [2; 32],
        settings: RecordSettings::default(),
        device: Default::default(),
        phase: Phase::Graphs,
        scene_triangles: 40,
        frame_states: vec![state(), state()],
        frames: vec![
            FrameRecord {
                frame: 0,
                visible: vec![A, B],
                covered: vec![A, H, B],
                edges: chain.clone(),
                ..Default::default()
            },
            FrameRecord {
                frame: 1,
                visible: vec![A, H, B],
                covered: vec![A, H, B],
                edges: chain,
                ..Default::default()
            },
        ],
        unique_visible: vec![A, H, B],
        geometry: geometry(3),
    }
}

fn draw(first_copy: u32, count: u32) -> DrawIndexedIndirectArgs {
    DrawIndexedIndirectArgs {
        index_count: count * 3,
        instance_count: 1,
        first_index: first_copy * 3,
        base_vertex: 0,
        first_instance: 0,
    }
}

/// G-local ids: A = 0, H = 1, B = 2. `copies` is the index buffer; frame 0 draws `f0`,
/// frame 1 draws `f1` (as (first copy, count) ranges).
fn baked(
    rec: &Recording,
    bridge: Bridge,
    copies: Vec<u32>,
    f0: &[(u32, u32)],
    f1: &[(u32, u32)],
) -> Baked {
    let mut draws = Vec::new();
    let mut frames = Vec::new();
    for ranges in [f0, f1] {
        frames.push(FrameWindow {
            first: draws.len() as u32,
            count: ranges.len() as u32,
        });
        draws.extend(ranges.iter().map(|&(a, n)| draw(a, n)));
    }
    Baked {
        tool_version: "test".into(),
        scene_hash: rec.scene_hash,
        path_hash: rec.path_hash,
        recording_hashes: vec![rec.content_hash()],
        settings: rec.settings,
        device: rec.device.clone(),
        merge: MergeInfo {
            bridge,
            ..MergeInfo::default()
        },
        stats: MergeStats::default(),
        geometry: rec.geometry.clone(),
        scene_ids: rec.unique_visible.clone(),
        copies,
        draws,
        frames,
        frame_states: rec.frame_states.clone(),
        removed_edges: vec![vec![], vec![]],
    }
}

#[test]
fn order_through_an_undrawn_triangle() {
    let rec = recording();
    let recs = std::slice::from_ref(&rec);
    // Buffer [A, H, B]: frame 0 draws A and B (skipping H) as two ranges, frame 1 all.
    let good = baked(
        &rec,
        Bridge::Ignored,
        vec![0, 1, 2],
        &[(0, 1), (2, 1)],
        &[(0, 3)],
    );
    let r = check_graph(recs, &good);
    assert!(r.ok, "{:?}", r.problems);
    assert_eq!(r.frames[0].drawn_not_visible, 0);

    // Buffer [B, A, H]: frame 0 draws B then A. B is reachable from A only through the
    // undrawn H, which still orders A first.
    let bad = baked(
        &rec,
        Bridge::Ignored,
        vec![2, 0, 1],
        &[(0, 2)],
        &[(1, 2), (0, 1)],
    );
    let r = check_graph(recs, &bad);
    assert!(!r.ok);
    assert_eq!(r.frames[0].graph_violations, 1, "{:?}", r.frames);
    // Frame 1 draws A, H, then B: fine.
    assert_eq!(r.frames[1].graph_violations, 0);
}

#[test]
fn bridge_policy_and_copies() {
    let rec = recording();
    let recs = std::slice::from_ref(&rec);
    // One copy of each drawn in both frames: H is drawn at frame 0 where it is covered but
    // hidden. Allowed by `hidden`, not by `ignored`.
    let both = |bridge: Bridge| baked(&rec, bridge, vec![0, 1, 2], &[(0, 3)], &[(0, 3)]);
    let r = check_graph(recs, &both(Bridge::Hidden));
    assert!(r.ok, "{:?}", r.problems);
    assert_eq!(r.frames[0].drawn_not_visible, 1);
    let r = check_graph(recs, &both(Bridge::Ignored));
    assert!(!r.ok);
    assert_eq!(r.frames[0].bridge_violations, 1);
    // `visible` allows no drawn-not-visible triangle at all.
    let r = check_graph(recs, &both(Bridge::Visible));
    assert!(!r.ok);
    assert_eq!(r.frames[0].bridge_violations, 1);
    assert_eq!(r.frames[1].bridge_violations, r.frames[1].drawn_not_visible);

    // A visible triangle drawn twice in one frame.
    let twice = baked(
        &rec,
        Bridge::Hidden,
        vec![0, 1, 2, 2],
        &[(0, 1), (2, 2)],
        &[(0, 3)],
    );
    let r = check_graph(recs, &twice);
    assert!(!r.ok);
    assert_eq!(r.frames[0].drawn_twice, 1);

    // A copy drawn in no frame.
    let unused = baked(
        &rec,
        Bridge::Hidden,
        vec![0, 1, 2, 1],
        &[(0, 1), (2, 1)],
        &[(0, 3)],
    );
    let r = check_graph(recs, &unused);
    assert!(!r.ok);
    assert_eq!(r.bad_copies, 1);

    // A malformed draw is reported, not a panic.
    let mut broken = both(Bridge::Hidden);
    broken.draws[0].index_count = 300;
    let r = check_graph(recs, &broken);
    assert!(!r.ok && r.problems[0].contains("structure"));
}

#[test]
fn removed_edges_must_exist_and_add_up() {
    let mut rec = recording();
    // A cycle in frame 1: B → A as well.
    rec.frames[1].edges.push(Edge {
        from: B,
        to: A,
        weight: 1,
    });
    rec.frames[1].edges.sort();
    let recs = std::slice::from_ref(&rec);
    let mut b = baked(
        &rec,
        Bridge::Ignored,
        vec![0, 1, 2],
        &[(0, 1), (2, 1)],
        &[(0, 3)],
    );
    // Unbroken cycle: E_f minus nothing is cyclic.
    assert!(!check_graph(recs, &b).ok);
    // Removing B → A (G-local 2 → 0) with its weight, and reporting it, passes.
    b.recording_hashes = vec![rec.content_hash()];
    b.removed_edges[1] = vec![Edge {
        from: 2,
        to: 0,
        weight: 1,
    }];
    b.stats.unordered_samples = 1;
    let r = check_graph(recs, &b);
    assert!(r.ok, "{:?}", r.problems);
    assert_eq!(r.frames[1].unordered_samples, 1);
    // A wrong weight or total fails.
    b.stats.unordered_samples = 2;
    assert!(!check_graph(recs, &b).ok);
    b.stats.unordered_samples = 1;
    b.removed_edges[1][0].weight = 5;
    assert!(!check_graph(recs, &b).ok);
}

#[test]
fn malformed_recording_is_reported() {
    let mut rec = recording();
    let good = baked(&rec, Bridge::Hidden, vec![0, 1, 2], &[(0, 3)], &[(0, 3)]);
    rec.frames[0].visible = vec![B, A];
    let r = check_graph(std::slice::from_ref(&rec), &good);
    assert!(
        !r.ok && r.problems[0].contains("malformed"),
        "{:?}",
        r.problems
    );
}
