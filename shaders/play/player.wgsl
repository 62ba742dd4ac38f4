// The player's entry points (composed after COMMON): the baked index buffer through the one
// vertex transform and the one surface function. One pipeline for every material; the mode only
// changes the fragment output (straight or premultiplied alpha) and the pipeline's blend and
// depth state.

struct PlayerVarying {
    @invariant @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) material: u32,
    // Alpha from textures is evaluated at the pixel centre, as the recorder does.
    @location(1) @interpolate(perspective, center) uv: vec2<f32>,
    @location(2) normal: vec3<f32>,
    @location(3) @interpolate(perspective, center) uv1: vec2<f32>,
    // View-space tangent (xyz) and handedness (w) times the node's mirror sign.
    @location(4) tangent: vec4<f32>,
    // View-space position.
    @location(5) view_position: vec3<f32>,
}

// The player's vertex stage as a function (an entry point cannot be called): the presorted
// renderer's vertex-stage variant adds its test after it.
fn player_vertex(v: VertexIn) -> PlayerVarying {
    var out: PlayerVarying;
    out.position = transform_position(v.position, v.node);
    out.material = v.material;
    out.uv = v.uv;
    out.normal = transform_normal(v.normal, v.node);
    out.uv1 = v.uv1;
    out.tangent = vec4<f32>(
        transform_normal(v.tangent.xyz, v.node),
        v.tangent.w * node_handedness(v.node),
    );
    out.view_position = view_position(v.position, v.node);
    return out;
}

@vertex
fn vs_player(v: VertexIn) -> PlayerVarying {
    return player_vertex(v);
}

// The texture coordinates and their derivatives: call at the top of a fragment entry point,
// before anything that may discard (uniform control flow).
fn player_uv(v: PlayerVarying) -> SurfaceUv {
    return surface_uv(v.uv, v.uv1);
}

// Lit colour with straight alpha in [0, 1]; discards culled back faces and MASK cut-outs.
fn player_colour(v: PlayerVarying, front_facing: bool, uv: SurfaceUv) -> vec4<f32> {
    // The material's fields are read once (on the data-texture tier, one texel each).
    let m = material_at(v.material);
    if (culled_of(m, front_facing)) {
        discard;
    }
    let base = surface_base_of(m, v.uv, v.uv1);
    if (base.a < 0.0) {
        discard;
    }
    let c = shade(m, base, ShadeIn(v.normal, v.tangent, v.view_position, front_facing, uv));
    return vec4<f32>(c.rgb, clamp(c.a, 0.0, 1.0));
}

// `blend` and `depth`: straight alpha; the blend state composites over (src-alpha,
// one-minus-src-alpha).
@fragment
fn fs_player_straight(v: PlayerVarying, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let uv = player_uv(v);
    return player_colour(v, front_facing, uv);
}

// `saturate`: premultiplied alpha; the blend state composites under what is already drawn
// (one-minus-dst-alpha, one).
@fragment
fn fs_player_premultiplied(v: PlayerVarying, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let uv = player_uv(v);
    let c = player_colour(v, front_facing, uv);
    return vec4<f32>(c.rgb * c.a, c.a);
}
