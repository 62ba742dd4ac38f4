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
// Three allowances for rasterizers other than the recording one (BENCHMARKS § Exactness
// across rasterizers; found on SwiftShader, the browser's WebGL2):
// - depth is compared over the sample's whole pixel grown by the tolerance, not at the
//   sample: a rasterizer may take a sample's depth elsewhere in its pixel. SwiftShader does:
//   it evaluates the depth plane with the sample's offset from the pixel centre negated in x
//   (in older versions in x and y), so sample 1 of the 4× pattern, at (0.875, 0.375), takes
//   its depth at (0.125, 0.375);
// - depth is that of the plane through the corners snapped to the rasterizer's sub-pixel grid
//   (4 to 8 bits), bounded by envelope_snapped_depth: on a sliver it extrapolates far (on
//   CarConcept, a sliver 0.04 behind the surface at its sample took a depth 0.03 in front of
//   it at the mirrored point);
// - a triangle whose facing snapping may turn (bit 3 of `closable`) is kept either facing and
//   never occludes; one degenerate in f32 (CONS_DEGENERATE), which snapping may give area,
//   has no depth to go by at all and is listed at depth 0.

// Per triangle of the drawn list: for edge k (corner k to corner k + 1), the vertex of the
// triangle across it opposite the edge, or 0xffffffff where the edge has no single neighbour.
@group(2) @binding(3) var<storage, read> cons_opposite: array<vec4<u32>>;

// Flag bits above the id: the triangle occludes (opaque, its plane valid); edge k crosses the
// box (bits 1–3); edge k is closable (bits 4–6).
// Bits of a node's id word that hold the id (trisort_gpu::ENVELOPE_ID_BITS, substituted).
const ENVELOPE_ID_BITS: u32 = ENVELOPE_ID_BITS_VALUEu;
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

// How far the depth a rasterizer takes over the box of half-size `r` (pixels) around `c` may
// lie from the exact plane when it snaps the corners to a grid of `grid` px (rounding: each
// corner moves by at most e = grid·√2/2) and interpolates the corners' own depths over the
// snapped triangle. x: the most the snapped triangle's plane departs from the exact plane
// over the box; y, z: the least and most depth it can take there. Both follow from the
// barycentric weights λ' of a point of the box in the snapped triangle: with Λ = Σ|λ'|, the
// snapped plane is the exact plane moved by Σ λ'_k ∇z·δ_k (at most |∇z| e Λ), and a sum of
// the corner depths weighted to 1 (within (Λ − 1) / 2 of their range). Λ is unbounded for a
// sliver, whose snapped area may be as small as the grid allows.
fn envelope_snapped_depth(in: ConsVarying, c: vec2<f32>, r: vec2<f32>, grid: f32) -> vec3<f32> {
    let e = grid * 0.70710678;
    let p = array<vec2<f32>, 3>(in.p01.xy, in.p01.zw, in.p2);
    let z = array<f32, 3>(cons_plane_at(in, p[0]), cons_plane_at(in, p[1]), cons_plane_at(in, p[2]));
    let zmin = min(min(z[0], z[1]), z[2]);
    let zmax = max(max(z[0], z[1]), z[2]);
    // The least twice-area the snapped triangle can have and still be drawn: moving each corner
    // by e changes twice the area by at most 2e (|e1| + |e2|) + 4e², and a drawn triangle on
    // the grid has twice its area at least grid².
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let least = max(abs(cross2(e1, e2)) - 2.0 * e * (length(e1) + length(e2)) - 4.0 * e * e,
        grid * grid);
    // Σ over corners k of |cross(p'_j − p'_i, q − p'_i)| (i, j the other two), bounded over
    // the box and the corners' moves.
    var sum = 0.0;
    for (var k = 0u; k < 3u; k++) {
        let a = p[(k + 1u) % 3u];
        let d = p[(k + 2u) % 3u] - a;
        let v = c - a;
        sum += abs(cross2(d, v)) + abs(d.x) * r.y + abs(d.y) * r.x + 2.0 * e * length(d)
            + 2.0 * e * (length(v) + length(r)) + 4.0 * e * e;
    }
    let weights = sum / least;
    let gradient = length(in.plane.xy / cons.px_per_ndc);
    let extra = 0.5 * (weights - 1.0) * (zmax - zmin);
    return vec3<f32>(gradient * e * weights, zmin - extra, zmax + extra);
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
        // The depth box: the sample's pixel grown by the tolerance (half-size `reach` px
        // around the pixel's centre `c`; a sample moved within the tolerance is taken to
        // keep its pixel, as it does at ±1/8 px with the standard patterns). The exact plane over it (not clamped to the
        // corners' depth range: a depth taken elsewhere in the pixel extrapolates) ...
        let c = cons_point(vec4<f32>(floor(in.position.xy) + vec2<f32>(0.5), 0.0, 1.0));
        let reach = vec2<f32>(0.5) + cons.tol_px;
        let z = cons_plane_at(in, c);
        let slack = abs(in.plane.x) * reach.x / cons.px_per_ndc.x
            + abs(in.plane.y) * reach.y / cons.px_per_ndc.y;
        if ((in.closable & CONS_DEGENERATE) != 0u) {
            near = 0.0;
            far = z;
        } else {
            // ... and the plane through its corners snapped to 4 sub-pixel bits (Vulkan's and
            // GLES's least; SwiftShader's) to 8 (common on desktop GPUs), whichever reaches
            // farther (the bound is not monotone in the grid: a sliver's least snapped area
            // bottoms out in between), or not snapped at all.
            near = z - slack;
            far = z + slack;
            for (var bits = 4u; bits <= 8u; bits++) {
                let b = envelope_snapped_depth(in, c, reach, 1.0 / f32(1u << bits));
                near = min(near, max(z - slack - b.x, b.y));
                far = max(far, min(z + slack + b.x, b.z));
            }
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
