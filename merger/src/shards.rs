//! Recordings made apart: what must be equal for them to be merged or joined
//! ([`differences`]), and [`join`], which puts frame ranges recorded on several machines back
//! into the one recording a single machine would have written.

use trisort_format::{hash_hex, DeviceInfo, Phase, RecordSettings, Recording};

use crate::MergeError;

/// One way in which a recording differs from another it is merged or joined with.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Difference {
    /// Whether it is the recording device (adapter, driver or backend): the only kind
    /// `merge --allow-mixed-devices` accepts, with a warning.
    pub device: bool,
    /// What differs, with both values (`size 128x128 vs 256x256`).
    pub what: String,
}

impl std::fmt::Display for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.what)
    }
}

/// Differences as one `; `-separated line (`size "1x1" vs "2x2"; samples "1" vs "4"`).
pub fn list_differences(d: &[Difference]) -> String {
    d.iter()
        .map(|d| d.what.as_str())
        .collect::<Vec<_>>()
        .join("; ")
}

/// Named fields that differ: `what "x" vs "y"` for each (device?, what, x, y) with x ≠ y.
fn differing(fields: Vec<(bool, &str, String, String)>) -> Vec<Difference> {
    fields
        .into_iter()
        .filter(|(_, _, x, y)| x != y)
        .map(|(device, what, x, y)| Difference {
            device,
            what: format!("{what} {x:?} vs {y:?}"),
        })
        .collect()
}

/// How device `b` differs from `a`: adapter (`device`), driver, backend.
pub fn device_differences(a: &DeviceInfo, b: &DeviceInfo) -> Vec<Difference> {
    differing(vec![
        (true, "device", a.adapter.clone(), b.adapter.clone()),
        (true, "driver", a.driver.clone(), b.driver.clone()),
        (true, "backend", a.backend.clone(), b.backend.clone()),
    ])
}

/// How settings `t` differ from `s`: size, samples, saturation, glass opacity, max layers,
/// intersection splitting and robust recording. Every field is named by an exhaustive
/// destructure, so a field added to [`RecordSettings`] fails to compile here until it is
/// compared too.
pub fn settings_differences(s: &RecordSettings, t: &RecordSettings) -> Vec<Difference> {
    let fields = |r: &RecordSettings| {
        let RecordSettings {
            width,
            height,
            samples,
            saturation,
            glass_opacity,
            max_layers,
            split_intersections,
            robust,
        } = *r;
        [
            ("size", format!("{width}x{height}")),
            ("samples", samples.to_string()),
            ("saturation", saturation.to_string()),
            ("glass opacity", glass_opacity.to_string()),
            ("max layers", max_layers.to_string()),
            ("intersection splitting", split_intersections.to_string()),
            ("robust", format!("{robust:?}")),
        ]
    };
    differing(
        fields(s)
            .into_iter()
            .zip(fields(t))
            .map(|((what, x), (_, y))| (false, what, x, y))
            .collect(),
    )
}

/// Everything in which recording `b` differs from `a` that makes them parts of different
/// bakes: the device ([`device_differences`]), the tool version, the settings
/// ([`settings_differences`]), the scene, the path (hash and frames), the phase and, between
/// two recordings with graphs, G. Frame ranges are not compared. Empty when they may be
/// merged or joined.
pub fn differences(a: &Recording, b: &Recording) -> Vec<Difference> {
    // Every field, so that one added to `Recording` fails to compile here until it is either
    // compared below or said not to need it.
    let Recording {
        tool_version: _,
        scene_hash: _,
        path_hash: _,
        settings: _,
        device: _,
        phase: _,
        scene_triangles: _,
        frame_states: _,
        unique_visible: _,
        frames: _,   // the ranges: what is joined, not compared
        geometry: _, // G's triangles: follows from the scene and G
        fps: _,      // part of the path hash
        clips: _,    // compared below
    } = a;
    let short = |h: &trisort_format::Hash| hash_hex(h)[..16].to_string();
    let phase = |r: &Recording| format!("{:?}", r.phase).to_lowercase();
    let mut out = device_differences(&a.device, &b.device);
    out.extend(differing(vec![(
        false,
        "tool version",
        a.tool_version.clone(),
        b.tool_version.clone(),
    )]));
    out.extend(settings_differences(&a.settings, &b.settings));
    out.extend(differing(vec![
        (
            false,
            "scene hash",
            short(&a.scene_hash),
            short(&b.scene_hash),
        ),
        (
            false,
            "scene triangles",
            a.scene_triangles.to_string(),
            b.scene_triangles.to_string(),
        ),
        (false, "path hash", short(&a.path_hash), short(&b.path_hash)),
        (
            false,
            "path frames",
            a.frame_states.len().to_string(),
            b.frame_states.len().to_string(),
        ),
        (false, "phase", phase(a), phase(b)),
    ]));
    if a.path_hash == b.path_hash
        && a.frame_states.len() == b.frame_states.len()
        && a.frame_states != b.frame_states
    {
        out.push(Difference {
            device: false,
            what: "frame states (cameras or poses) under one path hash".into(),
        });
    }
    if a.clips != b.clips {
        let names = |r: &Recording| {
            let v: Vec<String> = r
                .clips
                .iter()
                .map(|c| format!("{} {}..{}", c.name, c.first, c.first + c.count))
                .collect();
            v.join(", ")
        };
        out.push(Difference {
            device: false,
            what: format!("clips ({} vs {})", names(a), names(b)),
        });
    }
    if a.phase == Phase::Graphs && b.phase == Phase::Graphs && a.unique_visible != b.unique_visible
    {
        out.push(Difference {
            device: false,
            what: format!(
                "visible set G (|G| = {} vs {}; phase 2 ran with another G)",
                a.unique_visible.len(),
                b.unique_visible.len()
            ),
        });
    }
    out
}

