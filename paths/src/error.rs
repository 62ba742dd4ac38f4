//! The crate's one error type: where (file and line, generator spec or scene) and what.

use std::fmt;
use std::path::PathBuf;

/// Why a path could not be built.
///
/// Every variant names its source: the TOML file (with line and column where a value or a key
/// is at fault), the generator spec, or the scene whose animation or camera is used.
#[derive(Debug, thiserror::Error)]
pub enum PathError {
    /// The TOML path file could not be read.
    #[error("{}: cannot read the path file: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The TOML path file is not valid TOML, or does not have the shape of a path file
    /// (unknown key, wrong type, unknown interpolation mode).
    #[error("{}:{line}:{column}: {message}", path.display())]
    Syntax {
        /// The file.
        path: PathBuf,
        /// 1-based line of the offending text.
        line: usize,
        /// 1-based column (in characters) of the offending text.
        column: usize,
        /// The parser's message.
        message: String,
    },
    /// A well-formed path that cannot be played: see [`Problem`].
    #[error("{at}: {problem}")]
    Invalid {
        /// Where the problem was found.
        at: Location,
        /// What is wrong.
        problem: Problem,
    },
}

impl PathError {
    /// The [`Problem`] of an [`PathError::Invalid`] error, `None` for read and syntax errors.
    pub fn problem(&self) -> Option<&Problem> {
        match self {
            PathError::Invalid { problem, .. } => Some(problem),
            _ => None,
        }
    }
}

/// Where a [`Problem`] was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The TOML file's path, the generator spec (`orbit:…`), or `gltf animation of <scene>`.
    pub source: String,
    /// 1-based line in the TOML file, where one value or key is at fault.
    pub line: Option<usize>,
    /// 1-based column (in characters) in the TOML file.
    pub column: Option<usize>,
}

impl Location {
    /// A location without line information.
    pub(crate) fn whole(source: impl Into<String>) -> Self {
        Location {
            source: source.into(),
            line: None,
            column: None,
        }
    }

    /// A location at a byte offset of `text` (the TOML file's contents).
    pub(crate) fn at_offset(source: impl Into<String>, text: &str, offset: usize) -> Self {
        let (line, column) = line_column(text, offset);
        Location {
            source: source.into(),
            line: Some(line),
            column: Some(column),
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.source)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(column) = self.column {
                write!(f, ":{column}")?;
            }
        }
        Ok(())
    }
}

/// What is wrong with a path.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Problem {
    /// The path would have no frame (`frames = 0`, `orbit:frames=0`).
    #[error("the path has zero frames")]
    ZeroFrames,
    /// A value is NaN or infinite.
    #[error("{what} is not a finite number")]
    NonFinite {
        /// The value's name (`eye`, `yfov`, `frames`, …).
        what: String,
    },
    /// The up vector is zero or parallel to the view direction, so the camera's roll is
    /// undefined.
    #[error(
        "frame {frame}: the up vector is zero or parallel to the view direction (eye → target)"
    )]
    UpParallel {
        /// The frame.
        frame: usize,
    },
    /// The eye is at the target, so there is no view direction.
    #[error("frame {frame}: eye and target are the same point")]
    EyeAtTarget {
        /// The frame.
        frame: usize,
    },
    /// The vertical field of view is not in (0°, 180°).
    #[error("yfov {degrees}° is outside (0°, 180°)")]
    FovOutOfRange {
        /// The field of view in degrees.
        degrees: f64,
    },
    /// znear ≤ 0, or a finite zfar ≤ znear.
    #[error("clip planes znear = {znear}, zfar = {} need 0 < znear < zfar", zfar.map_or("infinite".to_string(), |z| z.to_string()))]
    ClipPlanes {
        /// Near plane distance.
        znear: f64,
        /// Far plane distance (`None`: infinite).
        zfar: Option<f64>,
    },
    /// No node of the scene has this name.
    #[error("the scene has no node named {name:?}{}", suggestion(similar))]
    UnknownNode {
        /// The name asked for.
        name: String,
        /// Up to five node names of the scene that are close to it, closest first.
        similar: Vec<String>,
    },
    /// A generator parameter is unknown, repeated, unparsable or out of range.
    #[error("parameter {name:?}: {reason}")]
    BadParameter {
        /// The parameter's name.
        name: String,
        /// Why it was rejected.
        reason: String,
    },
    /// A generator spec names no known generator.
    #[error("unknown path generator {name:?} (known: orbit, dolly)")]
    UnknownGenerator {
        /// The word before the colon.
        name: String,
    },
    /// The scene has no triangles, so there is no bounding box to frame or orbit.
    #[error("the scene has no triangles to frame")]
    EmptyScene,
    /// A key or track is inconsistent (two keys at one frame, a key without a frame, a
    /// rotation without an axis, a malformed glTF channel, …).
    #[error("{0}")]
    Inconsistent(String),
}

fn suggestion(similar: &[String]) -> String {
    if similar.is_empty() {
        String::new()
    } else {
        let list: Vec<String> = similar.iter().map(|s| format!("{s:?}")).collect();
        format!("; similar names: {}", list.join(", "))
    }
}

/// 1-based (line, column in characters) of a byte offset into `text`.
pub(crate) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let mut start = offset;
    while !text.is_char_boundary(start) {
        start -= 1;
    }
    let before = &text[..start];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    (line, column)
}

/// Up to five of `names` closest to `wanted` (names containing it first, then by
/// case-insensitive edit distance), closest first, without duplicates.
pub(crate) fn similar_names<'a>(wanted: &str, names: impl Iterator<Item = &'a str>) -> Vec<String> {
    let w = wanted.to_lowercase();
    let mut scored: Vec<(usize, String)> = Vec::new();
    for name in names {
        if name.is_empty() || scored.iter().any(|(_, s)| s == name) {
            continue;
        }
        let n = name.to_lowercase();
        let contains = !w.is_empty() && n.contains(&w);
        let d = edit_distance(&w, &n);
        let limit = (w.chars().count().max(3) / 2).max(2);
        if contains || d <= limit {
            let score = if contains { 0 } else { d };
            scored.push((score, name.to_string()));
        }
    }
    scored.sort();
    scored.into_iter().take(5).map(|(_, s)| s).collect()
}

/// Levenshtein distance over characters. O(|a|·|b|).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for (i, ca) in a.chars().enumerate() {
        cur[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_count_characters() {
        let text = "a = 1\nbé = 2\n  c";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 6), (2, 1));
        // 'é' is two bytes: the '=' after "bé " is the 4th character of line 2.
        assert_eq!(line_column(text, 10), (2, 4));
        assert_eq!(line_column(text, text.len()), (3, 4));
    }

    #[test]
    fn edit_distance_counts_edits() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("door", "door"), 0);
    }

    #[test]
    fn similar_names_prefer_close_and_containing_names() {
        let names = [
            "BodyDoorLColor1",
            "BodyDoorRColor1",
            "BodyHood",
            "WheelFrontL",
            "BodyDoorLColor1",
        ];
        let s = similar_names("BodyDoorLColour1", names.iter().copied());
        assert_eq!(s, vec!["BodyDoorLColor1", "BodyDoorRColor1"]);
        let s = similar_names("hood", names.iter().copied());
        assert_eq!(s, vec!["BodyHood"]);
        assert!(similar_names("zzzzzzzz", names.iter().copied()).is_empty());
    }
}
