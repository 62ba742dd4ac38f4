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
                tangent: [0.0; 4],
                uv1: [0.0; 2],
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
        variants: vec![],
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
        fps: None,
        clips: vec![trisort_format::Clip::whole(2, None, [2; 32])],
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
    let mut b = Baked {
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
        fps: rec.fps,
        environment: trisort_format::Environment::uniform(1.0),
        clips: rec.clips.clone(),
    };
    restat(&mut b, rec);
    b
}

/// Sets the statistics the file states to what its draws, its removed edges and the
/// recording give (what an honest merger writes).
fn restat(b: &mut Baked, rec: &Recording) {
    let frames = b.frames.len().max(1) as f64;
    let drawn: i64 = (0..b.frames.len())
        .flat_map(|f| b.frame_draws(f))
        .map(|d| d.index_count as i64 / 3)
        .sum();
    let visible: u64 = rec.frames.iter().map(|f| f.visible.len() as u64).sum();
    b.stats = MergeStats {
        index_triangles: b.copies.len() as u64,
        source_triangles: visible,
        unique_visible: rec.unique_visible.len() as u64,
        draws_per_frame_mean: b.frames.iter().map(|w| w.count as f64).sum::<f64>() / frames,
        draws_per_frame_max: b.frames.iter().map(|w| w.count).max().unwrap_or(0),
        drawn_not_visible_mean: (drawn - visible as i64) as f64 / frames,
        unordered_samples: b
            .removed_edges
            .iter()
            .flatten()
            .map(|e| e.weight as u64)
            .sum(),
        ..MergeStats::default()
    };
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
    // The message names the frame and the order broken (scene ids), through H.
    assert!(
        r.problems
            .iter()
            .any(|p| p.starts_with("frame 0: order 10→30 (scene ids) is violated")),
        "{:?}",
        r.problems
    );
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

/// Frame 1 of [`recording`] with B → A added: the cycle A → H → B → A.
fn cyclic_recording() -> Recording {
    let mut rec = recording();
    rec.frames[1].edges.push(Edge {
        from: B,
        to: A,
        weight: 1,
    });
    rec.frames[1].edges.sort();
    rec
}

/// `baked` over [`cyclic_recording`] (A, H, B drawn in order at frame 1) with `removed`
/// (G-local edges per frame) and honest statistics.
fn with_removed(rec: &Recording, removed: [Vec<Edge>; 2]) -> Baked {
    let mut b = baked(
        rec,
        Bridge::Ignored,
        vec![0, 1, 2],
        &[(0, 1), (2, 1)],
        &[(0, 3)],
    );
    b.removed_edges = removed.to_vec();
    restat(&mut b, rec);
    b
}

fn local(from: u32, to: u32, weight: u32) -> Edge {
    Edge { from, to, weight }
}

#[test]
fn removed_edges_must_lie_on_a_cycle_and_be_needed() {
    let rec = cyclic_recording();
    let recs = std::slice::from_ref(&rec);
    let good = with_removed(&rec, [vec![], vec![local(2, 0, 1)]]);
    let r = check_graph(recs, &good);
    assert!(r.ok, "{:?}", r.problems);

    // A → H of frame 0, where there is no cycle: its order was never in doubt.
    let acyclic = with_removed(&rec, [vec![local(0, 1, 2)], vec![local(2, 0, 1)]]);
    let r = check_graph(recs, &acyclic);
    assert!(!r.ok);
    assert_eq!(r.frames[0].removed_not_on_cycle, 1, "{:?}", r.frames[0]);
    assert_eq!(r.frames[0].graph_violations, 1);
    assert!(
        r.problems
            .iter()
            .any(|p| p
                .starts_with("frame 0: removed edge 10→20 (scene ids, weight 2) lies on no cycle")),
        "{:?}",
        r.problems
    );

    // B → A and A → H of frame 1: once both are gone, neither closes a cycle on its own.
    let both = with_removed(&rec, [vec![], vec![local(2, 0, 1), local(0, 1, 2)]]);
    let r = check_graph(recs, &both);
    assert!(!r.ok);
    assert_eq!(r.frames[1].removed_not_needed, 2, "{:?}", r.frames[1]);
    assert_eq!(r.frames[1].removed_not_on_cycle, 0);
    for edge in ["30→10", "10→20"] {
        let start = format!("frame 1: removed edge {edge} (scene ids");
        assert!(
            r.problems
                .iter()
                .any(|p| p.starts_with(&start) && p.contains("is not needed")),
            "{start}: {:?}",
            r.problems
        );
    }
}

#[test]
fn what_the_file_repeats_must_match_the_recording() {
    let rec = cyclic_recording();
    let recs = std::slice::from_ref(&rec);
    let good = with_removed(&rec, [vec![], vec![local(2, 0, 1)]]);
    type Edit = fn(&mut Baked);
    let cases: [(Edit, &str); 9] = [
        (
            |b| b.frame_states[1].camera.view[12] += 0.5,
            "frame 1: the baked camera differs from recording 0's",
        ),
        (
            |b| b.geometry.vertices[2].position[1] = 7.0,
            "the baked geometry differs from recording 0's: vertices 2 differs",
        ),
        (
            |b| b.device.adapter = "another".into(),
            "the device () differs from the baked file's (another)",
        ),
        (
            |b| b.stats.index_triangles = 2,
            "statistic index_triangles: the file states 2, its copies give 3",
        ),
        (
            |b| b.stats.unique_visible = 4,
            "statistic unique_visible: the file states 4, the recordings give 3",
        ),
        (
            |b| b.stats.source_triangles = 1,
            "statistic source_triangles: the file states 1, the recordings give 5",
        ),
        (
            |b| b.stats.draws_per_frame_max = 1,
            "statistic draws_per_frame_max: the file states 1, its frames give 2",
        ),
        (
            |b| b.stats.draws_per_frame_mean = 1.0,
            "statistic draws_per_frame_mean: the file states 1, its frames give 1.5",
        ),
        (
            |b| b.stats.drawn_not_visible_mean = f64::NAN,
            "statistic drawn_not_visible_mean: the file states NaN",
        ),
    ];
    for (edit, needle) in cases {
        let mut b = good.clone();
        edit(&mut b);
        let r = check_graph(recs, &b);
        assert!(!r.ok, "{needle}");
        assert!(
            r.problems.iter().any(|p| p.contains(needle)),
            "{needle}: {:?}",
            r.problems
        );
    }
}

/// One frame whose graph is a chain through 40,000 triangles closed into one cycle by its
/// last edge, which the file removes: the components and the search must not recurse.
#[test]
fn a_cycle_through_forty_thousand_triangles() {
    let n = 40_000u32;
    let mut edges: Vec<Edge> = (0..n - 1).map(|k| local(k, k + 1, 1)).collect();
    edges.push(local(n - 1, 0, 1));
    edges.sort();
    let all: Vec<u32> = (0..n).collect();
    let rec = Recording {
        frame_states: vec![state()],
        frames: vec![FrameRecord {
            frame: 0,
            visible: all.clone(),
            covered: all.clone(),
            edges,
            ..Default::default()
        }],
        unique_visible: all.clone(),
        scene_triangles: n,
        geometry: geometry(n),
        clips: vec![trisort_format::Clip::whole(1, None, [2; 32])],
        ..recording()
    };
    let mut b = baked(&rec, Bridge::Visible, all, &[(0, n)], &[]);
    b.frames.truncate(1);
    b.frame_states.truncate(1);
    b.removed_edges.truncate(1);
    b.clips[0].count = 1;
    b.removed_edges[0] = vec![local(n - 1, 0, 1)];
    restat(&mut b, &rec);
    let r = check_graph(std::slice::from_ref(&rec), &b);
    assert!(r.ok, "{:?}", r.problems);
    assert_eq!(r.frames[0].unordered_samples, 1);
}

/// A cut that is on a cycle and needed, but heavier than the least, fails. In frame
/// 1 of [`cyclic_recording`] (A → H 2, H → B 2, B → A 1) removing H → B (2 samples) and drawing
/// B, A, H keeps every other edge, yet B → A alone (1 sample) suffices.
#[test]
fn a_heavier_cut_than_the_least_is_rejected() {
    let rec = cyclic_recording();
    let recs = std::slice::from_ref(&rec);
    // Buffer [A, B, B, A, H]: frame 0 draws A, B; frame 1 draws B, A, H.
    let mut b = baked(
        &rec,
        Bridge::Ignored,
        vec![0, 2, 2, 0, 1],
        &[(0, 2)],
        &[(2, 3)],
    );
    b.removed_edges = vec![
        vec![],
        vec![Edge {
            from: 1,
            to: 2,
            weight: 2,
        }],
    ];
    restat(&mut b, &rec);
    let r = check_graph(recs, &b);
    assert!(!r.ok);
    assert_eq!(r.frames[1].cut_excess, 1, "{:?}", r.frames[1]);
    assert_eq!(
        r.frames[1].removed_not_needed + r.frames[1].removed_not_on_cycle,
        0
    );
    assert!(
        r.problems
            .iter()
            .any(|p| p.contains("removes 2 samples where 1 suffice")),
        "{:?}",
        r.problems
    );
}
