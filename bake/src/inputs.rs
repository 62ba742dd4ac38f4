//! Recordings as inputs of a merge or of a shard's phase 2: read and checked, checked to be
//! parts of one bake, and phase-1 results joined into G.

use std::path::{Path, PathBuf};

use trisort_format::{Baked, DeviceInfo, FileKind, Phase, RecordSettings, Recording};
use trisort_merger::{list_differences, settings_differences};
use trisort_scene::Scene;

use crate::{working_scene, BakeError, Working};

/// Reads one recording and checks its structure, naming the file when either fails.
pub fn read_recording(file: &Path) -> Result<Recording, BakeError> {
    let rec: Recording = trisort_format::read_file(FileKind::Recording, file)?;
    rec.check_structure()
        .map_err(|e| BakeError::Input(format!("{}: malformed recording: {e}", file.display())))?;
    Ok(rec)
}

/// Reads recordings and checks their structure ([`read_recording`]).
pub fn read_recordings(files: &[PathBuf]) -> Result<Vec<Recording>, BakeError> {
    files.iter().map(|f| read_recording(f)).collect()
}

/// Checks that `recs` (read from `files`) are parts of one bake
/// ([`trisort_merger::differences`] against the first): an error naming the file and every
/// difference, except that with `allow_mixed_devices` a different device only gives a
/// warning, handed to `warn` as soon as it is found (before a later file may be refused).
pub fn check_compatible(
    recs: &[Recording],
    files: &[PathBuf],
    allow_mixed_devices: bool,
    warn: &mut dyn FnMut(String),
) -> Result<(), BakeError> {
    for (k, r) in recs.iter().enumerate().skip(1) {
        let (device, other): (Vec<_>, Vec<_>) = trisort_merger::differences(&recs[0], r)
            .into_iter()
            .partition(|d| d.device);
        let (this, first) = (files[k].display(), files[0].display());
        if !other.is_empty() {
            return Err(BakeError::Input(format!(
                "{this} is not part of the same bake as {first}: {}",
                list_differences(&other)
            )));
        }
        if device.is_empty() {
            continue;
        }
        if !allow_mixed_devices {
            return Err(BakeError::Input(format!(
                "{this} was recorded on another device than {first}: {}; a bake of both is \
                 exact on neither (re-record it on one kind of device, or merge anyway with \
                 --allow-mixed-devices)",
                list_differences(&device)
            )));
        }
        warn(format!(
            "{this} was recorded on another device than {first}: {}; merged anyway \
             (--allow-mixed-devices): the bake is exact on neither, and its device says \
             \"mixed: …\"",
            list_differences(&device)
        ));
    }
    Ok(())
}

/// An error unless `rec` (read from `file`) was recorded with `settings`.
fn check_settings(
    rec: &Recording,
    file: &Path,
    settings: &RecordSettings,
) -> Result<(), BakeError> {
    let differ = settings_differences(&rec.settings, settings);
    if differ.is_empty() {
        return Ok(());
    }
    Err(BakeError::Input(format!(
        "{}: recorded with other settings than this command line's: {}",
        file.display(),
        list_differences(&differ)
    )))
}

/// A recording's file and the device it was recorded on.
pub type FileDevice = (PathBuf, DeviceInfo);

/// G from phase-1 recordings (`files`) that together cover every frame of `working`'s path,
/// recorded with `settings`; with the device each file was recorded on (phase 2 must run on
/// the same kind).
pub fn union_of_visibility(
    files: &[PathBuf],
    working: &Working,
    settings: &RecordSettings,
) -> Result<(Vec<u32>, Vec<FileDevice>), BakeError> {
    let n = working.timeline.frames.len();
    let mut seen = vec![false; n];
    let mut g = Vec::new();
    let mut devices = Vec::new();
    let (scene_hash, path_hash) = (working.scene.hash(), working.timeline.hash());
    for f in files {
        let rec = read_recording(f)?;
        if rec.scene_hash != scene_hash || rec.path_hash != path_hash || rec.frame_states.len() != n
        {
            let why = format!("{}: recorded from another scene or path", f.display());
            return Err(BakeError::Input(why));
        }
        check_settings(&rec, f, settings)?;
        devices.push((f.clone(), rec.device.clone()));
        for fr in &rec.frames {
            seen[fr.frame as usize] = true;
            g.extend_from_slice(&fr.visible);
        }
    }
    if let Some(missing) = seen.iter().position(|s| !s) {
        return Err(BakeError::Input(format!(
            "the --visibility recordings do not cover frame {missing} of the path's {n}; G \
             needs every frame"
        )));
    }
    g.sort_unstable();
    g.dedup();
    Ok((g, devices))
}

