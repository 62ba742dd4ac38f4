//! What is wrong with a decoded file that a reader must not use: the part at fault, the frame
//! where there is one, and the first problem found in words.

use std::fmt;

/// The part of a recording or baked file whose structure is wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Part {
    /// The recording settings ([`crate::RecordSettings::check_stored`]).
    Settings,
    /// The geometry: vertices, triangles, materials, textures, nodes, variants.
    Geometry,
    /// A frame's camera or node poses ([`crate::camera::check_frame_state`]).
    Camera,
    /// The stored light.
    Environment,
    /// A recording's visible set G and its frame records (visible and covered sets, edges,
    /// ties).
    Graphs,
    /// A baked file's scene ids, index buffer, draws, frame windows and per-frame lists.
    Layout,
    /// The frame rate.
    FrameRate,
}

impl Part {
    /// A problem of this part, of no one frame.
    pub fn error(self, problem: impl Into<String>) -> StructureError {
        StructureError::new(self, problem)
    }

    /// A problem of this part at frame `frame`.
    pub fn at_frame(self, frame: u32, problem: impl Into<String>) -> StructureError {
        StructureError::at_frame(self, frame, problem)
    }
}

impl fmt::Display for Part {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Part::Settings => "settings",
            Part::Geometry => "geometry",
            Part::Camera => "camera",
            Part::Environment => "environment",
            Part::Graphs => "graphs",
            Part::Layout => "layout",
            Part::FrameRate => "frame rate",
        })
    }
}

/// A structural problem of a decoded file (what `check_structure` and its parts return).
/// Displays as the problem alone, which names the frame, triangle or field.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{problem}")]
pub struct StructureError {
    /// The part at fault.
    pub part: Part,
    /// The frame, where the problem is one frame's.
    pub frame: Option<u32>,
    /// The first problem found, in words.
    pub problem: String,
}

impl StructureError {
    /// A problem of `part`, of no one frame.
    pub fn new(part: Part, problem: impl Into<String>) -> StructureError {
        StructureError {
            part,
            frame: None,
            problem: problem.into(),
        }
    }

    /// A problem of `part` at frame `frame`.
    pub fn at_frame(part: Part, frame: u32, problem: impl Into<String>) -> StructureError {
        StructureError {
            part,
            frame: Some(frame),
            problem: problem.into(),
        }
    }
}

impl From<StructureError> for String {
    fn from(e: StructureError) -> String {
        e.problem
    }
}