/// The recordings' positions in frame order, checking that their ranges follow each other
/// from frame 0 to the end of the path (recording 0's).
pub(crate) fn frame_order(recordings: &[Recording]) -> Result<Vec<usize>, MergeError> {
    let first = recordings.first().ok_or(MergeError::NoRecordings)?;
    let mut order: Vec<usize> = (0..recordings.len()).collect();
    order.sort_by_key(|&k| (recordings[k].frame_range().start, k));
    let mut next = 0u32;
    for &k in &order {
        let r = &recordings[k];
        if r.frames.is_empty() {
            return Err(MergeError::NoFrames { recording: k });
        }
        let range = r.frame_range();
        if range.start != next {
            return Err(MergeError::NotContiguous {
                recording: k,
                expected: next,
                found: range,
            });
        }
        for (n, fr) in r.frames.iter().enumerate() {
            if fr.frame != range.start + n as u32 {
                return Err(MergeError::BadFrame {
                    recording: k,
                    frame: fr.frame,
                    why: "frames are not consecutive".into(),
                });
            }
        }
        next = range.end;
    }
    let total = first.frame_states.len() as u32;
    if next != total {
        return Err(MergeError::MissingFrames {
            covered: next,
            total,
        });
    }
    Ok(order)
}

/// The first recording (in the given order) that differs from recording 0, and how.
pub(crate) fn first_difference(
    recordings: &[Recording],
    allow_mixed_devices: bool,
) -> Result<(), MergeError> {
    let Some(first) = recordings.first() else {
        return Err(MergeError::NoRecordings);
    };
    for (k, r) in recordings.iter().enumerate().skip(1) {
        let d: Vec<Difference> = differences(first, r)
            .into_iter()
            .filter(|d| !(allow_mixed_devices && d.device))
            .collect();
        if !d.is_empty() {
            return Err(MergeError::Differs {
                recording: k,
                differences: list_differences(&d),
            });
        }
    }
    Ok(())
}

/// The device a bake of `recordings` (in frame order) names: recording 0's when all agree;
/// otherwise every device with the frames it recorded, each field starting `mixed: `, so that
/// the baked file itself says it was merged from several devices.
pub(crate) fn device_of(recordings: &[&Recording]) -> DeviceInfo {
    let first = &recordings[0].device;
    if recordings.iter().all(|r| r.device == *first) {
        return first.clone();
    }
    let list = |field: fn(&DeviceInfo) -> &str| {
        let parts: Vec<String> = recordings
            .iter()
            .map(|r| {
                let f = r.frame_range();
                format!("{} (frames {}..{})", field(&r.device), f.start, f.end)
            })
            .collect();
        format!("mixed: {}", parts.join("; "))
    };
    DeviceInfo {
        adapter: list(|d| &d.adapter),
        driver: list(|d| &d.driver),
        backend: list(|d| &d.backend),
    }
}

/// Joins frame ranges of one path recorded apart (any order, same device, settings, scene,
/// path and phase; with graphs, the same G) into the recording one machine would have written
/// for the whole path: frames in order, and for phase-1 (`Visibility`) recordings G as the
/// union of the parts' visible sets. The ranges must cover the path exactly. Recordings that
/// [`differences`] finds different are refused, naming the first such recording and how it
/// differs ([`MergeError::Differs`]), whatever the device policy of a later merge.
pub fn join(recordings: &[Recording]) -> Result<Recording, MergeError> {
    for (k, r) in recordings.iter().enumerate() {
        r.check_structure()
            .map_err(|why| MergeError::Invalid { recording: k, why })?;
    }
    first_difference(recordings, false)?;
    let order = frame_order(recordings)?;
    let first = &recordings[order[0]];
    let mut out: Recording = first.clone();
    out.frames.clear();
    for &k in &order {
        out.frames.extend_from_slice(&recordings[k].frames);
    }
    if out.phase == Phase::Visibility {
        let mut g: Vec<u32> = recordings
            .iter()
            .flat_map(|r| r.unique_visible.iter().copied())
            .collect();
        g.sort_unstable();
        g.dedup();
        out.unique_visible = g;
    }
    out.check_structure().map_err(|why| MergeError::Invalid {
        recording: order[0],
        why: trisort_format::StructureError {
            problem: format!("the joined recording: {}", why.problem),
            ..why
        },
    })?;
    Ok(out)
}
