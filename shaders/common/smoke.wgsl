// The GPU smoke test: one triangle through the shared vertex transform (the plain pass's
// `vs_plain`, composed before this), coloured by its material.

@fragment
fn fs_smoke(in: PlainVarying) -> @location(0) vec4<f32> {
    return material_at(in.material).base_color;
}
