//! Synthetic recordings, for tests and benchmarks only (no GPU, no scene file).
//!
//! [`recording_from_frames`] turns hand-written per-frame sets and edges into a valid
//! [`Recording`]; [`turntable`] simulates the recorder on a one-dimensional scene seen by a
//! camera orbiting it, with opaque and transparent triangles, hidden and never-covered
//! triangles, interpenetrating (tilted) triangles that make intra-frame cycles, and order
//! inversions as the camera turns; [`split_frames`] cuts a recording into frame ranges, as
//! `record --frames a..b` on several machines would.

use trisort_format::{
    Camera, DeviceInfo, Edge, FrameRecord, FrameState, Geometry, Material, Node, Phase,
    RecordSettings, Recording, Vertex,
};

/// One frame of a hand-written recording, in scene ids.
#[derive(Clone, Debug, Default)]
pub struct FrameSpec {
    /// V_f.
    pub visible: Vec<u32>,
    /// Triangles covered but hidden (C_f \ V_f).
    pub hidden: Vec<u32>,
    /// E_f as `(front, back, weight)`.
    pub edges: Vec<(u32, u32, u32)>,
    /// Tie edges (a subset of `edges`, for depth-only bakes).
    pub ties: Vec<(u32, u32, u32)>,
}

/// Builds a Phase-2 recording of `scene_triangles` triangles from per-frame specs: G is the
/// union of the visible sets; hidden triangles and edge endpoints outside G are dropped (the
/// recorder's phase 2 peels only G). Sets are sorted and deduplicated. Geometry: one
/// triangle strip over G (triangle k uses vertices k, k+1, k+2), one material, one node.
pub fn recording_from_frames(scene_triangles: u32, frames: &[FrameSpec]) -> Recording {
    let mut g: Vec<u32> = frames
        .iter()
        .flat_map(|f| f.visible.iter().copied())
        .collect();
    g.sort_unstable();
    g.dedup();
    let in_g = |t: &u32| g.binary_search(t).is_ok();
    let edges = |list: &[(u32, u32, u32)]| {
        let mut e: Vec<Edge> = list
            .iter()
            .filter(|(a, b, _)| in_g(a) && in_g(b))
            .map(|&(from, to, weight)| Edge { from, to, weight })
            .collect();
        e.sort_unstable();
        e.dedup_by_key(|e| (e.from, e.to));
        e
    };
    let records: Vec<FrameRecord> = frames
        .iter()
        .enumerate()
        .map(|(f, s)| {
            let mut visible = s.visible.clone();
            visible.sort_unstable();
            visible.dedup();
            let edges_f = edges(&s.edges);
            let mut covered: Vec<u32> = visible
                .iter()
                .chain(&s.hidden)
                .copied()
                .filter(in_g)
                .collect();
            covered.extend(edges_f.iter().flat_map(|e| [e.from, e.to]));
            covered.sort_unstable();
            covered.dedup();
            FrameRecord {
                frame: f as u32,
                visible,
                covered,
                edges: edges_f,
                ties: edges(&s.ties),
                layers: [1, 1],
                truncated: false,
            }
        })
        .collect();
    let n = g.len() as u32;
    let vertices: Vec<Vertex> = (0..n + 2)
        .map(|k| Vertex {
            position: [k as f32 * 0.5, (k % 2) as f32, 0.0],
            normal: [0.0, 0.0, 1.0],
            uv: [0.0; 2],
            material: 0,
            node: 0,
            tangent: [0.0; 4],
            uv1: [0.0; 2],
        })
        .collect();
    let geometry = Geometry {
        vertices,
        triangles: (0..n).map(|k| [k, k + 1, k + 2]).collect(),
        materials: vec![Material::default()],
        textures: vec![],
        nodes: vec![Node {
            name: "root".into(),
            parent: None,
            rest: identity(),
        }],
        variants: vec![],
    };
    let frame_states = (0..frames.len())
        .map(|_| FrameState {
            camera: Camera {
                view: identity(),
                yfov: 1.0,
                znear: 0.1,
                zfar: None,
            },
            poses: vec![],
        })
        .collect();
    let mut id = Vec::new();
    id.extend_from_slice(&scene_triangles.to_le_bytes());
    id.extend_from_slice(&(frames.len() as u32).to_le_bytes());
    Recording {
        tool_version: trisort_format::TOOL_VERSION.into(),
        scene_hash: trisort_format::hash_bytes(&id),
        path_hash: trisort_format::hash_bytes(b"synthetic path"),
        settings: RecordSettings {
            width: 1,
            height: 1,
            samples: 1,
            ..RecordSettings::default()
        },
        device: DeviceInfo {
            adapter: "synthetic".into(),
            driver: String::new(),
            backend: String::new(),
        },
        phase: Phase::Graphs,
        scene_triangles,
        frame_states,
        frames: records,
        unique_visible: g,
        geometry,
        fps: None,
        clips: vec![trisort_format::Clip::whole(
            frames.len() as u32,
            None,
            trisort_format::hash_bytes(b"synthetic path"),
        )],
    }
}

