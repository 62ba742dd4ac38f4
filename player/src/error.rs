//! The player's error type.

use std::path::PathBuf;

/// Errors loading or playing a baked file.
#[derive(Debug, thiserror::Error)]
pub enum PlayerError {
    /// The file could not be read or decoded (the message names the file).
    #[error(transparent)]
    Format(#[from] trisort_format::FormatError),
    /// The file decoded but its contents are inconsistent.
    #[error("{}: inconsistent baked file: {reason}", path.as_ref().map_or("<memory>".into(), |p| p.display().to_string()))]
    Structure {
        /// The file, when it came from one.
        path: Option<PathBuf>,
        /// The first problem found.
        reason: trisort_format::StructureError,
    },
    /// A frame index beyond the file's frames.
    #[error("frame {frame} does not exist (the file has {frames} frames)")]
    FrameOutOfRange {
        /// The frame asked for.
        frame: u32,
        /// Frames in the file.
        frames: u32,
    },
    /// The file does not fit the device's binding tier (e.g. too many frames × nodes for the
    /// data textures of a WebGL2-class device).
    #[error("this baked file does not fit the device: {0}")]
    DeviceTooSmall(String),
    /// `depth` mode without a depth attachment format.
    #[error("depth mode needs a depth attachment: set PlayerConfig::depth_format")]
    DepthFormatMissing,
    /// A GPU resource could not be created or read (targets, readback).
    #[error(transparent)]
    Gpu(#[from] trisort_gpu::GpuError),
    /// wgpu refused to create a resource or run a command.
    #[error("wgpu: {0}")]
    Wgpu(String),
    /// A material variant that does not exist or cannot be played exactly
    /// ([`Player::set_variant`](crate::Player::set_variant)).
    #[error(transparent)]
    Variant(#[from] trisort_format::VariantError),
    /// A clip name the file does not have ([`Player::set_clip`](crate::Player::set_clip)).
    #[error("no clip named {name:?}; the file's clips: {}", clips.join(", "))]
    UnknownClip {
        /// The name asked for.
        name: String,
        /// The file's clips, in frame order.
        clips: Vec<String>,
    },
    /// The device was lost or a readback failed.
    #[error("GPU readback failed: {0}")]
    Readback(String),
}
