// The GPU smoke test: one triangle through the shared vertex transform.

struct Out {
    @invariant @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) material: u32,
}

@vertex
fn vs_main(v: VertexIn) -> Out {
    var out: Out;
    out.position = transform_position(v.position, v.node);
    out.material = v.material;
    return out;
}

@fragment
fn fs_main(in: Out) -> @location(0) vec4<f32> {
    return materials[in.material].base_color;
}
