//! The baked file as the player reads it (no GPU): byte-exact round trip, clear errors for
//! truncated, corrupted, junk and inconsistent files, and the playback warnings.

use std::path::Path;

use trisort_format::{container, Baked, FileKind, FormatError};
use trisort_player::{open_baked, playback_warnings, Mode, PlayerConfig, PlayerError};

use crate::support::*;

#[test]
fn a_baked_file_round_trips_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("quads.baked");
    let baked = quads();
    trisort_format::write_file_atomic(FileKind::Baked, &path, &baked).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(
        bytes,
        container::encode(FileKind::Baked, &baked),
        "the file is the encoding"
    );
    let back = open_baked(&path).unwrap();
    assert_eq!(back, baked);
    // Encoding what was read gives the same bytes again.
    assert_eq!(container::encode(FileKind::Baked, &back), bytes);
    // And a second write is identical.
    let again = dir.path().join("again.baked");
    trisort_format::write_file_atomic(FileKind::Baked, &again, &back).unwrap();
    assert_eq!(std::fs::read(&again).unwrap(), bytes);
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn rejected(path: &Path) -> String {
    let err = open_baked(path).expect_err("a damaged file must be rejected");
    let msg = err.to_string();
    assert!(
        msg.contains(&path.display().to_string()),
        "the error names the file: {msg}"
    );
    msg
}

#[test]
fn truncated_bit_flipped_and_junk_files_are_rejected_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = container::encode(FileKind::Baked, &quads());
    // Every truncation.
    for len in (0..bytes.len()).step_by(5).chain([bytes.len() - 1]) {
        let p = write(dir.path(), "cut.baked", &bytes[..len]);
        rejected(&p);
    }
    // Bit flips in the header and all through the payload.
    for i in (0..bytes.len()).step_by(3) {
        let mut b = bytes.clone();
        b[i] ^= 1 << (i % 8);
        let p = write(dir.path(), "flip.baked", &b);
        rejected(&p);
    }
    // Junk, an empty file, a recording where a baked file is expected, a missing file.
    let p = write(
        dir.path(),
        "junk.baked",
        b"this is not a trisort file at all, just text",
    );
    assert!(rejected(&p).contains("wrong magic"));
    rejected(&write(dir.path(), "empty.baked", b""));
    let rec = container::encode(FileKind::Recording, &quads());
    assert!(rejected(&write(dir.path(), "rec.baked", &rec)).contains("not a trisort baked file"));
    rejected(&dir.path().join("missing.baked"));
    // Trailing garbage.
    let mut padded = bytes.clone();
    padded.extend_from_slice(b"xx");
    rejected(&write(dir.path(), "padded.baked", &padded));
}

#[test]
fn a_well_formed_file_with_inconsistent_contents_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    type Damage = Box<dyn Fn(&mut Baked)>;
    let cases: Vec<(&str, Damage)> = vec![
        ("draw", Box::new(|b| b.draws[3].index_count = 9)),
        ("window", Box::new(|b| b.frames[2].count = 3)),
        ("copy", Box::new(|b| b.copies[5] = 99)),
        ("vertex", Box::new(|b| b.geometry.triangles[0][1] = 1000)),
        (
            "per-frame",
            Box::new(|b| {
                b.frame_states.pop();
            }),
        ),
    ];
    for (what, damage) in cases {
        let mut b = quads();
        damage(&mut b);
        let path = dir.path().join(format!("{what}.baked"));
        trisort_format::write_file_atomic(FileKind::Baked, &path, &b).unwrap();
        let err = open_baked(&path).expect_err(what);
        assert!(
            matches!(err, PlayerError::Structure { .. }),
            "{what}: {err}"
        );
        let msg = err.to_string();
        assert!(
            msg.contains(&path.display().to_string()) && msg.contains(what),
            "{msg}"
        );
    }
    // The undamaged file opens.
    let path = dir.path().join("ok.baked");
    trisort_format::write_file_atomic(FileKind::Baked, &path, &quads()).unwrap();
    open_baked(&path).unwrap();
    // Format errors keep their type.
    let err = open_baked(&dir.path().join("none.baked")).unwrap_err();
    assert!(
        matches!(err, PlayerError::Format(FormatError::Io { .. })),
        "{err}"
    );
}

#[test]
fn warnings_name_what_differs_from_the_recording() {
    let baked = quads();
    let exact = PlayerConfig::recorded(&baked, wgpu::TextureFormat::Rgba8Unorm);
    assert!(playback_warnings(&baked, &exact).is_empty());

    let other = PlayerConfig {
        size: (64, 48),
        ..exact.clone()
    };
    let w = playback_warnings(&baked, &other);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("64x48") && w[0].contains("32x32"), "{w:?}");

    let msaa = PlayerConfig {
        sample_count: 4,
        ..exact.clone()
    };
    assert!(playback_warnings(&baked, &msaa)[0].contains("4 sample"));

    let device = PlayerConfig {
        device: Some(trisort_format::DeviceInfo {
            adapter: "another GPU".into(),
            ..baked.device.clone()
        }),
        ..exact.clone()
    };
    assert!(playback_warnings(&baked, &device)[0].contains("another GPU"));
    let same_device = PlayerConfig {
        device: Some(baked.device.clone()),
        ..exact.clone()
    };
    assert!(playback_warnings(&baked, &same_device).is_empty());

    // Glass: more transparent than recorded warns, more opaque does not; no glass, no warning.
    let mut glassy = quads();
    glassy.settings.glass_opacity = 0.5;
    glassy.geometry.materials[0].transmission = 1.0;
    let thinner = PlayerConfig {
        glass_opacity: Some(0.2),
        ..exact.clone()
    };
    let w = playback_warnings(&glassy, &thinner);
    assert!(w.len() == 1 && w[0].contains("holes"), "{w:?}");
    let thicker = PlayerConfig {
        glass_opacity: Some(0.8),
        ..exact.clone()
    };
    assert!(playback_warnings(&glassy, &thicker).is_empty());
    assert!(
        playback_warnings(&baked, &thinner).is_empty(),
        "no glass in the scene"
    );

    // A depth-only bake wants the depth test.
    let mut depth_only = quads();
    depth_only.merge.depth_only = true;
    assert_eq!(playback_warnings(&depth_only, &exact).len(), 1);
    let depth = PlayerConfig {
        mode: Mode::Depth,
        ..exact
    };
    assert!(playback_warnings(&depth_only, &depth).is_empty());
}

#[test]
fn modes_parse_by_name() {
    for m in Mode::ALL {
        assert_eq!(m.name().parse::<Mode>().unwrap(), m);
    }
    assert!("over"
        .parse::<Mode>()
        .unwrap_err()
        .to_string()
        .contains("over"));
}
