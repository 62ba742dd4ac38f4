// Shared by every pipeline (recorder, player, reference): the vertex layout, the per-frame
// bindings, the ONE vertex transform and the ONE surface function. Every vertex shader that
// includes this marks its position @invariant, so all pipelines rasterize identical positions.

struct Frame {
    // Projection (f64 on the CPU, cast once).
    proj: mat4x4<f32>,
    // `basic` shading: view-space direction towards the light (xyz), ambient term (w).
    light: vec4<f32>,
    // x: glass opacity, y: width, z: height, w: sample count.
    params: vec4<f32>,
    // The view-to-world rotation (the inverse of the camera's rotation): environment lookups
    // are in world space, normals in view space.
    view_to_world: mat3x3<f32>,
}

// The light of the baked file's environment (the same for every frame).
struct Lighting {
    // Irradiance / π as order-2 spherical harmonics in world space (rgb), in the order
    // Y00, Y1-1, Y10, Y11, Y2-2, Y2-1, Y20, Y21, Y22.
    sh: array<vec4<f32>, 9>,
    // World-space direction towards the sun (xyz); w: 1 with a sun, 0 without.
    sun_direction: vec4<f32>,
    // Sun radiance (rgb).
    sun_color: vec4<f32>,
    // x: exposure, y: shading (0 basic, 1 pbr), z: tone map (0 Khronos PBR Neutral, 1 ACES),
    // w: the prefiltered radiance's last mip level (levels − 1).
    params: vec4<f32>,
}

struct MaterialGpu {
    base_color: vec4<f32>,
    // rgb: emissive (factor × strength); a: transmission.
    emissive: vec4<f32>,
    // x: alpha mode (0 opaque, 1 mask, 2 blend), y: alpha cutoff, z: double sided (0/1),
    // w: base-colour texture layer (< 0: none).
    params: vec4<f32>,
    // x: metallic, y: perceptual roughness, z: normal scale, w: occlusion strength.
    pbr: vec4<f32>,
    // x: clearcoat, y: clearcoat roughness.
    coat: vec4<f32>,
    // Per texture slot: the KHR_texture_transform rows (xyz; `u' = u_row · (u, v, 1)`), the
    // texture's layer (u_row.w, < 0: none), its texture coordinate set (v_row.w), the uv scale
    // of its layer's used corner (scale.xy) and its array (scale.z: 0 the sRGB array, 1 the
    // linear one; the texture's own colour space decides).
    base_u: vec4<f32>,
    base_v: vec4<f32>,
    base_scale: vec4<f32>,
    mr_u: vec4<f32>,
    mr_v: vec4<f32>,
    mr_scale: vec4<f32>,
    normal_u: vec4<f32>,
    normal_v: vec4<f32>,
    normal_scale: vec4<f32>,
    occlusion_u: vec4<f32>,
    occlusion_v: vec4<f32>,
    occlusion_scale: vec4<f32>,
    emissive_u: vec4<f32>,
    emissive_v: vec4<f32>,
    emissive_scale: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
// Bindings 1 and 2 (this frame's camera-relative node matrices, view × world, and the
// materials) come from a binding prelude per tier: storage.wgsl (storage buffers) or
// textures.wgsl (data textures, for GLES 3.0 / WebGL2). Both define `node_matrix(node)` and
// `material_at(index)`, so everything below is the same maths on every tier.
// Colour-encoded textures (base colour, emissive; Rgba8UnormSrgb) with their mips.
@group(0) @binding(3) var srgb_textures: texture_2d_array<f32>;
@group(0) @binding(4) var material_sampler: sampler;
// Linear data textures (metallic-roughness, normal, occlusion; Rgba8Unorm) with their mips.
@group(0) @binding(6) var linear_textures: texture_2d_array<f32>;
@group(0) @binding(7) var<uniform> lighting: Lighting;
// Prefiltered radiance, equirectangular (row 0 at the zenith), level k for roughness
// k / (levels − 1).
@group(0) @binding(8) var environment: texture_2d<f32>;
@group(0) @binding(9) var environment_sampler: sampler;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) material: u32,
    @location(4) node: u32,
    @location(5) tangent: vec4<f32>,
    @location(6) uv1: vec2<f32>,
}

