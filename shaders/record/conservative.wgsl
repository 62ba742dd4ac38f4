// Conservative visibility (record --conservative): which triangles can win a sample when the
// sample pattern moves by up to `tolerance` pixels in x and y (another rasterizer's snapping,
// a modest resize)?
//
// Pass 1 (vs_occlude + fs_occlude, depth target, test Less): the opaque triangles as
// rasterized at the recorded pattern, each writing its plane's *farthest* depth over a box of
// ±(tolerance + REACH) px around the sample: per sample, the nearest opaque surface raised by
// its slope.
// Pass 2 (vs_full + fs_spread, per sample, R32Float target): the largest pass-1 depth over the
// samples within ±(tolerance + REACH) px (background, 1, beyond the image): a depth that the
// opaque surfaces are nearer than anywhere in the sample's ±tolerance box, as long as they
// leave no gap narrower than the sample spacing that no sample falls in (a surface of small
// triangles covers the box although none of them does alone, which a per-triangle test would
// never see).
// Pass 3 (vs_dilate + fs_mark, per sample): every triangle grown by the box (grow.wgsl), so it
// covers every sample whose box it touches; where its *nearest* depth over the box is not
// behind pass 2's depth, it may win the sample: its flag is set.
//
// Composed after grow.wgsl (group 1).

// How far beyond the tolerance the spread reaches: half the largest gap between samples of
// the standard patterns (1×: 1 px apart; 4×: 0.5 px), a little more.
const REACH: f32 = 0.55;

@vertex
fn vs_occlude(@builtin(vertex_index) vi: u32) -> ConsVarying {
    let tri = vi / 3u;
    if (!cons_occludes(cons_triangles[tri].w)) {
        return cons_dropped();
    }
    return cons_corner(tri, vi % 3u, 0.0);
}

@vertex
fn vs_dilate(@builtin(vertex_index) vi: u32) -> ConsVarying {
    return cons_corner(vi / 3u, vi % 3u, 1.0);
}

struct OccludeOut {
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_occlude(
    in: ConsVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(sample_index) sample: u32,
) -> OccludeOut {
    if (culled(in.material, front_facing)) {
        discard;
    }
    var out: OccludeOut;
    var z = in.position.z;
    if (in.plane.w > 0.5) {
        let reach = (cons.tol_px + vec2<f32>(REACH)) / cons.px_per_ndc;
        z = cons_plane_depth(in) + abs(in.plane.x) * reach.x + abs(in.plane.y) * reach.y;
    }
    out.depth = clamp(z, 0.0, 1.0);
    return out;
}

// Pass 1's depth (the spread pass's group 1: the tolerance, binding 0, and this).
@group(1) @binding(5) var surface: {{DEPTH_TYPE}};

@vertex
fn vs_full(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.5, 1.0);
}

// The standard sample positions within a pixel (Vulkan, D3D): 1× at the centre, 4× rotated.
fn sample_position(k: u32) -> vec2<f32> {
    if ({{SAMPLE_COUNT}}u == 1u) {
        return vec2<f32>(0.5, 0.5);
    }
    var p = array<vec2<f32>, 4>(
        vec2<f32>(0.375, 0.125),
        vec2<f32>(0.875, 0.375),
        vec2<f32>(0.125, 0.625),
        vec2<f32>(0.625, 0.875),
    );
    return p[k];
}

@fragment
fn fs_spread(
    @builtin(position) position: vec4<f32>,
    @builtin(sample_index) sample: u32,
) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(surface));
    let here = vec2<i32>(position.xy);
    let me = vec2<f32>(here) + sample_position(sample);
    let reach = cons.tol_px + vec2<f32>(REACH);
    let r = i32(ceil(max(reach.x, reach.y)));
    var m = 0.0;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let c = here + vec2<i32>(dx, dy);
            for (var k = 0u; k < {{SAMPLE_COUNT}}u; k++) {
                let d = abs(vec2<f32>(c) + sample_position(k) - me);
                if (d.x > reach.x || d.y > reach.y) {
                    continue;
                }
                if (any(c < vec2<i32>(0)) || any(c >= size)) {
                    // Beyond the image nothing is known: no occluder.
                    m = 1.0;
                } else {
                    m = max(m, textureLoad(surface, c, {{AT_K}}));
                }
            }
        }
    }
    return vec4<f32>(m, 0.0, 0.0, 0.0);
}

// Pass 3's bindings: pass 2's depth and the per-triangle flags.
@group(1) @binding(3) var occluder: {{OCCLUDER_TYPE}};
@group(1) @binding(4) var<storage, read_write> flags: array<atomic<u32>>;

@fragment
fn fs_mark(
    in: ConsVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(sample_index) sample: u32,
) -> @location(0) vec4<f32> {
    if (culled(in.material, front_facing)) {
        discard;
    }
    var z = in.position.z;
    if (in.plane.w > 0.5) {
        if (!cons_inside(in, 1.0)) {
            discard;
        }
        z = cons_plane_depth(in) - cons_slack(in.plane, cons.tol_px);
    }
    let coord = vec2<i32>(in.position.xy);
    let occ = textureLoad(occluder, coord, {{AT_SAMPLE}}).x;
    // A little slack for rounding: the peel interpolates depth, this pass evaluates a plane.
    if (z <= occ + 1e-6) {
        atomicStore(&flags[in.tri], 1u);
    }
    return vec4<f32>(0.0);
}
