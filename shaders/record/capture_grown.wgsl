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
// Three allowances for rasterizers other than the recording one, each as wide as the bake's
// raster profile asks (`cons.profile`; BENCHMARKS § Raster profiles; all three were found on
// SwiftShader, the browser's WebGL2, whose `browser` profile takes the widest):
// - depth is compared over the sample's tolerance box where the profile takes depth at the
//   sample (the Vulkan and GLES rule), and over the sample's whole pixel grown by the
//   tolerance where it takes it anywhere in the pixel. SwiftShader does: it evaluates the
//   depth plane with the sample's offset from the pixel centre negated in x (in older
//   versions in x and y), so sample 1 of the 4× pattern, at (0.875, 0.375), takes its depth at
//   (0.125, 0.375);
// - depth is that of the plane through the corners snapped to the profile's sub-pixel grids,
//   bounded by envelope_depth_range: on a sliver it extrapolates far (on CarConcept, a sliver
//   0.04 behind the surface at its sample took a depth 0.03 in front of it at the mirrored
//   point, snapped to 1/16 px);
// - a triangle whose facing snapping to the profile's coarsest grid may turn (bit 3 of
//   `closable`) is kept either facing and never occludes; one degenerate in f32
//   (CONS_DEGENERATE), which snapping may give area, has no depth to go by at all and is
//   listed at depth 0.

// Per triangle of the drawn list: for edge k (corner k to corner k + 1), the vertex of the
// triangle across it opposite the edge, or 0xffffffff where the edge has no single neighbour.
@group(2) @binding(3) var<storage, read> cons_opposite: array<vec4<u32>>;

// Flag bits above the id: the triangle occludes (opaque, its plane valid); edge k crosses the
// box (bits 1–3); edge k is closable (bits 4–6).
// Bits of a node's id word that hold the id (trisort_gpu::ENVELOPE_ID_BITS, substituted).
const ENVELOPE_ID_BITS: u32 = {{ENVELOPE_ID_BITS}}u;
const ENVELOPE_OCCLUDES: u32 = 1u;

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
    // CONS_DEGENERATE from cons_corner, where set.
    var closable = out.closable;
    // Bit 3: its facing may turn on a rasterizer that snaps each corner to the profile's
    // coarsest grid (1/16 px for 4 bits, Vulkan's and GLES's least sub-pixel precision; 1/256
    // px for 8): twice its area is within what moving the corners by up to half a grid step in
    // x and y can change it by.
    if (cons_moved_area2(p, cons.profile.y) <= 0.0) {
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

// The depths (least, most) a rasterizer may take over the box of half-size `r` pixels around
// `c`, where the exact plane is `z` at `c` and departs from it by at most `slack` over the box:
// the exact plane's, or those of the plane through the corners snapped to a grid of 2^−b px
// for every b of the profile's sub-pixel bits (`cons.profile.zw`; 4 is Vulkan's and GLES's
// least precision and SwiftShader's, 8 that of Mesa's rasterizers (lavapipe reports it);
// rounding: each corner moves by at most e = 2^−b·√2/2), with the corners' own depths
// interpolated over the snapped triangle. The bound is not monotone in the grid (a
// sliver's least snapped area bottoms out in between), so every b of the range is taken.
//
// For a snapped grid, from the barycentric weights λ' of a point of the box in the snapped
// triangle, with Λ = Σ|λ'|: the snapped plane is the exact plane moved by Σ λ'_k ∇z·δ_k (at
// most |∇z| e Λ), and a sum of the corner depths weighted to 1 (within (Λ − 1) / 2 of their
// range). Λ ≤ Σ_k |cross(p'_j − p'_i, q − p'_i)| (bounded over the box and the moves) over
// the least twice-area the snapped triangle can have and still be drawn (cons_moved_area2,
// and at least the grid's square): unbounded for a sliver.
fn envelope_depth_range(in: ConsVarying, c: vec2<f32>, r: vec2<f32>, z: f32, slack: f32) -> vec2<f32> {
    let p = array<vec2<f32>, 3>(in.p01.xy, in.p01.zw, in.p2);
    let zk = array<f32, 3>(cons_plane_at(in, p[0]), cons_plane_at(in, p[1]), cons_plane_at(in, p[2]));
    let zmin = min(min(zk[0], zk[1]), zk[2]);
    let zmax = max(max(zk[0], zk[1]), zk[2]);
    let gradient = length(in.plane.xy / cons.px_per_ndc);
    // Per corner k (i, j the other two): |cross(p_j − p_i, q − p_i)| bounded over the box, and
    // the lengths the corners' moves multiply.
    var cross_box: array<f32, 3>;
    var edge: array<f32, 3>;
    var reach: array<f32, 3>;
    for (var k = 0u; k < 3u; k++) {
        let a = p[(k + 1u) % 3u];
        let d = p[(k + 2u) % 3u] - a;
        let v = c - a;
        cross_box[k] = abs(cross2(d, v)) + abs(d.x) * r.y + abs(d.y) * r.x;
        edge[k] = length(d);
        reach[k] = length(v) + length(r);
    }
    var range = vec2<f32>(z - slack, z + slack);
    for (var bits = u32(cons.profile.z); bits <= u32(cons.profile.w); bits++) {
        let grid = 1.0 / f32(1u << bits);
        let e = grid * 0.70710678;
        let least = max(cons_moved_area2(p, e), grid * grid);
        var sum = 0.0;
        for (var k = 0u; k < 3u; k++) {
            sum += cross_box[k] + 2.0 * e * edge[k] + 2.0 * e * reach[k] + 4.0 * e * e;
        }
        let weights = sum / least;
        let drift = gradient * e * weights;
        let extra = 0.5 * (weights - 1.0) * (zmax - zmin);
        range.x = min(range.x, max(z - slack - drift, zmin - extra));
        range.y = max(range.y, min(z + slack + drift, zmax + extra));
    }
    return range;
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
        // The depth box (half-size `reach` px around `c`), over which the plane is not
        // clamped to the corners' depth range (a depth taken off the triangle extrapolates):
        // the sample's tolerance box where the profile takes depth at the sample; else the
        // sample's pixel grown by the tolerance (a sample moved within the tolerance is taken
        // to keep its pixel, as it does at ±1/8 px with the standard patterns).
        var c = cons_point(in.position);
        var reach = cons.tol_px;
        if (cons.profile.x > 0.5) {
            c = cons_point(vec4<f32>(floor(in.position.xy) + vec2<f32>(0.5), 0.0, 1.0));
            reach = vec2<f32>(0.5) + cons.tol_px;
        }
        let z = cons_plane_at(in, c);
        if ((in.closable & CONS_DEGENERATE) != 0u) {
            near = 0.0;
            far = z;
        } else {
            let range = envelope_depth_range(in, c, reach, z, cons_slack(in.plane, reach));
            near = range.x;
            far = range.y;
        }
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
            let at = cons_point(in.position);
            for (var k = 0u; k < 3u; k++) {
                if (envelope_crosses(p[k], p[(k + 1u) % 3u], at, h)) {
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
