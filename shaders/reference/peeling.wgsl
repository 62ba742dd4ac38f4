// The GPU-only depth peeling renderer (trisort-reference's `PeelingRenderer`, the peeling
// rival of `bench`). Composed after COMMON and PLAYER: both passes draw with `vs_player`, so
// they rasterize the very positions the player, the recorder and the exact reference do.
//
// Fragments are ordered per sample by the recorder's (depth, triangle id) key: the depth is
// `position.z`, written explicitly (frag_depth) so the key test compares exactly what the depth
// test uses; on a depth tie the lower id is in front. Every triangle is drawn in one draw in
// ascending id order, so `primitive_index` is the triangle id.
//
// `fs_peeling` finds one layer per pass. Its mode (uniform) says which fragments survive
// against the previous pass's key at the same sample (read with textureLoad at sample_index):
//   0: all (first pass);
//   1: keys behind the previous one (front-to-back peel; depth test Less keeps the nearest,
//      the lower id on a tie);
//   2: keys in front of the previous one (back-to-front peel; depth test GreaterEqual keeps the
//      farthest, the higher id on a tie);
//   3: keys at or in front of the previous one (the first back-to-front pass under a limit:
//      the key of the last layer a truncated frame keeps).
// A cleared previous key (depth 1, id 0 after a front pass; depth 0, id 0 after a back pass)
// admits nothing in modes 1 and 2 and everything in front of the far plane in mode 3.
//
// `fs_peeling_composite` then draws every triangle again and shades, once per pixel with the
// player's `player_colour`, the samples where the layer's id is the triangle's own
// (`sample_mask`), exactly as the exact reference's compositing pass does (reference.wgsl).
// It reads no `sample_index`, so shading stays per pixel as in the player.

struct Peeling {
    // 0, 1, 2 or 3: see above.
    mode: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(1) @binding(0) var<uniform> peeling: Peeling;
@group(1) @binding(1) var prev_depth: {{DEPTH_TYPE}};
@group(1) @binding(2) var prev_ids: {{IDS_TYPE}};

struct PeelingOut {
    // Triangle id + 1; 0 (the clear value) where the layer has no fragment.
    @location(0) id: u32,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_peeling(
    v: PlayerVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(sample_index) sample: u32,
    @builtin(primitive_index) primitive: u32,
) -> PeelingOut {
    if (culled(v.material, front_facing)) {
        discard;
    }
    if (surface_base(v.material, v.uv, v.uv1).a < 0.0) {
        discard;
    }
    let z = v.position.z;
    // A front-to-back peel's depth test (Less against the cleared 1) never keeps the far
    // plane; the back-to-front one must drop it too.
    if (z >= 1.0) {
        discard;
    }
    let id = primitive + 1u;
    let mode = peeling.mode;
    if (mode != 0u) {
        let coord = vec2<i32>(v.position.xy);
        let pd = textureLoad(prev_depth, coord, {{AT_SAMPLE}});
        let pid = textureLoad(prev_ids, coord, {{AT_SAMPLE}}).x;
        if (mode == 1u) {
            if (z < pd || (z == pd && id <= pid)) {
                discard;
            }
        } else if (mode == 2u) {
            if (z > pd || (z == pd && id >= pid)) {
                discard;
            }
        } else if (z > pd || (z == pd && id > pid)) {
            discard;
        }
    }
    var out: PeelingOut;
    out.id = id;
    out.depth = z;
    return out;
}

// The ids of the layer being composited (the last `fs_peeling` pass's colour target); the
// compositing pipeline's group 1 holds only this binding.
@group(1) @binding(3) var layer_ids: {{IDS_TYPE}};

struct PeelingCompositeOut {
    @location(0) color: vec4<f32>,
    @builtin(sample_mask) mask: u32,
}

// `blend` and `depth`: as `fs_player_straight`, limited to the samples where triangle
// `primitive` is this layer's fragment.
@fragment
fn fs_peeling_composite(
    v: PlayerVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(primitive_index) primitive: u32,
) -> PeelingCompositeOut {
    let uv = player_uv(v);
    let coord = vec2<i32>(v.position.xy);
    let id = primitive + 1u;
    var mask = 0u;
    for (var s = 0u; s < {{SAMPLE_COUNT}}u; s = s + 1u) {
        if (textureLoad(layer_ids, coord, {{AT_S}}).x == id) {
            mask = mask | (1u << s);
        }
    }
    if (mask == 0u) {
        discard;
    }
    var out: PeelingCompositeOut;
    out.color = player_colour(v, front_facing, uv);
    out.mask = mask;
    return out;
}
