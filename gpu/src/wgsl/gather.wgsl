// Gathers one peel layer per sample into a buffer for readback: (id + 1, alpha bits, depth
// bits, 0). Multisampled textures cannot be copied to buffers, so a compute pass reads them.

struct Dims {
    width: u32,
    height: u32,
    samples: u32,
    pad: u32,
}

@group(0) @binding(0) var layer_ids: PREV_IDS_TYPE;
@group(0) @binding(1) var layer_depth: PREV_DEPTH_TYPE;
@group(0) @binding(2) var<storage, read_write> out: array<vec4<u32>>;
@group(0) @binding(3) var<uniform> dims: Dims;

@compute @workgroup_size(8, 8)
fn gather(@builtin(global_invocation_id) g: vec3<u32>) {
    if (g.x >= dims.width || g.y >= dims.height) {
        return;
    }
    let coord = vec2<i32>(g.xy);
    for (var s = 0u; s < dims.samples; s = s + 1u) {
        let ids = LOAD_LAYER_IDS;
        let depth = LOAD_LAYER_DEPTH;
        out[(g.y * dims.width + g.x) * dims.samples + s] = vec4<u32>(ids.x, ids.y, bitcast<u32>(depth), 0u);
    }
}