// The one vertex transform: local position → clip space.
fn transform_position(position: vec3<f32>, node: u32) -> vec4<f32> {
    return frame.proj * (node_matrix(node) * vec4<f32>(position, 1.0));
}

fn transform_normal(normal: vec3<f32>, node: u32) -> vec3<f32> {
    let m = node_matrix(node);
    return (m * vec4<f32>(normal, 0.0)).xyz;
}

// −1 where a node's matrix mirrors (its upper 3×3 has a negative determinant), else 1. The
// matrix is view × world and the view only rotates, so this is the world transform's sign.
// Vertex attributes stay in node-local space (the importer only reverses the winding of
// mirrored instances, so front faces and `transform_normal` are already right there), but a
// bitangent built as cross(n, t) in view space comes out reversed under a mirror: the tangent's
// handedness is multiplied by this once, in the vertex stage.
fn node_handedness(node: u32) -> f32 {
    let m = node_matrix(node);
    if (dot(cross(m[0].xyz, m[1].xyz), m[2].xyz) < 0.0) {
        return -1.0;
    }
    return 1.0;
}

// View-space position (the camera at the origin).
fn view_position(position: vec3<f32>, node: u32) -> vec3<f32> {
    return (node_matrix(node) * vec4<f32>(position, 1.0)).xyz;
}

// A texture slot's coordinate before wrapping: its set (0: uv, 1: uv1) through its transform.
fn slot_uv(u_row: vec4<f32>, v_row: vec4<f32>, uv: vec2<f32>, uv1: vec2<f32>) -> vec2<f32> {
    var c = uv;
    if (v_row.w > 0.5) {
        c = uv1;
    }
    return vec2<f32>(dot(u_row.xyz, vec3<f32>(c, 1.0)), dot(v_row.xyz, vec3<f32>(c, 1.0)));
}

// Base colour × texture at level 0, with the recorded/played opacity rules: glass gets the
// glass opacity, opaque and mask materials alpha 1 (mask cut-off is tested on the texture
// alpha), blend materials their alpha. Returns alpha < 0 when a MASK fragment is cut away.
// This alone decides visibility (recorder, player, reference): level 0 at the pixel centre.
fn surface_base(material: u32, uv: vec2<f32>, uv1: vec2<f32>) -> vec4<f32> {
    return surface_base_of(material_at(material), uv, uv1);
}

