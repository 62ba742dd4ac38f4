//! The compositing mode a baked frame is played in: a typed option shared by the player, the
//! reference, the bench and the CLI (the equations are in the player's crate documentation).

use std::fmt;
use std::str::FromStr;

/// How the sorted triangles are composited (see the crate documentation for the equations).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Back to front, *over*, no depth test.
    #[default]
    Blend,
    /// Front to back with the depth test (`Less`, depth writes) and *over*.
    Depth,
    /// Front to back, *under* on a target cleared to alpha 0, no depth test.
    Saturate,
}

impl Mode {
    /// Every mode.
    pub const ALL: [Mode; 3] = [Mode::Blend, Mode::Depth, Mode::Saturate];

    /// The CLI name (`blend`, `depth`, `saturate`).
    pub fn name(self) -> &'static str {
        match self {
            Mode::Blend => "blend",
            Mode::Depth => "depth",
            Mode::Saturate => "saturate",
        }
    }

    /// Whether the mode plays the stored order reversed (back to front).
    pub fn back_to_front(self) -> bool {
        self == Mode::Blend
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown mode name.
#[derive(Debug, thiserror::Error)]
#[error("unknown mode `{0}` (expected blend, depth or saturate)")]
pub struct ParseModeError(pub String);

impl FromStr for Mode {
    type Err = ParseModeError;
    fn from_str(s: &str) -> Result<Mode, ParseModeError> {
        Mode::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| ParseModeError(s.to_string()))
    }
}
