//! The merger's 32-bit counts: the splitter's table of which copy is drawn at each
//! vertex-frame, and the baked file's draws, which address copies in u32 index units. Every
//! such count goes through [`checked`], which fails with [`MergeError::TooLarge`] naming the
//! limit instead of wrapping silently.

use crate::MergeError;

/// A count the merger keeps in 32 bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    /// Vertex-frames of one segment: the vertices of every frame's graph, summed over the
    /// segment's frames (offsets into the splitter's table of drawn copies).
    VertexFrames,
    /// Triangle copies in the index buffer: draws address them in u32 index units, three per
    /// copy (`first_index`, `index_count`).
    Copies,
    /// Draws of all frames together (`FrameWindow::first`).
    Draws,
}

impl Limit {
    /// The largest count that fits: 4,294,967,295 vertex-frames or draws, 1,431,655,765
    /// copies.
    pub const fn max(self) -> u64 {
        match self {
            Limit::VertexFrames | Limit::Draws => u32::MAX as u64,
            Limit::Copies => u32::MAX as u64 / 3,
        }
    }

    /// What addresses the count in 32 bits.
    pub fn why(self) -> &'static str {
        match self {
            Limit::VertexFrames => "the splitter's table offsets are u32",
            Limit::Copies => "draws address copies in u32 indices, 3 per copy",
            Limit::Draws => "frame windows address draws with u32 offsets",
        }
    }

    /// What the user can do about it.
    pub fn hint(self) -> &'static str {
        match self {
            Limit::VertexFrames => "merge with a shorter --segment",
            Limit::Copies | Limit::Draws => "bake the path in several parts",
        }
    }
}

impl std::fmt::Display for Limit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Limit::VertexFrames => "vertex-frames in one segment",
            Limit::Copies => "triangle copies",
            Limit::Draws => "draws",
        })
    }
}

/// `count` as a u32 if it is at most `limit`'s [`Limit::max`], else the error that names the
/// limit.
pub(crate) fn checked(limit: Limit, count: u64) -> Result<u32, MergeError> {
    if count <= limit.max() {
        Ok(count as u32)
    } else {
        Err(MergeError::TooLarge { limit, count })
    }
}

/// Checks that no segment holds more vertex-frames than [`Limit::VertexFrames`] allows, given
/// every frame's vertex count (`vertices[f]`) and the segments (frame ranges).
pub(crate) fn check_segments(
    vertices: &[u64],
    segments: &[std::ops::Range<u32>],
) -> Result<(), MergeError> {
    for seg in segments {
        let sum = vertices[seg.start as usize..seg.end as usize]
            .iter()
            .fold(0u64, |a, &v| a.saturating_add(v));
        checked(Limit::VertexFrames, sum)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_up_to_the_limit_pass() {
        assert_eq!(
            checked(Limit::Copies, 1_431_655_765).ok(),
            Some(1_431_655_765)
        );
        assert_eq!(
            checked(Limit::VertexFrames, u32::MAX as u64).ok(),
            Some(u32::MAX)
        );
        assert_eq!(checked(Limit::Draws, 0).ok(), Some(0));
        // Three index units per copy still fit in u32 at the limit.
        assert!(Limit::Copies.max() * 3 <= u32::MAX as u64);
    }

    #[test]
    fn counts_above_the_limit_fail_naming_it() {
        for (limit, count) in [
            (Limit::VertexFrames, 4_294_967_296u64),
            (Limit::Copies, 1_431_655_766),
            (Limit::Draws, 5_000_000_000),
        ] {
            let e = checked(limit, count).expect_err("over the limit");
            let text = e.to_string();
            assert!(text.contains(&count.to_string()), "{text}");
            assert!(text.contains(&limit.max().to_string()), "{text}");
            assert!(text.contains(limit.hint()), "{text}");
        }
        let e = checked(Limit::Copies, 1_431_655_766)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "1431655766 triangle copies exceed the limit of 1431655765 (draws address copies \
             in u32 indices, 3 per copy); bake the path in several parts"
        );
    }

    #[test]
    fn segments_are_checked_one_by_one() {
        // Two segments of 3 GiB vertex-frames each: each fits, together they would not.
        let per_frame = [1u64 << 30; 6];
        assert!(check_segments(&per_frame, &[0..3, 3..6]).is_ok());
        let whole = std::slice::from_ref(&(0..6));
        let e = check_segments(&per_frame, whole).unwrap_err();
        assert!(matches!(
            e,
            MergeError::TooLarge { limit: Limit::VertexFrames, count } if count == 6 << 30
        ));
        assert!(e.to_string().contains("--segment"));
        // A sum beyond u64 saturates instead of wrapping below the limit.
        assert!(check_segments(&[u64::MAX, 5], std::slice::from_ref(&(0..2))).is_err());
    }
}