// `surface_base` of a material already read (`material_at`).
fn surface_base_of(m: MaterialGpu, uv: vec2<f32>, uv1: vec2<f32>) -> vec4<f32> {
    var color = m.base_color;
    if (m.params.w >= 0.0) {
        let layer = i32(m.params.w);
        let tuv = fract(slot_uv(m.base_u, m.base_v, uv, uv1)) * m.base_scale.xy;
        if (m.base_scale.z > 0.5) {
            color = color * textureSampleLevel(linear_textures, material_sampler, tuv, layer, 0.0);
        } else {
            color = color * textureSampleLevel(srgb_textures, material_sampler, tuv, layer, 0.0);
        }
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
    return culled_of(material_at(material), front_facing);
}

// `culled` of a material already read.
fn culled_of(m: MaterialGpu, front_facing: bool) -> bool {
    return m.params.z < 0.5 && !front_facing;
}

// Texture coordinates and their screen-space derivatives, taken at the top of a fragment
// entry point (uniform control flow), so colour textures can use their mips.
struct SurfaceUv {
    uv: vec2<f32>,
    uv1: vec2<f32>,
    uv_dx: vec2<f32>,
    uv_dy: vec2<f32>,
    uv1_dx: vec2<f32>,
    uv1_dy: vec2<f32>,
}

fn surface_uv(uv: vec2<f32>, uv1: vec2<f32>) -> SurfaceUv {
    return SurfaceUv(uv, uv1, dpdx(uv), dpdy(uv), dpdx(uv1), dpdy(uv1));
}

// A texture slot sampled with its mips (gradients of the unwrapped coordinate, scaled to the
// layer's corner) from the array its `scale.z` names. Returns `fallback` where the slot has
// no texture.
fn sample_slot(
    u_row: vec4<f32>,
    v_row: vec4<f32>,
    scale: vec4<f32>,
    s: SurfaceUv,
    fallback: vec4<f32>,
) -> vec4<f32> {
    if (u_row.w < 0.0) {
        return fallback;
    }
    var dx = s.uv_dx;
    var dy = s.uv_dy;
    if (v_row.w > 0.5) {
        dx = s.uv1_dx;
        dy = s.uv1_dy;
    }
    let tuv = fract(slot_uv(u_row, v_row, s.uv, s.uv1)) * scale.xy;
    let gx = vec2<f32>(dot(u_row.xy, dx), dot(v_row.xy, dx)) * scale.xy;
    let gy = vec2<f32>(dot(u_row.xy, dy), dot(v_row.xy, dy)) * scale.xy;
    let layer = i32(u_row.w);
    if (scale.z > 0.5) {
        return textureSampleGrad(linear_textures, material_sampler, tuv, layer, gx, gy);
    }
    return textureSampleGrad(srgb_textures, material_sampler, tuv, layer, gx, gy);
}

// A normal texture's tangent-space xy (x along +u, y along −v: glTF's "+Y up" in the image)
// brought into the mesh's tangent frame, which follows the mesh's uv, when the slot's
// KHR_texture_transform (rows `u_row`, `v_row`: u' = L·uv + o) turns the texture's axes
// against it. In the (u, −v) frame the linear part is L' = F·L·F (F = diag(1, −1)); its
// orthogonal polar factor Q (the rotation, or the reflection for a mirroring scale, nearest
// to L') maps the mesh's axes to the texture's, and the xy of a map pre-rotated by Q in the
// image comes back as Qᵀ·xy. Scale is left out on purpose: a non-uniform scale stretches the
// bumps but the map keeps its slopes (what tiling a detail map means to its author; the exact
// gradient rule Lᵀ would make a map tiled ten times ten times steeper), and Q of R·S is R for
// any positive scales S. A singular L leaves xy as it is.
fn normal_xy_in_mesh_frame(u_row: vec4<f32>, v_row: vec4<f32>, xy: vec2<f32>) -> vec2<f32> {
    let a = u_row.x;
    let b = -u_row.y;
    let c = -v_row.x;
    let d = v_row.y;
    // Rows of Q: (p, r) and s·(−r, p), s = ±1 the sign of det L'.
    var s = 1.0;
    var p = a + d;
    var r = b - c;
    if (a * d - b * c < 0.0) {
        s = -1.0;
        p = a - d;
        r = b + c;
    }
    let len = sqrt(p * p + r * r);
    if (len < 1e-20) {
        return xy;
    }
    // Qᵀ·xy = x·row0 + y·row1.
    return (xy.x * vec2<f32>(p, r) + xy.y * s * vec2<f32>(-r, p)) / len;
}

// Everything `shade` needs about the fragment besides its material and base colour.
struct ShadeIn {
    // View-space interpolated normal, tangent (xyz, w: handedness) and position.
    normal: vec3<f32>,
    tangent: vec4<f32>,
    position: vec3<f32>,
    front_facing: bool,
    uv: SurfaceUv,
}

const PI: f32 = 3.14159265;

// Irradiance / π from the spherical harmonics at world-space unit normal `n`.
fn sh_irradiance(n: vec3<f32>) -> vec3<f32> {
    let x = n.x;
    let y = n.y;
    let z = n.z;
    var e = lighting.sh[0].rgb * 0.282095;
    e += lighting.sh[1].rgb * (0.488603 * y);
    e += lighting.sh[2].rgb * (0.488603 * z);
    e += lighting.sh[3].rgb * (0.488603 * x);
    e += lighting.sh[4].rgb * (1.092548 * x * y);
    e += lighting.sh[5].rgb * (1.092548 * y * z);
    e += lighting.sh[6].rgb * (0.315392 * (3.0 * z * z - 1.0));
    e += lighting.sh[7].rgb * (1.092548 * x * z);
    e += lighting.sh[8].rgb * (0.546274 * (x * x - y * y));
    return max(e, vec3<f32>(0.0));
}

// Prefiltered radiance along world-space unit direction `d` for perceptual roughness `r`.
fn environment_radiance(direction: vec3<f32>, r: f32) -> vec3<f32> {
    let d = normalize(direction + vec3<f32>(0.0, 1e-12, 0.0));
    let phi = atan2(d.z, d.x);
    let u = fract(phi / (2.0 * PI) + 1.0);
    let v = acos(clamp(d.y, -1.0, 1.0)) / PI;
    let lod = clamp(r, 0.0, 1.0) * lighting.params.w;
    return textureSampleLevel(environment, environment_sampler, vec2<f32>(u, v), lod).rgb;
}

// The split-sum's scale and bias on F0 without a lookup table: Karis' analytic fit
// ("Physically Based Shading on Mobile", 2014).
fn env_brdf(f0: vec3<f32>, r: f32, n_dot_v: f32) -> vec3<f32> {
    let c0 = vec4<f32>(-1.0, -0.0275, -0.572, 0.022);
    let c1 = vec4<f32>(1.0, 0.0425, 1.04, -0.04);
    let k = r * c0 + c1;
    let a004 = min(k.x * k.x, exp2(-9.28 * n_dot_v)) * k.x + k.y;
    let ab = vec2<f32>(-1.04, 1.04) * a004 + k.zw;
    return f0 * ab.x + ab.y;
}

fn fresnel_schlick(f0: vec3<f32>, v_dot_h: f32) -> vec3<f32> {
    return f0 + (vec3<f32>(1.0) - f0) * pow(1.0 - v_dot_h, 5.0);
}

// GGX distribution × height-correlated Smith visibility, for perceptual roughness `r`.
fn ggx_dv(n_dot_h: f32, n_dot_v: f32, n_dot_l: f32, r: f32) -> f32 {
    let a = max(r * r, 1e-3);
    let a2 = a * a;
    let f = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * f * f);
    let gv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    let gl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    return d * 0.5 / max(gv + gl, 1e-6);
}

