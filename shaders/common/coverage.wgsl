// The recorder's coverage test: an independent depth-tested render through the player's
// vertex stage (`vs_player`) writing each sample's triangle id + 1, so the test can compare
// what the peel recorded at sample k with what the player's pipeline covers at sample k.

@fragment
fn fs_coverage(v: PlayerVarying, @builtin(primitive_index) p: u32) -> @location(0) vec2<u32> {
    return vec2<u32>(p + 1u, 0u);
}