fn identity() -> [f64; 16] {
    let mut m = [0.0; 16];
    for k in 0..4 {
        m[k * 5] = 1.0;
    }
    m
}

/// Parameters of [`turntable`].
#[derive(Clone, Copy, Debug)]
pub struct Turntable {
    /// Objects on the turntable (closed polygons).
    pub objects: u32,
    /// Sides (triangles) per object.
    pub sides: u32,
    /// Frames of the path.
    pub frames: u32,
    /// Samples across the one-dimensional image.
    pub samples: u32,
    /// Total camera turn in degrees over the path.
    pub degrees: f64,
    /// Fraction of transparent objects (opacity 0.5); the rest are opaque.
    pub transparent: f64,
    /// Object radius scale (radii are 0.08–0.28 times this).
    pub size: f64,
    /// Random seed.
    pub seed: u64,
}

impl Default for Turntable {
    fn default() -> Self {
        Turntable {
            objects: 12,
            sides: 24,
            frames: 24,
            samples: 256,
            degrees: 90.0,
            transparent: 0.3,
            size: 1.0,
            seed: 1,
        }
    }
}

/// A deterministic pseudo-random generator (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Simulates the recorder on a turntable seen in one dimension: `objects` closed polygons of
/// `sides` double-sided segments ("triangles", ids object-major) stand at random places on a
/// disc (they may overlap and interpenetrate, which makes intra-frame cycles); the camera
/// orbits the disc at distance 3 looking at its centre; each of `samples` rays peels the
/// segments it hits by (depth, id). V_f: segments reached before the ray's opacity saturates
/// (0.998); C_f: every segment of G the ray hits; E_f: neighbours in the peel of G, weighted
/// by rays. Depth complexity is that of a few objects (2 per object), as in real scenes.
/// Deterministic in its parameters.
pub fn turntable(p: &Turntable) -> Recording {
    let objects = place_objects(p);
    let n = p.objects * p.sides;
    let opacity = |t: u32| objects[(t / p.sides) as usize].opacity;
    let peels: Vec<Vec<Vec<u32>>> = (0..p.frames)
        .map(|f| turntable_peel(p, &objects, f))
        .collect();
    let visible_of = |samples: &Vec<Vec<u32>>| {
        let mut vis = Vec::new();
        for order in samples {
            let mut transmit = 1.0;
            for &t in order {
                if 1.0 - transmit >= 0.998 {
                    break;
                }
                vis.push(t);
                transmit *= 1.0 - opacity(t);
            }
        }
        vis.sort_unstable();
        vis.dedup();
        vis
    };
    let visible: Vec<Vec<u32>> = peels.iter().map(visible_of).collect();
    let mut g: Vec<u32> = visible.iter().flatten().copied().collect();
    g.sort_unstable();
    g.dedup();
    let specs: Vec<FrameSpec> = peels
        .iter()
        .zip(&visible)
        .map(|(samples, vis)| turntable_frame(samples, vis, &g))
        .collect();
    let mut rec = recording_from_frames(n, &specs);
    let mut id = Vec::new();
    for x in [
        p.objects as u64,
        p.sides as u64,
        p.frames as u64,
        p.samples as u64,
        p.seed,
        p.degrees.to_bits(),
        p.transparent.to_bits(),
        p.size.to_bits(),
    ] {
        id.extend_from_slice(&x.to_le_bytes());
    }
    rec.scene_hash = trisort_format::hash_bytes(&id);
    rec
}

/// One object of the [`turntable`]: a closed polygon around (x, z) of `radius`, turned by
/// `phase` of a turn, at `opacity`.
struct TurntableObject {
    x: f64,
    z: f64,
    radius: f64,
    phase: f64,
    opacity: f64,
}

/// The [`turntable`]'s objects at random places on the disc (drawn from `p.seed`).
fn place_objects(p: &Turntable) -> Vec<TurntableObject> {
    let mut rng = Rng(p.seed);
    (0..p.objects)
        .map(|_| {
            let r = 0.9 * rng.unit().sqrt();
            let a = rng.unit() * std::f64::consts::TAU;
            TurntableObject {
                x: r * a.cos(),
                z: r * a.sin(),
                radius: (0.08 + 0.2 * rng.unit()) * p.size,
                phase: rng.unit(),
                opacity: if rng.unit() < p.transparent { 0.5 } else { 1.0 },
            }
        })
        .collect()
}

