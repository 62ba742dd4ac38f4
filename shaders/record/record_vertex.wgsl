// The recorder's vertex stage, shared by the peel (peel.wgsl) and the capture (capture.wgsl),
// so both rasterize the same positions with the same varyings: the one vertex transform, the
// material, and the texture coordinates that alpha is read with.

struct RecordVarying {
    @invariant @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) material: u32,
    // Alpha from textures is evaluated at the pixel centre, as the player evaluates it.
    @location(1) @interpolate(perspective, center) uv: vec2<f32>,
    @location(2) @interpolate(perspective, center) uv1: vec2<f32>,
}

@vertex
fn vs_record(v: VertexIn) -> RecordVarying {
    var out: RecordVarying;
    out.position = transform_position(v.position, v.node);
    out.material = v.material;
    out.uv = v.uv;
    out.uv1 = v.uv1;
    return out;
}
