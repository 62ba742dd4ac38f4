// The exact reference's compositing entry points (composed after COMMON and PLAYER, so the
// colour is the player's own `player_colour`, evaluated once per pixel like the player does).
// One pass per peel layer: each triangle of the layer writes only the samples where the peel
// found it in that layer, through the sample mask; the hardware ANDs that mask with coverage.
// Nothing here reads `sample_index`, so shading stays per pixel, as in the player.

struct Composite {
    // Image width and sample count of the layer's id list.
    width: u32,
    samples: u32,
    pad0: u32,
    pad1: u32,
}

@group(1) @binding(0) var<uniform> composite: Composite;
// Per sample of this layer: scene id + 1 of its fragment, 0 where the layer has none.
// Sample s of pixel (x, y) is entry (y * width + x) * samples + s.
@group(1) @binding(1) var<storage, read> layer_ids: array<u32>;
// Scene id of each triangle of this draw (primitive_index restarts at 0 in every draw).
@group(1) @binding(2) var<storage, read> draw_ids: array<u32>;

// The samples of this pixel at which triangle `primitive` of the draw is this layer's fragment.
fn layer_mask(position: vec4<f32>, primitive: u32) -> u32 {
    let id = draw_ids[primitive] + 1u;
    let coord = vec2<u32>(position.xy);
    let first = (coord.y * composite.width + coord.x) * composite.samples;
    var mask = 0u;
    for (var s = 0u; s < composite.samples; s = s + 1u) {
        if (layer_ids[first + s] == id) {
            mask = mask | (1u << s);
        }
    }
    return mask;
}

struct ReferenceOut {
    @location(0) color: vec4<f32>,
    @builtin(sample_mask) mask: u32,
}

// `player_colour` at the samples where triangle `primitive` is the layer's fragment; discards
// where it is at none.
fn layer_colour(v: PlayerVarying, front_facing: bool, primitive: u32) -> ReferenceOut {
    let uv = player_uv(v);
    let mask = layer_mask(v.position, primitive);
    if (mask == 0u) {
        discard;
    }
    var out: ReferenceOut;
    out.color = player_colour(v, front_facing, uv);
    out.mask = mask;
    return out;
}

// `blend` and `depth`: as `fs_player_straight`, limited to the layer's samples.
@fragment
fn fs_reference_straight(
    v: PlayerVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(primitive_index) primitive: u32,
) -> ReferenceOut {
    return layer_colour(v, front_facing, primitive);
}

// `saturate`: as `fs_player_premultiplied`, limited to the layer's samples.
@fragment
fn fs_reference_premultiplied(
    v: PlayerVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(primitive_index) primitive: u32,
) -> ReferenceOut {
    var out = layer_colour(v, front_facing, primitive);
    let c = out.color;
    out.color = vec4<f32>(c.rgb * c.a, c.a);
    return out;
}
