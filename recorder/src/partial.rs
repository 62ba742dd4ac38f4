//! `OUT.partial/`: finished frames stored as they finish, so an interrupted recording resumes.
//!
//! The folder holds a `key` file, the hash of everything that decides a frame's result (scene,
//! path, settings, phase, range, the given G, tool version), and one small file per finished
//! frame and phase. A folder with another key is emptied before use; a frame file that does not
//! decode is recorded again.

use std::path::{Path, PathBuf};

use serde::{de::DeserializeOwned, Serialize};
use trisort_format::container::{decode, encode, write_bytes_atomic, FileKind};
use trisort_format::{Edge, FormatError};

use crate::RecordJob;

/// A partial-results folder bound to one job.
pub struct PartialDir {
    dir: PathBuf,
}

/// A finished frame's result as stored (its encoding is the value's): read only at the
/// current format version, like a recording.
#[derive(serde::Deserialize)]
#[serde(transparent)]
struct Finished<T>(T);

impl<T: DeserializeOwned> trisort_format::Stored for Finished<T> {}

/// Phase-1 result of a frame: visible set, layers, truncated.
pub(crate) type Visibility = (Vec<u32>, u32, bool);
/// Phase-2 result of a frame: covered, edges, ties, layers, truncated, and the triangles the
/// tie rule brings before saturation (they join V_f).
pub(crate) type Graph = (Vec<u32>, Vec<Edge>, Vec<Edge>, u32, bool, Vec<u32>);

/// The partial folder that belongs to output file `out`: `OUT.partial/`.
pub fn partial_path(out: &Path) -> PathBuf {
    let mut name = out.file_name().unwrap_or_default().to_os_string();
    name.push(".partial");
    out.with_file_name(name)
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> FormatError + '_ {
    move |source| FormatError::Io {
        path: path.to_path_buf(),
        source,
    }
}

impl PartialDir {
    /// Opens (creating if needed) the folder for `job`; clears it when it holds another job's
    /// frames. Returns the folder and how many finished frame files it already holds.
    pub fn open(dir: &Path, job: &RecordJob) -> Result<(PartialDir, usize), FormatError> {
        let key = trisort_format::hash_hex(&job_key(job));
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let key_path = dir.join("key");
        let same = std::fs::read_to_string(&key_path)
            .map(|k| k.trim() == key)
            .unwrap_or(false);
        let mut existing = 0;
        for entry in std::fs::read_dir(dir).map_err(io(dir))? {
            let entry = entry.map_err(io(dir))?;
            if entry.file_name() == "key" {
                continue;
            }
            if same {
                existing += 1;
            } else {
                std::fs::remove_file(entry.path()).map_err(io(&entry.path()))?;
            }
        }
        if !same {
            write_bytes_atomic(&key_path, key.as_bytes())?;
        }
        Ok((
            PartialDir {
                dir: dir.to_path_buf(),
            },
            existing,
        ))
    }

    /// Removes the folder (after the final file was written).
    pub fn remove(self) -> Result<(), FormatError> {
        std::fs::remove_dir_all(&self.dir).map_err(io(&self.dir))
    }

    fn load<T: DeserializeOwned>(&self, name: String) -> Option<T> {
        let path = self.dir.join(name);
        let bytes = std::fs::read(&path).ok()?;
        decode::<Finished<T>>(FileKind::Recording, &bytes, &path)
            .ok()
            .map(|f| f.0)
    }

    fn store<T: Serialize>(&self, name: String, value: &T) -> Result<(), FormatError> {
        write_bytes_atomic(&self.dir.join(name), &encode(FileKind::Recording, value))
    }

    pub(crate) fn load_visibility(&self, frame: u32) -> Option<Visibility> {
        self.load(format!("visibility-{frame:07}"))
    }

    pub(crate) fn store_visibility(&self, frame: u32, v: &Visibility) -> Result<(), FormatError> {
        self.store(format!("visibility-{frame:07}"), v)
    }

    pub(crate) fn load_graph(&self, frame: u32) -> Option<Graph> {
        self.load(format!("graph-{frame:07}"))
    }

    pub(crate) fn store_graph(&self, frame: u32, g: &Graph) -> Result<(), FormatError> {
        self.store(format!("graph-{frame:07}"), g)
    }
}

fn job_key(job: &RecordJob) -> trisort_format::Hash {
    let s = &job.settings;
    let mut h = blake3::Hasher::new();
    h.update(trisort_format::TOOL_VERSION.as_bytes());
    h.update(&job.scene_hash);
    h.update(&job.path_hash);
    for x in [
        s.width,
        s.height,
        s.samples,
        s.max_layers,
        s.saturation.to_bits(),
        s.glass_opacity.to_bits(),
    ] {
        h.update(&x.to_le_bytes());
    }
    h.update(format!("{:?} {:?} {:?}", job.phase, job.range, s.robust).as_bytes());
    if let Some(g) = &job.known_visible {
        h.update(b"G");
        h.update(bytemuck::cast_slice(g));
    }
    *h.finalize().as_bytes()
}
