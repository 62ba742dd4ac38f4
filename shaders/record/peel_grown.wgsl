// The grown peel (record --conservative, phase 2): the peel of peel.wgsl over triangles grown
// by the tolerance box (grow.wgsl, group 2), so that at each sample it lists, in (depth, id)
// order, every triangle that could cover the sample when the pattern moves within the
// tolerance; consecutive fragments give the edges that order the triangles conservative
// visibility adds. A fragment's depth is its triangle's plane at the sample (extended past the
// triangle's edges); its id is its position in the drawn list (the non-indexed draw's
// triangle, no primitive index needed). Alpha is not evaluated (phase 2 needs none): 1.

@fragment
fn fs_peel_grown(
    in: ConsVarying,
    @builtin(front_facing) front_facing: bool,
    @builtin(sample_index) sample: u32,
) -> PeelOut {
    let coord = vec2<i32>(in.position.xy);
    if (peel_done(coord, sample)) {
        discard;
    }
    let grown = cons_grown_depth(in, front_facing);
    if (grown.y < 0.5) {
        discard;
    }
    let z = grown.x;
    let id = in.tri;
    if (peeled_before(coord, sample, z, id)) {
        discard;
    }
    var out: PeelOut;
    out.ids = vec2<u32>(id + 1u, bitcast<u32>(1.0));
    out.depth = z;
    return out;
}
