//! Clips at play time: `set_clip` selects which of the file's frames a host iterates, by name;
//! an unknown name is refused naming the file's clips and leaves the selection as it was;
//! frame indices stay the file's.

use trisort_format::Clip;
use trisort_player::{clip_index, Player, PlayerConfig, PlayerError};

use crate::support::*;

/// [`quads`] (3 frames) as a bundle of two clips: `tour` = frames 0..1, `door` = 1..3.
fn bundle() -> trisort_format::Baked {
    let mut b = quads();
    let clip = |name: &str, first, count, fps| Clip {
        name: name.into(),
        first,
        count,
        fps,
        path_hash: [7; 32],
        path_first: 0,
    };
    b.clips = vec![
        clip("tour", 0, 1, Some(24.0)),
        clip("door", 1, 2, Some(5.0)),
    ];
    b.check_structure().unwrap();
    b
}

#[test]
fn set_clip_selects_a_clip_by_name_and_refuses_an_unknown_one() {
    let baked = bundle();
    assert_eq!(clip_index(&baked.clips, "door").unwrap(), 1);
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let config = PlayerConfig::recorded(&baked, wgpu::TextureFormat::Rgba8UnormSrgb);
    let mut p = Player::new(&gpu.device, &gpu.queue, &baked, config).unwrap();
    let names: Vec<&str> = p.clips().iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["tour", "door"]);
    // The first clip until another is selected.
    assert_eq!((p.clip_index(), p.clip().name.as_str()), (0, "tour"));
    assert_eq!(p.clip_frames(), 0..1);

    p.set_clip("door").unwrap();
    assert_eq!((p.clip_index(), p.clip().name.as_str()), (1, "door"));
    assert_eq!(p.clip_frames(), 1..3);
    assert_eq!(p.clip().fps, Some(5.0));
    // Frame indices stay the file's: every frame is drawable whatever the clip.
    assert_eq!(p.frame_count(), 3);
    assert!(!p.frame_commands(0).is_empty());

    let err = p.set_clip("garage").unwrap_err();
    let PlayerError::UnknownClip { name, clips } = &err else {
        panic!("{err:?}");
    };
    assert_eq!(
        (name.as_str(), clips.as_slice()),
        ("garage", &["tour".to_string(), "door".to_string()][..])
    );
    assert_eq!(
        err.to_string(),
        "no clip named \"garage\"; the file's clips: tour, door"
    );
    assert_eq!(p.clip().name, "door", "a refused name leaves the selection");
}