// Khronos PBR Neutral tone mapping (linear in, linear out, in [0, 1]).
fn tone_map_neutral(c: vec3<f32>) -> vec3<f32> {
    let start = 0.8 - 0.04;
    let desaturation = 0.15;
    let x = min(c.r, min(c.g, c.b));
    var offset = 0.04;
    if (x < 0.08) {
        offset = x - 6.25 * x * x;
    }
    var color = c - offset;
    let peak = max(color.r, max(color.g, color.b));
    if (peak < start) {
        return color;
    }
    let d = 1.0 - start;
    let new_peak = 1.0 - d * d / (peak + d - start);
    color = color * (new_peak / peak);
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(color, vec3<f32>(new_peak), g);
}

// ACES filmic tone mapping (Narkowicz's fit of the reference curve).
fn tone_map_aces(c: vec3<f32>) -> vec3<f32> {
    return (c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14);
}

// `basic` shading: one view-space directional light plus ambient, plus the emissive factor,
// no tone map (what trisort drew before PBR; the C host draws this).
fn shade_basic(m: MaterialGpu, base: vec4<f32>, s: ShadeIn) -> vec4<f32> {
    var n = normalize(s.normal + vec3<f32>(0.0, 0.0, 1e-12));
    if (!s.front_facing) {
        n = -n;
    }
    let diffuse = max(dot(n, normalize(frame.light.xyz)), 0.0);
    let lit = base.rgb * (frame.light.w + (1.0 - frame.light.w) * diffuse)
        + m.emissive.rgb;
    return vec4<f32>(lit, base.a);
}

