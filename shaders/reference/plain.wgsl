// A plain pass for benchmarks: the shared vertex transform, depth test, one output per pixel
// (no per-sample shading, no peel test). What a peel pass costs is measured against this.

struct PlainVarying {
    @invariant @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) material: u32,
}

@vertex
fn vs_plain(v: VertexIn) -> PlainVarying {
    var out: PlainVarying;
    out.position = transform_position(v.position, v.node);
    out.material = v.material;
    return out;
}

@fragment
fn fs_plain(in: PlainVarying) -> @location(0) vec2<u32> {
    return vec2<u32>(in.material + 1u, 0u);
}