/// Frame `f` of the [`turntable`]: per sample, the peel of the segments the ray hits, by
/// (depth, id).
fn turntable_peel(p: &Turntable, objects: &[TurntableObject], f: u32) -> Vec<Vec<u32>> {
    let focal = 2.0;
    let theta = (p.degrees * f as f64 / (p.frames.max(2) - 1) as f64).to_radians();
    let (sn, cs) = theta.sin_cos();
    let to_camera = |x: f64, z: f64| (x * cs - z * sn, 3.0 + x * sn + z * cs);
    let mut per_sample: Vec<Vec<(f64, u32)>> = vec![Vec::new(); p.samples as usize];
    for (o, ob) in objects.iter().enumerate() {
        let (cx, cz) = to_camera(ob.x, ob.z);
        // Screen interval of the object's bounding circle.
        let s_of =
            |u: f64| ((u + 1.0) / 2.0 * p.samples as f64 - 0.5).clamp(-1.0, p.samples as f64);
        let lo = s_of(focal * (cx - ob.radius) / (cz - ob.radius))
            .floor()
            .max(0.0) as u32;
        let hi = s_of(focal * (cx + ob.radius) / (cz - ob.radius))
            .ceil()
            .min(p.samples as f64 - 1.0) as u32;
        let corner = |k: u32| {
            let a = (k as f64 / p.sides as f64 + ob.phase) * std::f64::consts::TAU;
            to_camera(ob.x + ob.radius * a.cos(), ob.z + ob.radius * a.sin())
        };
        for k in 0..p.sides {
            let (ax, az) = corner(k);
            let (bx, bz) = corner(k + 1);
            let t = o as u32 * p.sides + k;
            for smp in lo..=hi {
                let kk = ((smp as f64 + 0.5) / p.samples as f64 * 2.0 - 1.0) / focal;
                let den = (bx - ax) - kk * (bz - az);
                if den.abs() < 1e-12 {
                    continue;
                }
                let sp = (kk * az - ax) / den;
                if (0.0..1.0).contains(&sp) {
                    let depth = az + sp * (bz - az);
                    if depth > 0.1 {
                        per_sample[smp as usize].push((depth, t));
                    }
                }
            }
        }
    }
    per_sample
        .into_iter()
        .map(|mut v| {
            v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            v.into_iter().map(|(_, t)| t).collect()
        })
        .collect()
}

/// One [`turntable`] frame's graph from its peels (`samples`) and visible set `vis`: covered
/// triangles of G (`g`) not visible are hidden, neighbours in the peel of G are edges weighted
/// by rays.
fn turntable_frame(samples: &[Vec<u32>], vis: &[u32], g: &[u32]) -> FrameSpec {
    let mut counts: std::collections::BTreeMap<(u32, u32), u32> = Default::default();
    let mut covered = Vec::new();
    for order in samples {
        let in_g: Vec<u32> = order
            .iter()
            .copied()
            .filter(|t| g.binary_search(t).is_ok())
            .collect();
        covered.extend_from_slice(&in_g);
        for w in in_g.windows(2) {
            *counts.entry((w[0], w[1])).or_default() += 1;
        }
    }
    covered.sort_unstable();
    covered.dedup();
    let hidden = covered
        .into_iter()
        .filter(|t| vis.binary_search(t).is_err())
        .collect();
    FrameSpec {
        visible: vis.to_vec(),
        hidden,
        edges: counts.into_iter().map(|((a, b), w)| (a, b, w)).collect(),
        ties: vec![],
    }
}

/// Cuts a recording into frame ranges starting at each of `starts` (ascending, first 0), as
/// separate recordings of the same path would be.
pub fn split_frames(rec: &Recording, starts: &[u32]) -> Vec<Recording> {
    let n = rec.frames.len() as u32;
    starts
        .iter()
        .enumerate()
        .map(|(k, &a)| {
            let b = starts.get(k + 1).copied().unwrap_or(n);
            let mut r = rec.clone();
            r.frames = rec.frames[a as usize..b as usize].to_vec();
            r
        })
        .collect()
}

/// `pairs` pairs of triangles (2k, 2k + 1) that swap order halfway through frames 0..4, in
/// front of a chain of `chain` covered but hidden triangles (ids from 2 · `pairs` on): in
/// frames 0–1 every 2k lies in front of the chain and the chain in front of every 2k + 1; in
/// frames 2–3, 2k + 1 lies directly in front of 2k and 2k still in front of the chain. The
/// chain is visible in frame 4 only. The swaps make the splitter cut copies and then try to
/// join them back, and each try searches through the whole hidden chain: the case that made
/// that search quadratic.
pub fn hidden_chain(chain: u32, pairs: u32) -> Recording {
    let (first, last) = (2 * pairs, 2 * pairs + chain - 1);
    let mut links: Vec<(u32, u32, u32)> = (first..last).map(|t| (t, t + 1, 1)).collect();
    links.extend((0..pairs).map(|k| (2 * k, first, 1)));
    let hidden: Vec<u32> = (first..=last).collect();
    let frames: Vec<FrameSpec> = (0..5)
        .map(|f| {
            if f == 4 {
                return FrameSpec {
                    visible: hidden.clone(),
                    ..FrameSpec::default()
                };
            }
            let mut edges = links.clone();
            edges.extend((0..pairs).map(|k| {
                if f < 2 {
                    (last, 2 * k + 1, 1)
                } else {
                    (2 * k + 1, 2 * k, 2)
                }
            }));
            FrameSpec {
                visible: (0..first).collect(),
                hidden: hidden.clone(),
                edges,
                ties: Vec::new(),
            }
        })
        .collect();
    recording_from_frames(first + chain, &frames)
}