// `pbr` shading: glTF metallic-roughness with normal, occlusion and emissive maps and a
// clearcoat layer, lit by the environment (prefiltered radiance × analytic split sum,
// spherical-harmonic irradiance) and the optional sun; exposed and tone mapped into [0, 1].
fn shade_pbr(m: MaterialGpu, base: vec4<f32>, s: ShadeIn) -> vec4<f32> {
    let white = vec4<f32>(1.0);
    // Colour at the mips the derivatives ask for; `base` (level 0) keeps the alpha.
    var albedo = m.base_color.rgb;
    if (m.params.w >= 0.0) {
        albedo = albedo * sample_slot(m.base_u, m.base_v, m.base_scale, s.uv, white).rgb;
    }
    let mr = sample_slot(m.mr_u, m.mr_v, m.mr_scale, s.uv, white);
    let metallic = clamp(m.pbr.x * mr.b, 0.0, 1.0);
    let rough = clamp(m.pbr.y * mr.g, 0.03, 1.0);

    // The front face's frame; a back face (double-sided) reverses the mapped normal whole, as
    // glTF asks (negating only the geometric normal would mirror the map's x on back faces).
    var ng = normalize(s.normal + vec3<f32>(0.0, 0.0, 1e-12));
    var n = ng;
    if (m.normal_u.w >= 0.0 && dot(s.tangent.xyz, s.tangent.xyz) > 1e-12) {
        let tex = sample_slot(m.normal_u, m.normal_v, m.normal_scale, s.uv, white).xyz;
        let xy = normal_xy_in_mesh_frame(m.normal_u, m.normal_v, tex.xy * 2.0 - 1.0);
        let tn = vec3<f32>(xy * m.pbr.z, tex.z * 2.0 - 1.0);
        let t = normalize(s.tangent.xyz - ng * dot(ng, s.tangent.xyz) + vec3<f32>(1e-12, 0.0, 0.0));
        // Handedness × the node's mirror sign (`vs_player`).
        var sign = 1.0;
        if (s.tangent.w < 0.0) {
            sign = -1.0;
        }
        let b = cross(ng, t) * sign;
        n = normalize(t * tn.x + b * tn.y + ng * max(tn.z, 1e-4));
    }
    if (!s.front_facing) {
        ng = -ng;
        n = -n;
    }
    let v = normalize(-s.position + vec3<f32>(0.0, 0.0, 1e-12));
    let n_dot_v = clamp(dot(n, v), 1e-4, 1.0);
    let to_world = frame.view_to_world;

    let f0 = mix(vec3<f32>(0.04), albedo, metallic);
    // Transmission (glass) replaces the diffuse lobe: light passes through instead of
    // scattering, so glass shows only what it reflects (and what blends through it).
    let transmission = clamp(m.emissive.a, 0.0, 1.0);
    let diffuse_colour = albedo * (1.0 - metallic) * (1.0 - transmission);
    let occlusion = 1.0 + m.pbr.w
        * (sample_slot(m.occlusion_u, m.occlusion_v, m.occlusion_scale, s.uv, white).r - 1.0);

    // Image-based light.
    let r = reflect(-v, n);
    let specular_env = environment_radiance(to_world * r, rough) * env_brdf(f0, rough, n_dot_v);
    let diffuse_env = diffuse_colour * sh_irradiance(normalize(to_world * n));
    var colour = (diffuse_env + specular_env) * occlusion;

    // The sun.
    let sun = lighting.sun_direction.w > 0.5;
    var l = vec3<f32>(0.0, 0.0, 1.0);
    if (sun) {
        l = normalize(transpose(to_world) * lighting.sun_direction.xyz);
        let n_dot_l = dot(n, l);
        if (n_dot_l > 0.0) {
            let h = normalize(l + v);
            let f = fresnel_schlick(f0, clamp(dot(v, h), 0.0, 1.0));
            let spec = f * ggx_dv(clamp(dot(n, h), 0.0, 1.0), n_dot_v, n_dot_l, rough);
            let diff = (vec3<f32>(1.0) - f) * diffuse_colour / PI;
            colour += (diff + spec) * lighting.sun_color.rgb * n_dot_l;
        }
    }

    // Clearcoat: a second GGX lobe on the geometric normal, F0 0.04, over the base.
    let coat = m.coat.x;
    if (coat > 0.0) {
        let coat_rough = clamp(m.coat.y, 0.03, 1.0);
        let c_dot_v = clamp(dot(ng, v), 1e-4, 1.0);
        let fc = 0.04 + 0.96 * pow(1.0 - c_dot_v, 5.0);
        let rc = reflect(-v, ng);
        var coat_light = environment_radiance(to_world * rc, coat_rough)
            * env_brdf(vec3<f32>(0.04), coat_rough, c_dot_v);
        if (sun) {
            let c_dot_l = dot(ng, l);
            if (c_dot_l > 0.0) {
                let h = normalize(l + v);
                let f = 0.04 + 0.96 * pow(1.0 - clamp(dot(v, h), 0.0, 1.0), 5.0);
                coat_light += f * ggx_dv(clamp(dot(ng, h), 0.0, 1.0), c_dot_v, c_dot_l, coat_rough)
                    * lighting.sun_color.rgb * c_dot_l;
            }
        }
        colour = colour * (1.0 - coat * fc) + coat * coat_light;
    }

    let emissive_tex = sample_slot(m.emissive_u, m.emissive_v, m.emissive_scale, s.uv, white);
    colour += m.emissive.rgb * emissive_tex.rgb;

    colour = max(colour * lighting.params.x, vec3<f32>(0.0));
    if (lighting.params.z > 0.5) {
        colour = tone_map_aces(colour);
    } else {
        colour = tone_map_neutral(colour);
    }
    colour = clamp(colour, vec3<f32>(0.0), vec3<f32>(1.0));
    // Glass is drawn at the glass opacity, and blending scales its colour by that opacity; what
    // glass shows is reflection added over what lies behind, so its colour is divided by the
    // opacity (up to white) to reach the screen at full strength. The base colour's tint of the
    // light passing through is not modelled (over-blending cannot multiply what lies behind).
    if (transmission > 0.0 && base.a > 0.0) {
        colour = min(colour / base.a, vec3<f32>(1.0));
    }
    return vec4<f32>(colour, base.a);
}

// The surface model a pipeline is specialised to (`shading_constants`): 0 basic, 1 pbr, 2 (the
// default) as `lighting` says at run time. A specialised pipeline compiles only its model: a
// CPU rasterizer (llvmpipe) runs both sides of a uniform branch, so the run-time choice made
// the basic model cost as much as PBR there.
override SHADING_MODEL: u32 = 2u;

// Lit colour (linear, straight alpha) of a fragment of material `m` (`material_at`, read once
// per fragment) whose `surface_base` is `base`: `basic` or `pbr` as the pipeline's
// `SHADING_MODEL`, or the lighting, says.
fn shade(m: MaterialGpu, base: vec4<f32>, s: ShadeIn) -> vec4<f32> {
    if (SHADING_MODEL == 1u || (SHADING_MODEL == 2u && lighting.params.y > 0.5)) {
        return shade_pbr(m, base, s);
    }
    return shade_basic(m, base, s);
}
