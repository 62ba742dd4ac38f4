// The recorder's fragment capture: one render pass keeps every fragment of every drawn
// triangle at every sample, where depth peeling needs one pass per layer. Each layer of a peel
// is, per sample, the next fragment in (depth, id) order, so the whole peel of a sample is its
// captured fragments sorted by (depth, id): the host sorts each sample's list and walks it as
// the peel would (phase 1 until saturation, phase 2 completely).
//
// Drawn like a peel pass: the same vertex transform (@invariant position), the same MSAA
// pattern, shaded once per covered sample (`sample_index`), the same facing, MASK and alpha
// rules (`surface_base` at the pixel centre), and the same id (the triangle's position in the
// drawn list).
// A peel keeps only fragments that pass its depth test `Less` against the cleared 1.0, so
// fragments at depth 1 are left out here too. Phase 2 runs no depth test: every fragment is
// kept. Phase 1 (visibility until saturation) may first draw the triangles that are opaque
// wherever they are drawn into the depth buffer and then capture with `LessEqual` against it,
// the test forced before the shader ({{EARLY_DEPTH_TEST}}): a sample's walk stops at its first
// opaque fragment, and every fragment before it in (depth, id) order passes.
//
// Each kept fragment takes a node from the pool with an atomic counter and pushes it on its
// sample's list (`atomicExchange` on the head). Fragments that find the pool full are counted
// apart, so the host knows how large a pool the pass needed and draws again, and the node
// counter never passes the capacity by more than the fragments in flight (it cannot wrap).

struct Capture {
    // Position in the index buffer of this draw's first triangle (primitive_index restarts
    // per draw): its id is `draw_ids[first + primitive_index]`.
    first: u32,
    // Image width and sample count.
    width: u32,
    samples: u32,
    // Nodes in the pool.
    capacity: u32,
}

// One fragment: depth bits, id + 1, opacity bits (clamped to [0, 1], as a peel layer stores
// it), and the next node's index + 1 (0 ends the list).
struct Node {
    depth: u32,
    id: u32,
    alpha: u32,
    next: u32,
}

@group(1) @binding(0) var<uniform> capture: Capture;
// Per sample (pixel (x, y) sample s is (y * width + x) * samples + s): first node index + 1.
@group(1) @binding(1) var<storage, read_write> heads: array<atomic<u32>>;
// 0: nodes taken (at most the capacity plus the fragments in flight); 1: fragments that found
// the pool full before taking one (may wrap past 2^32 on an enormous pass); 2: non-zero once
// any fragment found the pool full.
@group(1) @binding(2) var<storage, read_write> counter: array<atomic<u32>, 4>;
@group(1) @binding(3) var<storage, read_write> nodes: array<Node>;
// Per triangle of the index buffer, its id (its position in the drawn list): the index buffer
// holds the triangles whose opacity needs no texture first, then the others, each part in id
// order, and each part is drawn by its own pipeline (READS_ALPHA). The order fragments are
// drawn in does not matter here: the host sorts every sample's list.
@group(1) @binding(4) var<storage, read> draw_ids: array<u32>;

// Whether this pipeline's triangles may take their opacity from a texture (MASK and BLEND
// materials, `surface_base`). Where not (OPAQUE materials and glass), the opacity is what
// `surface_base` gives them without sampling: 1, or the glass opacity. A CPU rasterizer runs
// both sides of a branch on the material, so the texture is left out by specialising.
override READS_ALPHA: bool = true;

{{EARLY_DEPTH_TEST}}
@fragment
fn fs_capture(
    in: RecordVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(sample_index) sample: u32,
    @builtin(primitive_index) primitive: u32,
) {
    let m = material_at(in.material);
    if (culled_of(m, front_facing)) {
        return;
    }
    var alpha = 1.0;
    if (READS_ALPHA) {
        alpha = surface_base_of(m, in.uv, in.uv1).a;
    } else if (m.emissive.a > 0.0) {
        alpha = frame.params.x;
    }
    let z = in.position.z;
    if (alpha < 0.0 || !(z < 1.0)) {
        return;
    }
    capture_push(in.position.xy, sample, z, draw_ids[capture.first + primitive] + 1u, alpha);
}

// Pushes a fragment (depth `z`, id + 1 `id1`, opacity `alpha`) on the list of `sample` of the
// pixel at `xy`, if the pool has room (the counters count the attempt either way).
fn capture_push(xy: vec2<f32>, sample: u32, z: f32, id1: u32, alpha: f32) {
    if (atomicLoad(&counter[0]) >= capture.capacity) {
        atomicAdd(&counter[1], 1u);
        atomicStore(&counter[2], 1u);
        return;
    }
    let n = atomicAdd(&counter[0], 1u);
    if (n >= capture.capacity) {
        // Counted in counter[0] already.
        atomicStore(&counter[2], 1u);
        return;
    }
    let coord = vec2<u32>(xy);
    let slot = (coord.y * capture.width + coord.x) * capture.samples + sample;
    let next = atomicExchange(&heads[slot], n + 1u);
    nodes[n] = Node(bitcast<u32>(z), id1, bitcast<u32>(clamp(alpha, 0.0, 1.0)), next);
}
