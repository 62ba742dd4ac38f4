// Depth-presorted lists (paper 000), the free-viewpoint renderer (composed after COMMON and
// PLAYER: colours are the player's `player_colour`). A copy is drawn where the camera passes
// every one of its half-space tests (one plane lookup and dot product per test), selected in
// one of the two stages paper 000 measures:
// - fragment (`fs_presorted_*`): the partition's copies in one indexed draw; a fragment's copy
//   is the segment's first copy plus `primitive_index`;
// - vertex (`vs_presorted`): the copies drawn without indices from a vertex buffer of three
//   vertices a copy, so a vertex's copy is `vertex_index / 3`; a failing copy's corners all
//   go outside the clip volume, and the copy has no fragments.

struct PresortParams {
    // The camera relative to the polyhedron's centre (xyz), world units.
    eye: vec4<f32>,
    // x: the drawn segment's first copy (in this draw's order).
    first: vec4<u32>,
}

@group(1) @binding(0) var<uniform> presort: PresortParams;
// Per copy: its first test and the number of tests.
@group(1) @binding(1) var<storage, read> copy_tests: array<vec2<u32>>;
// Per test: the plane's index, bit 31 set where the test is the plane's negative side.
@group(1) @binding(2) var<storage, read> tests: array<u32>;
// Planes n · (x − centre) = d as (n, d).
@group(1) @binding(3) var<storage, read> planes: array<vec4<f32>>;

// Whether the camera passes every test of `copy`: `n · eye − d ≥ 0`, or `< 0` flipped (a plane
// and its flip are exactly complementary).
fn presort_passes(copy: u32) -> bool {
    let r = copy_tests[copy];
    for (var k = 0u; k < r.y; k = k + 1u) {
        let t = tests[r.x + k];
        let p = planes[t & 0x7fffffffu];
        let v = p.x * presort.eye.x + p.y * presort.eye.y + p.z * presort.eye.z - p.w;
        let flipped = (t >> 31u) != 0u;
        if (flipped != (v < 0.0)) {
            return false;
        }
    }
    return true;
}

@vertex
fn vs_presorted(v: VertexIn, @builtin(vertex_index) index: u32) -> PlayerVarying {
    var out = player_vertex(v);
    if (!presort_passes(index / 3u)) {
        out.position = vec4<f32>(2.0, 2.0, 2.0, 1.0);
    }
    return out;
}

@fragment
fn fs_presorted_straight(
    v: PlayerVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(primitive_index) primitive: u32,
) -> @location(0) vec4<f32> {
    let uv = player_uv(v);
    if (!presort_passes(presort.first.x + primitive)) {
        discard;
    }
    return player_colour(v, front_facing, uv);
}

@fragment
fn fs_presorted_premultiplied(
    v: PlayerVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(primitive_index) primitive: u32,
) -> @location(0) vec4<f32> {
    let uv = player_uv(v);
    if (!presort_passes(presort.first.x + primitive)) {
        discard;
    }
    let c = player_colour(v, front_facing, uv);
    return vec4<f32>(c.rgb * c.a, c.a);
}
