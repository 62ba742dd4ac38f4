//! What the baked file repeats from its recordings: identities, settings, the geometry of G,
//! the path's frames, and the statistics its draws and the recordings determine.

use trisort_format::{Baked, FrameRecord, FrameState, Geometry, Phase, Recording};

use crate::{GraphReport, Tally};

/// Checks the recordings against the file and returns their frames in order, one per frame
/// of the file; `None` (with the reason in `report`) when they cannot be compared at all.
pub(crate) fn collect_frames<'a>(
    recordings: &'a [Recording],
    baked: &Baked,
    report: &mut GraphReport,
) -> Option<Vec<&'a FrameRecord>> {
    if recordings.is_empty() {
        report.problems.push("no recording given".into());
        return None;
    }
    for (k, r) in recordings.iter().enumerate() {
        if let Err(e) = r.check_structure() {
            report
                .problems
                .push(format!("recording {k} is malformed: {e}"));
            return None;
        }
    }
    if !same_identity(recordings, baked, report) {
        return None;
    }
    for (k, r) in recordings.iter().enumerate() {
        same_content(k, r, baked, report);
    }
    // The light the file claims: the built-in studio is made anew and compared (a file
    // light from an .hdr file is checked by `trisort verify --environment FILE.hdr`).
    if baked.environment.name == "studio" {
        if let Some(what) = baked.environment.difference(&trisort_light::studio()) {
            report.problem(format!(
                "the file's environment claims to be the built-in studio but differs: {what}"
            ));
        }
    }
    let mut hashes: Vec<_> = recordings.iter().map(Recording::content_hash).collect();
    let mut expected = baked.recording_hashes.clone();
    hashes.sort_unstable();
    expected.sort_unstable();
    if hashes != expected {
        report.problem("the recordings' hashes differ from those the file was merged from".into());
    }
    let nframes = baked.frames.len();
    let mut out: Vec<Option<&FrameRecord>> = vec![None; nframes];
    for r in recordings {
        for fr in &r.frames {
            match out.get_mut(fr.frame as usize) {
                Some(slot @ None) => *slot = Some(fr),
                Some(Some(_)) => report.problem(format!("frame {} is recorded twice", fr.frame)),
                None => report.problem(format!(
                    "frame {} lies beyond the file's {nframes} frames",
                    fr.frame
                )),
            }
        }
    }
    let missing = out.iter().filter(|s| s.is_none()).count();
    if missing > 0 {
        report.problems.push(format!(
            "{missing} of the file's {nframes} frames are not in the recordings"
        ));
        return None;
    }
    Some(out.into_iter().map(|s| s.expect("checked above")).collect())
}

/// Whether every recording is of the file's scene, path, settings and G, with graphs (without
/// which nothing else can be compared).
fn same_identity(recordings: &[Recording], baked: &Baked, report: &mut GraphReport) -> bool {
    let mut same = true;
    for (k, r) in recordings.iter().enumerate() {
        let mut differs = |what: &str| {
            report.problems.push(format!(
                "recording {k}: {what} differs from the baked file's"
            ));
            same = false;
        };
        if r.phase != Phase::Graphs {
            differs("phase (it has no graphs)");
        }
        if r.scene_hash != baked.scene_hash {
            differs("scene hash");
        }
        if r.path_hash != baked.path_hash {
            differs("path hash");
        }
        if r.settings != baked.settings {
            differs("recording settings");
        }
        if r.unique_visible != baked.scene_ids {
            differs("set G of visible triangles");
        }
    }
    same
}

/// What the file copies from recording `k`: the device, the frame rate, the geometry of G and
/// the path (its frame count, every frame's camera and poses).
fn same_content(k: usize, r: &Recording, baked: &Baked, report: &mut GraphReport) {
    if r.device != baked.device {
        report.problem(format!(
            "recording {k}: the device ({}) differs from the baked file's ({})",
            r.device.adapter, baked.device.adapter
        ));
    }
    if let Some(what) = geometry_difference(&r.geometry, &baked.geometry) {
        report.problem(format!(
            "the baked geometry differs from recording {k}'s: {what}"
        ));
    }
    if r.fps.map(f64::to_bits) != baked.fps.map(f64::to_bits) {
        report.problem(format!(
            "recording {k}: the frame rate ({:?} fps) differs from the baked file's ({:?})",
            r.fps, baked.fps
        ));
    }
    let path = r.frame_states.len();
    if baked.frames.len() != path {
        report.problem(format!(
            "the file has {} frames, the recorded path {path}",
            baked.frames.len()
        ));
    }
    let mut shown = 0;
    for (f, (a, b)) in r.frame_states.iter().zip(&baked.frame_states).enumerate() {
        if let Some(what) = frame_state_difference(a, b) {
            shown += 1;
            if shown <= 3 {
                report.problem(format!(
                    "frame {f}: the baked {what} differs from recording {k}'s"
                ));
            }
        }
    }
    if shown > 3 {
        report.problem(format!(
            "{shown} frames' cameras or poses differ from recording {k}'s"
        ));
    }
}

