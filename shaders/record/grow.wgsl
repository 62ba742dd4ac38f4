// Triangles grown or shrunk by a tolerance box in screen space, shared by the conservative
// visibility passes (conservative.wgsl) and the grown peel (peel_grown.wgsl); its bindings
// live in group {{CONS_GROUP}}.
//
// Triangles are pulled from storage (three invocations per triangle, non-indexed draw),
// transformed by the one vertex transform, and grown or shrunk in pixel units after the
// perspective divide; depth is the triangle's plane z = a·x + b·y + c in NDC, evaluated at the
// sample. A triangle reaching behind the camera (w ≤ ε at a corner) is drawn ungrown with its
// interpolated depth (plane.w = 0), and is never shrunk. One degenerate in f32 is grown as its
// bounding box at its nearest corner's depth, and never shrunk.

struct Cons {
    // The box a sample may move in, half-size in pixels (x, y): the bake's tolerance plus half
    // a step of its profile's coarsest sub-pixel grid (recorder's GrowBuffers); pixels per NDC
    // unit (width / 2, height / 2).
    tol_px: vec2<f32>,
    px_per_ndc: vec2<f32>,
    // The bake's raster profile (format's RasterProfile), read by the envelope capture: x, 1
    // where a rasterizer may take a sample's depth anywhere in its pixel (0: at the sample);
    // y, how far a corner moves when snapped to the profile's coarsest grid (round to nearest
    // in x and y: 2^−bits · √2 / 2 px); z and w, the least and most sub-pixel bits.
    profile: vec4<f32>,
}

@group({{CONS_GROUP}}) @binding(0) var<uniform> cons: Cons;
// Per vertex: local position (xyz) and node (w, bitcast).
@group({{CONS_GROUP}}) @binding(1) var<storage, read> cons_vertices: array<vec4<f32>>;
// Per triangle: its three vertex indices and its material.
@group({{CONS_GROUP}}) @binding(2) var<storage, read> cons_triangles: array<vec4<u32>>;

struct ConsVarying {
    @invariant @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) tri: u32,
    // Plane z = a·x + b·y + c (NDC); w: 1 when the plane is valid.
    @location(1) @interpolate(flat) plane: vec4<f32>,
    // Edge k's half-plane in pixel units, moved by the box: inside iff n·p ≤ c (xy: n, z: c).
    @location(2) @interpolate(flat) e0: vec3<f32>,
    @location(3) @interpolate(flat) e1: vec3<f32>,
    @location(4) @interpolate(flat) e2: vec3<f32>,
    // Grown bounding box in pixel units (min x, min y, max x, max y).
    @location(5) @interpolate(flat) bounds: vec4<f32>,
    @location(6) @interpolate(flat) material: u32,
    // The corners in pixel units (p0.xy, p1.xy; p2), for the envelope capture.
    @location(7) @interpolate(flat) p01: vec4<f32>,
    @location(8) @interpolate(flat) p2: vec2<f32>,
    // The envelope capture's bit k: across edge k (corner k to corner k + 1) lies a neighbour
    // on the other side of it (see capture_grown.wgsl); CONS_DEGENERATE wherever the triangle
    // is degenerate in f32 (grown only); 0 elsewhere.
    @location(9) @interpolate(flat) closable: u32,
}

// `closable`'s flag for a grown triangle of no area in f32 (see cons_corner).
const CONS_DEGENERATE: u32 = 16u;

