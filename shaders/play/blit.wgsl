const UNDER: bool = {{UNDER}};
const ENCODE_SRGB: bool = {{ENCODE_SRGB}};
const BACKGROUND: vec3<f32> = vec3<f32>({{BACKGROUND}});
// The copy from the player's linear `Rgba16Float` frame to a window's surface (the window
// viewer): one triangle over the viewport, each pixel reading the texel under it (nearest;
// stretched while a resize settles). `UNDER` composites the background under the accumulated
// colour (`saturate` mode: `rgb + (1 - a)·background`, as the headless player does); the
// output is opaque and, with `ENCODE_SRGB`, sRGB-encoded here (written through a non-sRGB
// view). `blit_shader` in lib.rs defines UNDER, ENCODE_SRGB and BACKGROUND before this.
@group(0) @binding(0) var frame: texture_2d<f32>;

struct VsOut {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs_blit(@builtin(vertex_index) i: u32) -> VsOut {
    // (0, 0), (2, 0), (0, 2) in uv: a triangle covering the viewport, uv (0, 0) top left.
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var out: VsOut;
    out.position = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    out.uv = uv;
    return out;
}

fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

@fragment
fn fs_blit(in: VsOut) -> @location(0) vec4<f32> {
    let dims = textureDimensions(frame);
    let texel = min(vec2<u32>(in.uv * vec2<f32>(dims)), dims - vec2<u32>(1u));
    let c = textureLoad(frame, texel, 0);
    var rgb = c.rgb;
    if UNDER {
        rgb = rgb + (1.0 - c.a) * BACKGROUND;
    }
    rgb = clamp(rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    if ENCODE_SRGB {
        rgb = srgb_encode(rgb);
    }
    return vec4<f32>(rgb, 1.0);
}
