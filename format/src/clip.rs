//! Clips: the camera paths of a bundle. A baked file (and the recording it is merged from)
//! holds one or more paths, each a named run of consecutive frames with its own rate, all
//! drawn from one sorted index buffer.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use crate::Hash;

/// One camera path of a bundle: frames `first .. first + count` of the file, named, with the
/// rate it plays at and the identity of the path it was sampled from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Clip {
    /// The clip's name (`bake --path NAME=SPEC`; [`Clip::DEFAULT_NAME`] when unnamed): 1 to
    /// [`Clip::MAX_NAME`] ASCII letters, digits, `_`, `-` and `.`, starting with a letter or
    /// digit; unique within a file.
    pub name: String,
    /// The clip's first frame among the file's frames.
    pub first: u32,
    /// Its number of frames (at least one).
    pub count: u32,
    /// Frames per second it plays at by default (`None` where the recording did not know).
    pub fps: Option<f64>,
    /// Hash of the path's frames the clip was sampled from (the whole path, even where the
    /// clip is a range of it).
    pub path_hash: Hash,
    /// The frame of that path the clip starts at (`bake --frames A..B`: A; else 0).
    pub path_first: u32,
}

impl Clip {
    /// The name of a file's only clip when its path was not named, and of the clip a file
    /// of format 4 or 5 (which had none) is read with.
    pub const DEFAULT_NAME: &'static str = "main";
    /// The longest clip name, in bytes.
    pub const MAX_NAME: usize = 64;

    /// The only clip of a file of one whole path of `frames` frames: [`Clip::DEFAULT_NAME`].
    pub fn whole(frames: u32, fps: Option<f64>, path_hash: Hash) -> Clip {
        Clip {
            name: Clip::DEFAULT_NAME.into(),
            first: 0,
            count: frames,
            fps,
            path_hash,
            path_first: 0,
        }
    }

    /// The file's frames the clip spans.
    pub fn frames(&self) -> Range<u32> {
        self.first..self.first + self.count
    }

    /// Checks a clip name: what [`Clip::name`] allows, or why not in words.
    pub fn check_name(name: &str) -> Result<(), String> {
        let ok_char = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.');
        if name.is_empty() || name.len() > Clip::MAX_NAME {
            return Err(format!(
                "clip name {name:?} must be 1 to {} characters long",
                Clip::MAX_NAME
            ));
        }
        if !name.starts_with(|c: char| c.is_ascii_alphanumeric()) || !name.chars().all(ok_char) {
            return Err(format!(
                "clip name {name:?} may hold only ASCII letters, digits, `_`, `-` and `.`, and \
                 must start with a letter or digit"
            ));
        }
        Ok(())
    }
}

/// Checks a file's clips against its `frames` frames: at least one; valid, unique names;
/// each at least one frame long, with a valid rate; together they cover the frames in order,
/// each starting where the one before ends.
pub fn check_clips(clips: &[Clip], frames: usize) -> Result<(), crate::StructureError> {
    let layout = |problem: String| crate::Part::Layout.error(problem);
    if clips.is_empty() {
        return Err(layout("the file lists no clip".into()));
    }
    let mut next = 0u64;
    for (k, c) in clips.iter().enumerate() {
        Clip::check_name(&c.name).map_err(|why| layout(format!("clip {k}: {why}")))?;
        if clips[..k].iter().any(|d| d.name == c.name) {
            return Err(layout(format!("clip name {:?} is listed twice", c.name)));
        }
        if c.count == 0 || c.first as u64 != next {
            return Err(layout(format!(
                "clip {:?} spans frames {}..{}; clips must follow each other from frame 0, \
                 each at least one frame long (this one should start at {next})",
                c.name,
                c.first,
                c.first as u64 + c.count as u64
            )));
        }
        crate::baked::check_fps(c.fps)?;
        next += c.count as u64;
    }
    if next != frames as u64 {
        return Err(layout(format!(
            "the clips cover {next} frames, the file has {frames}"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clip(name: &str, first: u32, count: u32) -> Clip {
        Clip {
            name: name.into(),
            first,
            count,
            fps: Some(5.0),
            path_hash: [0; 32],
            path_first: 0,
        }
    }

    #[test]
    fn clips_must_cover_the_frames_in_order_with_unique_names() {
        check_clips(&[clip("tour", 0, 3), clip("door", 3, 2)], 5).unwrap();
        let cases: [(Vec<Clip>, usize, &str); 7] = [
            (vec![], 0, "no clip"),
            (vec![clip("tour", 0, 3)], 4, "cover 3 frames"),
            (vec![clip("a", 0, 2), clip("a", 2, 2)], 4, "twice"),
            (
                vec![clip("a", 0, 2), clip("b", 3, 1)],
                4,
                "should start at 2",
            ),
            (
                vec![clip("a", 0, 0), clip("b", 0, 1)],
                1,
                "at least one frame",
            ),
            (vec![clip("", 0, 1)], 1, "1 to 64"),
            (vec![clip("a b", 0, 1)], 1, "may hold only"),
        ];
        for (clips, frames, needle) in cases {
            let err = check_clips(&clips, frames).unwrap_err().problem;
            assert!(err.contains(needle), "{err:?} lacks {needle:?}");
        }
        let mut bad_fps = clip("a", 0, 1);
        bad_fps.fps = Some(0.0);
        assert!(check_clips(&[bad_fps], 1).is_err());
        assert!(Clip::check_name("door-open_2.v1").is_ok());
        assert!(Clip::check_name("-x").is_err());
        assert!(Clip::check_name(&"x".repeat(65)).is_err());
    }
}