/// Joins phase-1 recordings (`files`, frame ranges covering `working`'s path, e.g. one per
/// shard) into one phase-1 recording of the whole path, whose G every shard's phase 2 reads;
/// they must be of `working`'s scene (`scene` and `path` name it in errors) and recorded with
/// `settings`.
pub fn join_visibility(
    files: &[PathBuf],
    working: &Working,
    settings: &RecordSettings,
    names: (&str, &str),
) -> Result<(Recording, usize), BakeError> {
    let recs = read_recordings(files)?;
    for (r, f) in recs.iter().zip(files) {
        if r.phase != Phase::Visibility {
            return Err(BakeError::Input(format!(
                "{}: not a phase-1 recording (record it with --phase visibility)",
                f.display()
            )));
        }
    }
    check_compatible(&recs, files, false, &mut |_| {})?;
    let rec = trisort_merger::join(&recs).map_err(|error| BakeError::Merge {
        error,
        files: files.iter().map(|f| f.display().to_string()).collect(),
    })?;
    if rec.scene_hash != working.scene.hash() || rec.path_hash != working.timeline.hash() {
        return Err(BakeError::Input(format!(
            "{}: recorded from another scene or path than {} --path {}",
            files[0].display(),
            names.0,
            names.1
        )));
    }
    check_settings(&rec, &files[0], settings)?;
    Ok((rec, recs.len()))
}

/// A baked file and the recordings (may be none) it was merged from, with their files.
pub struct Recorded<'a> {
    /// The baked file.
    pub baked: &'a Baked,
    /// Its file, for messages.
    pub baked_file: &'a Path,
    /// Its recordings.
    pub recordings: &'a [Recording],
    /// Their files, in the same order.
    pub files: &'a [PathBuf],
}

/// Makes `scene` (loaded from `spec`) the scene `recorded` was recorded from: split where
/// the recording split it (by the first recording's path and settings, else the baked
/// file's), and checked against the baked file's and every recording's scene hash, so that
/// a reference renders what was baked and the recordings' cycles excuse that scene's pixels.
pub fn recorded_scene(
    scene: &mut Scene,
    spec: &str,
    recorded: &Recorded<'_>,
) -> Result<(), BakeError> {
    let baked = recorded.baked;
    let (states, settings, from) = match (recorded.recordings.first(), recorded.files.first()) {
        (Some(r), Some(file)) => (&r.frame_states, r.settings, file.as_path()),
        _ => (&baked.frame_states, baked.settings, recorded.baked_file),
    };
    working_scene(scene, spec, states, &from.display().to_string(), &settings)?;
    let hash = scene.hash();
    if hash != baked.scene_hash {
        return Err(BakeError::Input(format!(
            "scene {spec} (hash {}) is not the scene the baked file was made from (hash {}): \
             give the same scene file, or for demo the same demo:TRIANGLES",
            &trisort_format::hash_hex(&hash)[..16],
            &trisort_format::hash_hex(&baked.scene_hash)[..16]
        )));
    }
    for (file, r) in recorded.files.iter().zip(recorded.recordings) {
        if r.scene_hash != hash {
            return Err(BakeError::Input(format!(
                "{}: the recording is not of scene {spec}: its pixels cannot excuse the scene's",
                file.display()
            )));
        }
    }
    Ok(())
}
