//! Fuzzes the Recording reader: the checked container, then the structure check every CLI
//! reader runs. Neither may panic, hang or allocate what a header merely claims; a file that
//! passes both must be safe to walk (the loop below touches what the merger indexes).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use trisort_format::container::{decode, FileKind};
use trisort_format::Recording;

fuzz_target!(|data: &[u8]| {
    let Some(bytes) = trisort_fuzz::file_bytes(FileKind::Recording, data) else {
        return;
    };
    let Ok(rec) = decode::<Recording>(FileKind::Recording, &bytes, Path::new("fuzz.rec")) else {
        return;
    };
    if rec.check_structure().is_err() {
        return;
    }
    // What check_structure promises: every id indexes G's geometry, every frame its state.
    for fr in &rec.frames {
        let _ = &rec.frame_states[fr.frame as usize];
        for t in fr.visible.iter().chain(&fr.covered) {
            let k = rec.unique_visible.binary_search(t).expect("in G");
            if rec.phase == trisort_format::Phase::Graphs {
                let _ = rec.geometry.triangle_node(k as u32);
            }
        }
    }
    let _ = rec.frame_range();
    let _ = rec.content_hash();
});
