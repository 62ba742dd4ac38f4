// The grown capture (record --conservative, phase 2): the capture of capture.wgsl over the
// triangles grown by the tolerance box (grow.wgsl, group 2), the one-pass form of the grown
// peel (peel_grown.wgsl) with the same fragments: each sample's list holds every triangle that
// could cover the sample when the pattern moves within the tolerance, at the depth of its
// plane at the sample (extended past its edges, clamped to [0, 1]); the host sorts each list by
// (depth, id) as the grown peel's layers would come. Ids are positions in the drawn list (the
// non-indexed draw's triangle); opacity is 1 (phase 2 reads none).

@fragment
fn fs_capture_grown(
    in: ConsVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(sample_index) sample: u32,
) {
    let grown = cons_grown_depth(in, front_facing);
    let z = grown.x;
    // The grown peel writes z as its depth and tests `Less` against the cleared 1.0.
    if (grown.y < 0.5 || !(z < 1.0)) {
        return;
    }
    capture_push(in.position.xy, sample, z, in.tri + 1u, 1.0);
}

// The envelope capture (record --conservative, phase 1): the grown capture's fragments with
// what the host needs to bound, per sample, how far the nearest opaque surface can lie
// anywhere in the sample's tolerance box (recorder/src/envelope.rs). A node holds the plane's
// nearest depth over the depth box (as its depth), its farthest (as its opacity) and, above
// the id's ENVELOPE_ID_BITS, the flags below.
//
// Two allowances for rasterizers other than the recording one, both measured on SwiftShader
// (the browser's WebGL2; BENCHMARKS § Exactness across rasterizers):
// - depth is compared over the sample's box grown by ENVELOPE_DEPTH_REACH more: a rasterizer
//   may take a triangle's depth at another point of the pixel than the sample (a triangle
//   0.0035 behind a closed fan that covers it won a sample there, and no longer did when moved
//   2 % farther along the view rays);
// - a triangle whose facing snapping may turn (bit 3 of `closable`) is kept either facing and
//   never occludes.

// Per triangle of the drawn list: for edge k (corner k to corner k + 1), the vertex of the
// triangle across it opposite the edge, or 0xffffffff where the edge has no single neighbour.
@group(2) @binding(3) var<storage, read> cons_opposite: array<vec4<u32>>;

// Flag bits above the id: the triangle occludes (opaque, its plane valid); edge k crosses the
// box (bits 1–3); edge k is closable (bits 4–6).
// Bits of a node's id word that hold the id (trisort_gpu::ENVELOPE_ID_BITS, substituted).
const ENVELOPE_ID_BITS: u32 = ENVELOPE_ID_BITS_VALUEu;
const ENVELOPE_OCCLUDES: u32 = 1u;
// Pixels beyond the tolerance over which depths are compared: from a sample to its pixel's
// centre is at most 0.375 px at 4× (0 at 1×); half a pixel covers that with some margin.
const ENVELOPE_DEPTH_REACH: f32 = 0.5;

// Corner `corner` of grown triangle `vi / 3`, with its closable edges: those whose neighbour's
// opposite vertex lies strictly on the other side of the edge than the triangle's own third
// corner (the two cover both sides of it; a fold, a border or a neighbour reaching behind the
// camera is not closable).
@vertex
fn vs_envelope(@builtin(vertex_index) vi: u32) -> ConsVarying {
    let tri = vi / 3u;
    var out = cons_corner(tri, vi % 3u, 1.0);
    if (out.plane.w < 0.5) {
        return out;
    }
    let opposite = cons_opposite[tri];
    let p = array<vec2<f32>, 3>(out.p01.xy, out.p01.zw, out.p2);
    var closable = 0u;
    // Bit 3: its facing may turn on a rasterizer that snaps each corner to its own grid of
    // 1/16 px (Vulkan's and GLES's least sub-pixel precision): twice its area is within what
    // moving the corners by up to 1/32 px can change it by.
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let moved = 2.0 * sqrt(2.0) / 32.0;
    if (abs(cross2(e1, e2)) <= moved * (length(e1) + length(e2)) + moved * moved) {
        closable |= 8u;
    }
    for (var k = 0u; k < 3u; k++) {
        let o = opposite[k];
        if (o == 0xffffffffu) {
            continue;
        }
        let v = cons_vertices[o];
        let clip = transform_position(v.xyz, bitcast<u32>(v.w));
        if (clip.w <= 1e-6) {
            continue;
        }
        let q = clip.xy / clip.w * cons.px_per_ndc;
        let a = p[k];
        let d = p[(k + 1u) % 3u] - a;
        let own = cross2(d, p[(k + 2u) % 3u] - a);
        let theirs = cross2(d, q - a);
        if (own * theirs < 0.0) {
            closable |= 1u << k;
        }
    }
    out.closable = closable;
    return out;
}

