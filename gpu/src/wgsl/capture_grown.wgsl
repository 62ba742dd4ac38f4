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
