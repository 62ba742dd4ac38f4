//! Fuzzes the TOML path parser over the demo car (its node names, e.g. `DriverDoor`): any text must give a
//! timeline or a `PathError`, never a panic, and a timeline's cameras must be usable
//! (finite, invertible, 0 < znear < zfar) as the crate documents.
#![no_main]

use std::path::Path;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use trisort_scene::Scene;

fn scene() -> &'static Scene {
    static SCENE: OnceLock<Scene> = OnceLock::new();
    SCENE.get_or_init(|| trisort_scene::demo_car::demo_car(10_000))
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(timeline) = trisort_paths::load_toml_str(text, Path::new("fuzz.toml"), scene()) else {
        return;
    };
    assert!(!timeline.frames.is_empty());
    for (f, s) in timeline.frames.iter().enumerate() {
        if let Err(e) =
            trisort_format::camera::check_frame_state(f, s, Some(scene().geometry.nodes.len()))
        {
            panic!("the path parser produced an unusable frame: {e}");
        }
    }
});