fn cons_dropped() -> ConsVarying {
    var out: ConsVarying;
    // Outside the clip volume: nothing is rasterized.
    out.position = vec4<f32>(2.0, 2.0, 2.0, 1.0);
    out.tri = 0u;
    out.plane = vec4<f32>(0.0);
    out.e0 = vec3<f32>(0.0);
    out.e1 = vec3<f32>(0.0);
    out.e2 = vec3<f32>(0.0);
    out.bounds = vec4<f32>(0.0);
    out.material = 0u;
    out.p01 = vec4<f32>(0.0);
    out.p2 = vec2<f32>(0.0);
    out.closable = 0u;
    return out;
}

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// Corner `corner` of the primitive drawn for triangle `tri`: as it is (`grow` = 0, the
// rasterizer's own coverage, depth from the plane); grown (`grow` = 1), a triangle
// around its bounding box grown by the box, whose fragments keep the samples whose box meets
// the triangle (the separating-axis test of box and triangle: the three edge half-planes
// moved out by the box's support, and the grown bounding box); shrunk (`grow` = −1), the
// triangle itself, whose fragments keep the samples whose whole box lies inside it (the
// half-planes moved in). Tested per fragment, so no corner of an offset triangle is ever
// computed (slivers would put it anywhere).
fn cons_corner(tri: u32, corner: u32, grow: f32) -> ConsVarying {
    let t = cons_triangles[tri];
    var clip: array<vec4<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        let v = cons_vertices[t[k]];
        clip[k] = transform_position(v.xyz, bitcast<u32>(v.w));
    }
    var out = cons_dropped();
    out.tri = tri;
    out.material = t.w;
    let behind = min(min(clip[0].w, clip[1].w), clip[2].w) <= 1e-6;
    if (behind) {
        if (grow < 0.0) {
            return cons_dropped();
        }
        // Ungrown, with its own interpolated depth (plane.w = 0).
        out.position = clip[corner];
        return out;
    }
    var ndc: array<vec3<f32>, 3>;
    var p: array<vec2<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        ndc[k] = clip[k].xyz / clip[k].w;
        p[k] = ndc[k].xy * cons.px_per_ndc;
    }
    let area = cross2(p[1] - p[0], p[2] - p[0]);
    // The plane through the three NDC points.
    let d1 = ndc[1] - ndc[0];
    let d2 = ndc[2] - ndc[0];
    let det3 = d1.x * d2.y - d2.x * d1.y;
    let pa = (d1.z * d2.y - d2.z * d1.y) / det3;
    let pb = (d1.x * d2.z - d2.x * d1.z) / det3;
    let pc = ndc[0].z - pa * ndc[0].x - pb * ndc[0].y;
    // Degenerate here (a segment or a point in f32, or no finite plane), but a rasterizer
    // snapping its corners to another grid may give it area: grown, it is kept as its bounding
    // box grown by the box, at its nearest corner's depth, and marked (CONS_DEGENERATE) so that
    // it never occludes and its depth is taken as unknown. Ungrown or shrunk, it covers nothing.
    let degenerate = !(abs(area) >= 1e-12) || !all(abs(vec3<f32>(pa, pb, pc)) < vec3<f32>(1e30));
    if (degenerate && grow <= 0.0) {
        return cons_dropped();
    }
    let s = sign(area);
    var e: array<vec3<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        let d = p[(k + 1u) % 3u] - p[k];
        let n = s * normalize(vec2<f32>(d.y, -d.x));
        let support = abs(n.x) * cons.tol_px.x + abs(n.y) * cons.tol_px.y;
        e[k] = vec3<f32>(n, dot(n, p[k]) + grow * support);
    }
    out.p01 = vec4<f32>(p[0], p[1]);
    out.p2 = p[2];
    out.plane = vec4<f32>(pa, pb, pc, 1.0);
    if (degenerate) {
        // Every edge test passes (0 ≤ 0): the grown bounds alone decide.
        e = array<vec3<f32>, 3>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
        out.plane = vec4<f32>(0.0, 0.0, min(min(ndc[0].z, ndc[1].z), ndc[2].z), 1.0);
        out.closable = CONS_DEGENERATE;
    }
    out.e0 = e[0];
    out.e1 = e[1];
    out.e2 = e[2];
    let lo = min(min(p[0], p[1]), p[2]) - cons.tol_px;
    let hi = max(max(p[0], p[1]), p[2]) + cons.tol_px;
    out.bounds = vec4<f32>(lo, hi);
    var q = p[corner];
    if (grow > 0.0) {
        // A right triangle around the grown box (twice its area; its corner opposite the
        // right angle on the hypotenuse), with 1/64 px to spare so no sample of the box lies
        // on an edge of it.
        let spare = 1.0 / 64.0;
        let a = lo - vec2<f32>(spare);
        let size = 2.0 * (hi - lo + vec2<f32>(2.0 * spare));
        if (corner == 0u) {
            q = a;
        } else if (corner == 1u) {
            q = a + vec2<f32>(size.x, 0.0);
        } else {
            q = a + vec2<f32>(0.0, size.y);
        }
        // Keep the drawn triangle's winding, so front_facing is the triangle's own.
        if (s < 0.0) {
            if (corner == 1u) {
                q = a + vec2<f32>(0.0, size.y);
            } else if (corner == 2u) {
                q = a + vec2<f32>(size.x, 0.0);
            }
        }
    }
    // Depth comes from the plane in the fragment stage; any z inside the clip volume will do.
    out.position = vec4<f32>(q / cons.px_per_ndc, 0.5, 1.0);
    return out;
}

