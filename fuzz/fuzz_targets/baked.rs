//! Fuzzes the Baked reader: the checked container, then `Baked::check_structure` (what the
//! player and the validator run before touching a file). A file that passes must be safe to
//! index the way the player does: every frame's draws, the index buffer, the node matrices.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use trisort_format::container::{decode, FileKind};
use trisort_format::Baked;

fuzz_target!(|data: &[u8]| {
    let Some(bytes) = trisort_fuzz::file_bytes(FileKind::Baked, data) else {
        return;
    };
    let Ok(baked) = decode::<Baked>(FileKind::Baked, &bytes, Path::new("fuzz.baked")) else {
        return;
    };
    if baked.check_structure().is_err() {
        return;
    }
    let indices = baked.indices();
    let nv = baked.geometry.vertices.len();
    assert!(indices.iter().all(|&i| (i as usize) < nv));
    for f in 0..baked.frames.len() {
        for d in baked.frame_draws(f) {
            let _ = &indices[d.first_index as usize..(d.first_index + d.index_count) as usize];
        }
        let _ = trisort_format::camera::node_view_matrices(
            &baked.geometry.nodes,
            &baked.frame_states[f],
        );
    }
});
