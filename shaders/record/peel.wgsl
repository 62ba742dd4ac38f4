// Depth peeling, one pass per layer (recorder and reference). Triangles are drawn in
// ascending id order with depth test Less; a fragment survives only if its (depth, id) key is
// greater than the previous layer's at the same sample, so each pass yields, per sample, the
// next fragment in (depth, id) order. The compared depth is written explicitly (frag_depth),
// so the discard test compares exactly what the depth test uses.

struct Peel {
    // Id of the first triangle of this draw (primitive_index restarts per draw).
    base_id: u32,
    // Image width, sample count, and 1 on the first layer.
    width: u32,
    samples: u32,
    first_layer: u32,
}

@group(1) @binding(0) var<uniform> peel: Peel;
@group(1) @binding(1) var prev_depth: {{DEPTH_TYPE}};
@group(1) @binding(2) var prev_ids: {{IDS_TYPE}};
// Per sample: non-zero once the sample is saturated or has no fragment left.
@group(1) @binding(3) var<storage, read> done: array<u32>;

struct PeelOut {
    // x: id + 1 (0 = no fragment), y: alpha bits.
    @location(0) ids: vec2<u32>,
    @builtin(frag_depth) depth: f32,
}

// Whether `sample` of the pixel at `coord` is saturated or has no fragment left.
fn peel_done(coord: vec2<i32>, sample: u32) -> bool {
    let slot = (u32(coord.y) * peel.width + u32(coord.x)) * peel.samples + sample;
    return done[slot] != 0u;
}

// Whether the key (z, id) is not greater than the previous layer's at `sample` of `coord`
// (always false on the first layer): the fragment belongs to an earlier layer.
fn peeled_before(coord: vec2<i32>, sample: u32, z: f32, id: u32) -> bool {
    if (peel.first_layer != 0u) {
        return false;
    }
    let pd = textureLoad(prev_depth, coord, {{AT_SAMPLE}});
    let pid = textureLoad(prev_ids, coord, {{AT_SAMPLE}}).x;
    return z < pd || (z == pd && id + 1u <= pid);
}

@fragment
fn fs_peel(
    in: RecordVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(sample_index) sample: u32,
    @builtin(primitive_index) primitive: u32,
) -> PeelOut {
    let coord = vec2<i32>(in.position.xy);
    if (peel_done(coord, sample)) {
        discard;
    }
    if (culled(in.material, front_facing)) {
        discard;
    }
    let base = surface_base(in.material, in.uv, in.uv1);
    if (base.a < 0.0) {
        discard;
    }
    let id = peel.base_id + primitive;
    let z = in.position.z;
    if (peeled_before(coord, sample, z, id)) {
        discard;
    }
    var out: PeelOut;
    out.ids = vec2<u32>(id + 1u, bitcast<u32>(clamp(base.a, 0.0, 1.0)));
    out.depth = z;
    return out;
}
