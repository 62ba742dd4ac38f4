//! Frame ranges recorded apart: [`join`] gives back the whole recording, merging refuses
//! recordings that differ (naming each difference with both values) and merges recordings of
//! different devices only with [`MergeOptions::allow_mixed_devices`], whose bake says so.

use crate::merge;
use trisort_format::Recording;
use trisort_merger::synth::{split_frames, turntable, Turntable};
use trisort_merger::{differences, join, MergeError, MergeOptions};

fn parts() -> (Recording, Vec<Recording>) {
    let rec = turntable(&Turntable {
        objects: 4,
        sides: 10,
        frames: 9,
        samples: 64,
        ..Turntable::default()
    });
    let parts = split_frames(&rec, &[0, 2, 6]);
    (rec, parts)
}

#[test]
fn joined_parts_are_the_whole_recording_in_any_order() {
    let (rec, parts) = parts();
    assert_eq!(join(&parts).unwrap(), rec);
    let reversed: Vec<Recording> = parts.iter().rev().cloned().collect();
    assert_eq!(join(&reversed).unwrap(), rec);
    let opts = MergeOptions::default();
    // A bake of the joined recording is the bake of the whole one.
    assert_eq!(
        merge(&[join(&parts).unwrap()], &opts).unwrap(),
        merge(std::slice::from_ref(&rec), &opts).unwrap()
    );
    // A gap or an overlap is refused.
    let e = join(&[parts[0].clone(), parts[2].clone()]).unwrap_err();
    assert!(matches!(e, MergeError::NotContiguous { .. }), "{e}");
    let e = join(&[parts[0].clone(), parts[1].clone(), parts[1].clone()]).unwrap_err();
    assert!(matches!(e, MergeError::NotContiguous { .. }), "{e}");
}

#[test]
fn every_difference_is_named_with_both_values() {
    let (_, parts) = parts();
    let mut other = parts[1].clone();
    other.settings.width += 1;
    other.settings.samples = 5 - parts[0].settings.samples; // 1 <-> 4
    other.device.driver = "another driver".into();
    other.scene_hash[0] ^= 1;
    let d: Vec<String> = differences(&parts[0], &other)
        .iter()
        .map(|d| d.to_string())
        .collect();
    let size = format!(
        "size \"{w}x{h}\" vs \"{w1}x{h}\"",
        w = parts[0].settings.width,
        w1 = parts[0].settings.width + 1,
        h = parts[0].settings.height
    );
    assert!(d.contains(&size), "{d:?}");
    assert!(d.iter().any(|x| x.starts_with("samples")), "{d:?}");
    assert!(d.iter().any(|x| x.starts_with("scene hash")), "{d:?}");
    let driver = format!("driver {:?} vs \"another driver\"", parts[0].device.driver);
    assert!(d.contains(&driver), "{d:?}");
    assert_eq!(differences(&parts[0], &parts[2]), vec![]);
    // Robust recording is a setting too, named like the others.
    let mut robust = parts[2].clone();
    robust.settings.robust.patterns += 1;
    let d = differences(&parts[0], &robust);
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(
        d[0].what.starts_with("robust ") && d[0].what.contains("patterns"),
        "{d:?}"
    );
}

#[test]
fn mixed_devices_are_refused_unless_allowed_and_then_recorded() {
    let (_, mut parts) = parts();
    parts[2].device.adapter = "Other GPU".into();
    let opts = MergeOptions::default();
    let e = merge(&parts, &opts).unwrap_err().to_string();
    assert!(
        e.contains("recording 2") && e.contains("device") && e.contains("Other GPU"),
        "{e}"
    );
    let e = join(&parts).unwrap_err().to_string();
    assert!(e.contains("recording 2") && e.contains("Other GPU"), "{e}");
    let mixed = MergeOptions {
        allow_mixed_devices: true,
        ..opts
    };
    let baked = merge(&parts, &mixed).unwrap();
    assert!(
        baked.device.adapter.starts_with("mixed: "),
        "{:?}",
        baked.device
    );
    assert!(
        baked.device.adapter.contains("Other GPU (frames 6..9)"),
        "{:?}",
        baked.device
    );
    // Only the device may differ.
    parts[1].settings.max_layers += 1;
    let e = merge(&parts, &mixed).unwrap_err().to_string();
    assert!(e.contains("recording 1") && e.contains("max layers"), "{e}");
}
