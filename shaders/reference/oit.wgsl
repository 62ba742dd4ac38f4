// Order-independent transparency with per-sample linked lists (paper 001), the run-time rival of
// the baked player (composed after COMMON and PLAYER: colours are the player's `player_colour`).
//
// List pass (`vs_player`, `fs_oit_list`): every scene triangle in one draw, ascending ids, no
// depth test, shaded once per covered sample (`sample_index` makes each sample its own
// invocation; `uv` and `normal` stay centre-interpolated, so the colour is the player's
// per-pixel one). Each fragment with alpha > 0 takes a node from the pool with an atomic counter and pushes it
// on its sample's list (`atomicExchange` on the head). The counter counts every attempt, also
// past the pool's end, so the host knows exactly how many fragments were lost.
//
// Resolve pass (`vs_oit_fullscreen`, `fs_oit_resolve`): one invocation per sample gathers the
// nearest {{OIT_MAX_SORTED}} fragments of its list sorted by (depth, id), the exact reference's
// peel order, and composites them back to front over the clear colour with the player's
// straight-alpha `over`, rounding to binary16 after every layer as the Rgba16Float target does
// between the reference's blended draws (`oit_f16`). Fragments behind the nearest opaque one
// are skipped (over an opaque fragment the result is that fragment's colour, whatever lies
// behind).

struct OitParams {
    // Image width, sample count, node pool capacity, and 1 where the target's blend unit
    // rounds to binary16 toward zero (lavapipe), 0 where it rounds to nearest even.
    width: u32,
    samples: u32,
    capacity: u32,
    round_to_zero: u32,
    // The target's clear colour (linear, alpha 1).
    clear: vec4<f32>,
    // Node n lives in buffer n >> chunk_shift at index n & chunk_mask (one storage buffer
    // binding is limited in size, so the pool is split over up to four).
    chunk_shift: u32,
    chunk_mask: u32,
    pad0: u32,
    pad1: u32,
}

// One stored fragment: straight-alpha colour (f32, as the blend unit receives it), the
// rasterized depth, the scene triangle id, and the next node index + 1 (0 ends the list).
struct OitNode {
    r: f32,
    g: f32,
    b: f32,
    a: f32,
    depth: f32,
    id: u32,
    next: u32,
}

@group(1) @binding(0) var<uniform> oit: OitParams;
// Per sample (pixel (x, y) sample s is (y * width + x) * samples + s): first node index + 1.
@group(1) @binding(1) var<storage, read_write> oit_heads: array<atomic<u32>>;
// 0: fragments that asked for a node (may exceed the capacity); 1: samples whose list held
// more than {{OIT_MAX_SORTED}} fragments.
@group(1) @binding(2) var<storage, read_write> oit_counters: array<atomic<u32>, 2>;
// The node pool in up to four buffers (unused ones are bound to a one-node dummy).
@group(1) @binding(3) var<storage, read_write> oit_nodes0: array<OitNode>;
@group(1) @binding(4) var<storage, read_write> oit_nodes1: array<OitNode>;
@group(1) @binding(5) var<storage, read_write> oit_nodes2: array<OitNode>;
@group(1) @binding(6) var<storage, read_write> oit_nodes3: array<OitNode>;

fn oit_store(n: u32, node: OitNode) {
    let i = n & oit.chunk_mask;
    switch (n >> oit.chunk_shift) {
        case 0u: { oit_nodes0[i] = node; }
        case 1u: { oit_nodes1[i] = node; }
        case 2u: { oit_nodes2[i] = node; }
        default: { oit_nodes3[i] = node; }
    }
}

fn oit_load(n: u32) -> OitNode {
    let i = n & oit.chunk_mask;
    switch (n >> oit.chunk_shift) {
        case 0u: { return oit_nodes0[i]; }
        case 1u: { return oit_nodes1[i]; }
        case 2u: { return oit_nodes2[i]; }
        default: { return oit_nodes3[i]; }
    }
}

const MAX_SORTED: u32 = {{OIT_MAX_SORTED}}u;

fn oit_slot(position: vec4<f32>, sample: u32) -> u32 {
    let coord = vec2<u32>(position.xy);
    return (coord.y * oit.width + coord.x) * oit.samples + sample;
}