/// The first part of `baked` that differs from `recorded`, named for people.
fn geometry_difference(recorded: &Geometry, baked: &Geometry) -> Option<String> {
    fn first<T: PartialEq>(what: &str, a: &[T], b: &[T]) -> Option<String> {
        if a.len() != b.len() {
            return Some(format!("{} {what} instead of {}", b.len(), a.len()));
        }
        let k = a.iter().zip(b).position(|(x, y)| x != y)?;
        Some(format!("{what} {k} differs"))
    }
    first("vertices", &recorded.vertices, &baked.vertices)
        .or_else(|| first("triangles", &recorded.triangles, &baked.triangles))
        .or_else(|| first("materials", &recorded.materials, &baked.materials))
        .or_else(|| texture_difference(recorded, &baked.textures))
        .or_else(|| first("nodes", &recorded.nodes, &baked.nodes))
}

/// The first texture of `baked` that is not the recording's: equal, or (stored as blocks by
/// `--textures`) of the same name, size and colour space with, where the recording's
/// materials let its alpha decide visibility (a MASK or BLEND base colour), the same level-0
/// alpha texel for texel. Colour may differ: the visibility recorded does not depend on it.
fn texture_difference(recorded: &Geometry, baked: &[trisort_format::Texture]) -> Option<String> {
    if recorded.textures.len() != baked.len() {
        return Some(format!(
            "{} textures instead of {}",
            baked.len(),
            recorded.textures.len()
        ));
    }
    let alpha_decides = recorded.alpha_decides_visibility();
    let k = (recorded.textures.iter().zip(baked).enumerate()).position(|(k, (r, b))| {
        if b.blocks.is_none() || r.blocks.is_some() {
            return r != b;
        }
        let alpha = |t: &trisort_format::Texture| -> Vec<u8> {
            t.rgba8.chunks_exact(4).map(|p| p[3]).collect()
        };
        (&r.name, r.width, r.height, r.srgb) != (&b.name, b.width, b.height, b.srgb)
            || (alpha_decides[k] && alpha(r) != alpha(b))
    })?;
    Some(format!("textures {k} differs"))
}

/// Which part of a frame state differs: "camera" or "node poses".
fn frame_state_difference(recorded: &FrameState, baked: &FrameState) -> Option<&'static str> {
    if recorded.camera != baked.camera {
        Some("camera")
    } else if recorded.poses != baked.poses {
        Some("node poses")
    } else {
        None
    }
}

/// Every statistic the file states that its draws and the recordings determine, recomputed.
pub(crate) fn check_stats(
    recordings: &[Recording],
    baked: &Baked,
    tally: &Tally,
    report: &mut GraphReport,
) {
    let s = &baked.stats;
    let frames = tally.draws.len().max(1) as f64;
    let whole = |name: &str, stated: u64, derived: u64, from: &str, report: &mut GraphReport| {
        if stated != derived {
            report.problem(format!(
                "statistic {name}: the file states {stated}, {from} give {derived}"
            ));
        }
    };
    let mean = |name: &str, stated: f64, derived: f64, from: &str, report: &mut GraphReport| {
        if (stated - derived).abs() > 1e-9 * derived.abs().max(1.0) || stated.is_nan() {
            report.problem(format!(
                "statistic {name}: the file states {stated}, {from} give {derived}"
            ));
        }
    };
    let copies = baked.copies.len() as u64;
    whole(
        "index_triangles",
        s.index_triangles,
        copies,
        "its copies",
        report,
    );
    let g = recordings.first().map_or(0, |r| r.unique_visible.len()) as u64;
    whole(
        "unique_visible",
        s.unique_visible,
        g,
        "the recordings",
        report,
    );
    whole(
        "source_triangles",
        s.source_triangles,
        tally.visible,
        "the recordings",
        report,
    );
    let max = tally.draws.iter().copied().max().unwrap_or(0) as u64;
    whole(
        "draws_per_frame_max",
        s.draws_per_frame_max as u64,
        max,
        "its frames",
        report,
    );
    let sum: f64 = tally.draws.iter().map(|&c| c as f64).sum();
    mean(
        "draws_per_frame_mean",
        s.draws_per_frame_mean,
        sum / frames,
        "its frames",
        report,
    );
    let dnv = tally.drawn_minus_visible as f64 / frames;
    let from = "its draws and the recordings";
    mean(
        "drawn_not_visible_mean",
        s.drawn_not_visible_mean,
        dnv,
        from,
        report,
    );
    let removed = "its removed edges";
    whole(
        "unordered_samples",
        s.unordered_samples,
        tally.removed_weight,
        removed,
        report,
    );
}
