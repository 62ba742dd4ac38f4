// Gathers one peel layer per sample into a buffer for readback. Multisampled textures cannot
// be copied to buffers, so a compute pass reads them.
//
// `gather` writes three arrays of n = width · height · samples words each: id + 1 at
// [0, n), alpha bits at [n, 2n), depth bits at [2n, 3n), so that a reader copies back only
// the arrays it needs (ids and alpha for visibility, ids and depth for graphs).
// `gather_interleaved` is the former layout, one (id + 1, alpha bits, depth bits, 0) per
// sample; the recorder keeps it reachable to compare against (same layer either way).

struct Dims {
    width: u32,
    height: u32,
    samples: u32,
    pad: u32,
}

@group(0) @binding(0) var layer_ids: {{IDS_TYPE}};
@group(0) @binding(1) var layer_depth: {{DEPTH_TYPE}};
@group(0) @binding(2) var<storage, read_write> out: array<u32>;
@group(0) @binding(3) var<uniform> dims: Dims;

@compute @workgroup_size(8, 8)
fn gather(@builtin(global_invocation_id) g: vec3<u32>) {
    if (g.x >= dims.width || g.y >= dims.height) {
        return;
    }
    let coord = vec2<i32>(g.xy);
    let n = dims.width * dims.height * dims.samples;
    for (var s = 0u; s < dims.samples; s = s + 1u) {
        let ids = textureLoad(layer_ids, coord, {{AT_S}});
        let depth = textureLoad(layer_depth, coord, {{AT_S}});
        let slot = (g.y * dims.width + g.x) * dims.samples + s;
        out[slot] = ids.x;
        out[n + slot] = ids.y;
        out[2u * n + slot] = bitcast<u32>(depth);
    }
}

@compute @workgroup_size(8, 8)
fn gather_interleaved(@builtin(global_invocation_id) g: vec3<u32>) {
    if (g.x >= dims.width || g.y >= dims.height) {
        return;
    }
    let coord = vec2<i32>(g.xy);
    for (var s = 0u; s < dims.samples; s = s + 1u) {
        let ids = textureLoad(layer_ids, coord, {{AT_S}});
        let depth = textureLoad(layer_depth, coord, {{AT_S}});
        let slot = ((g.y * dims.width + g.x) * dims.samples + s) * 4u;
        out[slot] = ids.x;
        out[slot + 1u] = ids.y;
        out[slot + 2u] = bitcast<u32>(depth);
        out[slot + 3u] = 0u;
    }
}