@fragment
fn fs_oit_list(
    v: PlayerVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(sample_index) sample: u32,
    @builtin(sample_mask) coverage: u32,
    @builtin(primitive_index) primitive: u32,
) -> @location(0) vec4<f32> {
    let uv = player_uv(v);
    if ((coverage & (1u << sample)) == 0u) {
        discard;
    }
    let c = player_colour(v, front_facing, uv);
    // Fully transparent fragments (glass at opacity 0) change nothing: `over` keeps the
    // destination exactly.
    if (c.a <= 0.0) {
        discard;
    }
    let n = atomicAdd(&oit_counters[0], 1u);
    if (n < oit.capacity) {
        let next = atomicExchange(&oit_heads[oit_slot(v.position, sample)], n + 1u);
        oit_store(n, OitNode(c.r, c.g, c.b, c.a, v.position.z, primitive, next));
    }
    // The colour attachment is a dummy with an empty write mask.
    return vec4<f32>(0.0);
}

@vertex
fn vs_oit_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(i & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

// Whether node key (da, ia) comes before (db, ib): nearer first, lower id on a depth tie.
fn oit_before(da: f32, ia: u32, db: f32, ib: u32) -> bool {
    return da < db || (da == db && ia < ib);
}

// Rounds to binary16 as the blend unit does when it stores to an Rgba16Float target: toward
// zero on lavapipe, to nearest even elsewhere.
fn oit_f16(x: vec4<f32>) -> vec4<f32> {
    if (oit.round_to_zero == 0u) {
        return quantizeToF16(x);
    }
    var out: vec4<f32>;
    for (var i = 0; i < 4; i = i + 1) {
        let b = bitcast<u32>(x[i]);
        if (((b >> 23u) & 0xffu) >= 113u) {
            out[i] = bitcast<f32>(b & 0xffffe000u);
        } else {
            out[i] = trunc(x[i] * 16777216.0) / 16777216.0;
        }
    }
    return out;
}

@fragment
fn fs_oit_resolve(
    @builtin(position) position: vec4<f32>,
    @builtin(sample_index) sample: u32,
) -> @location(0) vec4<f32> {
    var depth: array<f32, MAX_SORTED>;
    var id: array<u32, MAX_SORTED>;
    var node: array<u32, MAX_SORTED>;
    var n = 0u;
    var overflow = false;
    var p = atomicLoad(&oit_heads[oit_slot(position, sample)]);
    // Insertion into the sorted prefix; past MAX_SORTED the farthest is dropped.
    for (var guard = 0u; p != 0u && guard < oit.capacity; guard = guard + 1u) {
        let k = p - 1u;
        let f = oit_load(k);
        let d = f.depth;
        let t = f.id;
        p = f.next;
        if (n == MAX_SORTED) {
            overflow = true;
            if (!oit_before(d, t, depth[n - 1u], id[n - 1u])) {
                continue;
            }
            n = n - 1u;
        }
        var j = n;
        while (j > 0u && oit_before(d, t, depth[j - 1u], id[j - 1u])) {
            depth[j] = depth[j - 1u];
            id[j] = id[j - 1u];
            node[j] = node[j - 1u];
            j = j - 1u;
        }
        depth[j] = d;
        id[j] = t;
        node[j] = k;
        n = n + 1u;
    }
    if (overflow) {
        atomicAdd(&oit_counters[1], 1u);
    }
    // Nothing behind the nearest opaque fragment shows.
    var last = n;
    for (var j = 0u; j < n; j = j + 1u) {
        if (oit_load(node[j]).a >= 1.0) {
            last = j + 1u;
            break;
        }
    }
    var c = quantizeToF16(oit.clear);
    for (var j = last; j > 0u; j = j - 1u) {
        let f = oit_load(node[j - 1u]);
        let src = vec4<f32>(f.r, f.g, f.b, f.a);
        // The player's blend state: colour s.a·s + (1 − s.a)·d, alpha s.a + (1 − s.a)·d.a.
        let rgb = src.rgb * src.a + c.rgb * (1.0 - src.a);
        let a = src.a + c.a * (1.0 - src.a);
        c = oit_f16(vec4<f32>(rgb, a));
    }
    return c;
}