// Whether segment a–b meets the box of half-size `h` around `c` (separating axes: x, y and the
// segment's normal). The ends are put in one order first, so the two triangles sharing an edge
// decide alike.
fn envelope_crosses(a0: vec2<f32>, b0: vec2<f32>, c: vec2<f32>, h: vec2<f32>) -> bool {
    var a = a0;
    var b = b0;
    if (b.x < a.x || (b.x == a.x && b.y < a.y)) {
        a = b0;
        b = a0;
    }
    if (any(max(a, b) < c - h) || any(min(a, b) > c + h)) {
        return false;
    }
    let n = vec2<f32>(b.y - a.y, a.x - b.x);
    return abs(dot(n, c - a)) <= abs(n.x) * h.x + abs(n.y) * h.y;
}

@fragment
fn fs_capture_envelope(
    in: ConsVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(sample_index) sample: u32,
) {
    // Either facing where snapping may turn it (bit 3 of closable); then it never occludes.
    let turns = (in.closable & 8u) != 0u;
    if (!turns && culled(in.material, front_facing)) {
        return;
    }
    var near = in.position.z;
    var far = in.position.z;
    var flags = 0u;
    if (in.plane.w > 0.5) {
        if (!cons_inside(in, 1.0)) {
            return;
        }
        // The plane over the depth box: ±(tolerance + ENVELOPE_DEPTH_REACH) px (not clamped
        // to the corners' depth range, as a depth taken elsewhere in the pixel extrapolates).
        let z = cons_plane_depth(in);
        let reach = (cons.tol_px + vec2<f32>(ENVELOPE_DEPTH_REACH)) / cons.px_per_ndc;
        let slack = abs(in.plane.x) * reach.x + abs(in.plane.y) * reach.y;
        near = z - slack;
        far = z + slack;
        // Only a plane inside the depth range over the whole box occludes there: where the
        // near or far plane clips it, it covers nothing.
        let inside = near >= 0.0 && far <= 1.0;
        if (!turns && inside && cons_occludes(in.material)) {
            flags = ENVELOPE_OCCLUDES | ((in.closable & 7u) << 4u);
            let p = array<vec2<f32>, 3>(in.p01.xy, in.p01.zw, in.p2);
            // The box a little larger than the tolerance: an edge that may graze it counts as
            // crossing (which only ever makes the bound farther). The margin grows with the
            // corners' distance from the centre, which f32 resolves ever more coarsely (a
            // corner just in front of the eye plane projects millions of pixels away).
            let far_corner = max(max(abs(p[0]), abs(p[1])), abs(p[2]));
            let margin = max(far_corner.x, far_corner.y) / 262144.0;
            let h = cons.tol_px * (1.0 + 1.0 / 64.0) + vec2<f32>(1.0 / 1024.0 + margin);
            let c = cons_point(in.position);
            for (var k = 0u; k < 3u; k++) {
                if (envelope_crosses(p[k], p[(k + 1u) % 3u], c, h)) {
                    flags |= 2u << k;
                }
            }
        }
    }
    near = clamp(near, 0.0, 1.0);
    if (!(near < 1.0)) {
        return;
    }
    let id = (in.tri + 1u) | (flags << ENVELOPE_ID_BITS);
    capture_push(in.position.xy, sample, near, id, clamp(far, 0.0, 1.0));
}
