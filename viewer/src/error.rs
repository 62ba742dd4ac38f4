//! [`ViewerError`]: why the viewer could not open or stopped.

use std::path::PathBuf;

/// An error of the caller's [`ViewerHost::check_device`](crate::ViewerHost::check_device).
pub type BoxError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Why the viewer could not open a window or stopped playing.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// No display server is named, or none accepted a connection or a window.
    #[error("no display: the viewer needs X11 or Wayland{}", detail.as_ref().map_or(String::new(), |d| format!(" ({d})")))]
    NoDisplay {
        /// What failed when a display was named (`None`: none was).
        detail: Option<String>,
    },
    /// A playback rate that is not a positive number.
    #[error("the frame rate must be a positive number, not {0}")]
    Fps(f64),
    /// The baked file could not be read, or the player failed.
    #[error(transparent)]
    Player(#[from] trisort_player::PlayerError),
    /// The material variant asked for does not exist or cannot be played exactly.
    #[error("playing {}", file.display())]
    Variant {
        /// The baked file.
        file: PathBuf,
        /// What is wrong with the variant.
        #[source]
        source: trisort_format::VariantError,
    },
    /// The clip asked for ([`ViewerOptions::clip`](crate::ViewerOptions::clip)) is not in
    /// the file.
    #[error("playing {}", file.display())]
    Clip {
        /// The baked file.
        file: PathBuf,
        /// The error naming the file's clips.
        #[source]
        source: trisort_player::PlayerError,
    },
    /// A frame range that is empty or runs past the file's frames.
    #[error("frame range {start}..{end} is empty or outside the file's frames 0..{frames}")]
    FrameRange {
        /// First frame asked for.
        start: u32,
        /// End (exclusive) asked for.
        end: u32,
        /// Frames in the file.
        frames: u32,
    },
    /// The file has no frames to play.
    #[error("{}: the baked file has no frames", file.display())]
    NoFrames {
        /// The baked file.
        file: PathBuf,
    },
    /// The window, its device or the player could not be set up for the file.
    #[error("playing {}", file.display())]
    Open {
        /// The baked file.
        file: PathBuf,
        /// What failed.
        #[source]
        source: Box<ViewerError>,
    },
    /// The presorted renderer refused the file or a camera.
    #[error("showing {}", file.display())]
    Presorted {
        /// The presorted file.
        file: PathBuf,
        /// What failed.
        #[source]
        source: trisort_reference::ReferenceError,
    },
    /// wgpu could not create a surface for the window.
    #[error("creating a wgpu surface for the window")]
    Surface(#[source] wgpu::CreateSurfaceError),
    /// No GPU device can present to the window.
    #[error("opening a GPU device that can present to this window")]
    Adapter(#[source] trisort_gpu::GpuError),
    /// The surface could not be configured.
    #[error(transparent)]
    Gpu(#[from] trisort_gpu::GpuError),
    /// The caller's check refused the window's device.
    #[error(transparent)]
    Device(BoxError),
    /// Waiting for the GPU before rebuilding the player failed.
    #[error("waiting for the GPU: {0}")]
    Poll(wgpu::PollError),
    /// The window's surface was lost.
    #[error("the window's surface was lost")]
    SurfaceLost,
    /// wgpu reported an error no error scope caught.
    #[error("wgpu: {0}")]
    Wgpu(String),
    /// The event loop failed.
    #[error("window event loop")]
    EventLoop(#[source] winit::error::EventLoopError),
}
