// Shared by every pipeline (recorder, player, reference): the vertex layout, the per-frame
// bindings, the ONE vertex transform and the ONE surface function. Every vertex shader that
// includes this marks its position @invariant, so all pipelines rasterize identical positions.

struct Frame {
    // Projection (f64 on the CPU, cast once).
    proj: mat4x4<f32>,
    // View-space direction towards the light (xyz), ambient term (w).
    light: vec4<f32>,
    // x: glass opacity, y: width, z: height, w: sample count.
    params: vec4<f32>,
}

struct MaterialGpu {
    base_color: vec4<f32>,
    // rgb: emissive; a: transmission.
    emissive: vec4<f32>,
    // x: alpha mode (0 opaque, 1 mask, 2 blend), y: alpha cutoff, z: double sided (0/1),
    // w: texture layer (< 0: none).
    params: vec4<f32>,
    // xy: scale from the material's texture uv to its layer's used region.
    uv_scale: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
// Bindings 1 and 2 (this frame's camera-relative node matrices, view × world, and the
// materials) come from a binding prelude per tier: storage.wgsl (storage buffers) or
// textures.wgsl (data textures, for GLES 3.0 / WebGL2). Both define `node_matrix(node)` and
// `material_at(index)`, so everything below is the same maths on every tier.
@group(0) @binding(3) var base_color_textures: texture_2d_array<f32>;
@group(0) @binding(4) var base_color_sampler: sampler;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) material: u32,
    @location(4) node: u32,
}

// The one vertex transform: local position → clip space.
fn transform_position(position: vec3<f32>, node: u32) -> vec4<f32> {
    return frame.proj * (node_matrix(node) * vec4<f32>(position, 1.0));
}

fn transform_normal(normal: vec3<f32>, node: u32) -> vec3<f32> {
    let m = node_matrix(node);
    return (m * vec4<f32>(normal, 0.0)).xyz;
}

// Base colour × texture at `uv`, with the recorded/played opacity rules: glass gets the glass
// opacity, opaque and mask materials alpha 1 (mask cut-off is tested on the texture alpha), blend
// materials their alpha. Returns alpha < 0 when a MASK fragment is cut away.
fn surface_base(material: u32, uv: vec2<f32>) -> vec4<f32> {
    let m = material_at(material);
    var color = m.base_color;
    if (m.params.w >= 0.0) {
        let layer = i32(m.params.w);
        let tuv = fract(uv) * m.uv_scale.xy;
        color = color * textureSampleLevel(base_color_textures, base_color_sampler, tuv, layer, 0.0);
    }
    let mode = u32(m.params.x);
    if (m.emissive.a > 0.0) {
        color.a = frame.params.x;
    } else if (mode == 0u) {
        color.a = 1.0;
    } else if (mode == 1u) {
        if (color.a < m.params.y) {
            color.a = -1.0;
        } else {
            color.a = 1.0;
        }
    }
    return color;
}

// Whether a fragment is discarded for facing: single-sided materials drop back faces.
fn culled(material: u32, front_facing: bool) -> bool {
    return material_at(material).params.z < 0.5 && !front_facing;
}

// Lit colour (linear, straight alpha): one directional light plus ambient, plus emissive.
fn shade(material: u32, base: vec4<f32>, view_normal: vec3<f32>, front_facing: bool) -> vec4<f32> {
    var n = normalize(view_normal + vec3<f32>(0.0, 0.0, 1e-12));
    if (!front_facing) {
        n = -n;
    }
    let diffuse = max(dot(n, normalize(frame.light.xyz)), 0.0);
    let lit = base.rgb * (frame.light.w + (1.0 - frame.light.w) * diffuse)
        + material_at(material).emissive.rgb;
    return vec4<f32>(lit, base.a);
}