// The sample's position in pixel units of the NDC frame (x right, y up, origin at the centre):
// with per-sample shading (`sample_index`), `position.xy` is the sample's location.
fn cons_point(position: vec4<f32>) -> vec2<f32> {
    let ndc = vec2<f32>(position.x / cons.px_per_ndc.x - 1.0, 1.0 - position.y / cons.px_per_ndc.y);
    return ndc * cons.px_per_ndc;
}

// Whether the sample passes the three edge tests (and, grown, lies in the grown bounds).
fn cons_inside(in: ConsVarying, grow: f32) -> bool {
    let p = cons_point(in.position);
    let edges = dot(in.e0.xy, p) <= in.e0.z && dot(in.e1.xy, p) <= in.e1.z
        && dot(in.e2.xy, p) <= in.e2.z;
    if (grow < 0.0) {
        return edges;
    }
    return edges && all(p >= in.bounds.xy) && all(p <= in.bounds.zw);
}

// How far the plane departs from its value at a point over a box of half-size `half` pixels
// around it (the tolerance box: `cons.tol_px`).
fn cons_slack(plane: vec4<f32>, half: vec2<f32>) -> f32 {
    let h = half / cons.px_per_ndc;
    return abs(plane.x) * h.x + abs(plane.y) * h.y;
}

// A lower bound on twice the area of triangle `p` once each corner moves by up to `e` pixels
// (snapped to another grid): moving the corners changes twice the area by at most
// 2e (|e1| + |e2|) + 4e². At most 0: snapping may make it degenerate or turn its facing.
fn cons_moved_area2(p: array<vec2<f32>, 3>, e: f32) -> f32 {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    return abs(cross2(e1, e2)) - 2.0 * e * (length(e1) + length(e2)) - 4.0 * e * e;
}

// The triangle's plane at `p` (pixel units of the NDC frame, as cons_point).
fn cons_plane_at(in: ConsVarying, p: vec2<f32>) -> f32 {
    let q = p / cons.px_per_ndc;
    return in.plane.x * q.x + in.plane.y * q.y + in.plane.z;
}

fn cons_plane_depth(in: ConsVarying) -> f32 {
    return cons_plane_at(in, cons_point(in.position));
}

fn cons_occludes(material: u32) -> bool {
    let m = material_at(material);
    // Opaque materials only (no blend, no mask cut-outs, no glass).
    return u32(m.params.x) == 0u && m.emissive.a <= 0.0;
}

// The grown peel's and grown capture's vertex stage: triangle `vi / 3` of the drawn list, grown
// by the box.
@vertex
fn vs_grown(@builtin(vertex_index) vi: u32) -> ConsVarying {
    return cons_corner(vi / 3u, vi % 3u, 1.0);
}

// A grown fragment: x, the depth it is recorded at (its triangle's plane at the sample,
// clamped to [0, 1]; the interpolated depth where the plane is not valid); y, 1 where it is
// kept and 0 where it is dropped (a culled back face, or a sample the grown triangle does not
// reach). A single-sided triangle whose facing snapping to the profile's coarsest grid may turn
// is kept either facing, as the envelope capture keeps it: a sliver facing away by a few
// thousandths of a pixel² draws front-facing on a rasterizer that snaps its corners (the demo
// car at 64², 4×: moved by 1/512 px, a sliver culled here covered a sample, and no grown edge
// ordered it).
fn cons_grown_depth(in: ConsVarying, front_facing: bool) -> vec2<f32> {
    let p = array<vec2<f32>, 3>(in.p01.xy, in.p01.zw, in.p2);
    let turns = in.plane.w > 0.5 && cons_moved_area2(p, cons.profile.y) <= 0.0;
    if (!turns && culled(in.material, front_facing)) {
        return vec2<f32>(0.0, 0.0);
    }
    if (in.plane.w > 0.5) {
        if (!cons_inside(in, 1.0)) {
            return vec2<f32>(0.0, 0.0);
        }
        return vec2<f32>(clamp(cons_plane_depth(in), 0.0, 1.0), 1.0);
    }
    return vec2<f32>(in.position.z, 1.0);
}
