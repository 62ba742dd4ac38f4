//! trisort's web player: plays a baked file on a `<canvas>` with WebGPU where the browser
//! offers it and WebGL2 otherwise (the player's GLES 3.0 / WebGL2 tier: node matrices and
//! materials in data textures, one `draw_indexed` per range).
//!
//! The wasm build (`web/build.sh`, wasm-bindgen) exports [`WebPlayer`](browser) to the page in
//! `web/www/`; a frame on the canvas is the headless player's frame, drawn into the same
//! `Rgba16Float` target and copied to the canvas by the same blit as the window viewer
//! ([`trisort_player::OnScreen`] in the wasm build). Natively this crate is only the small pure
//! part the page's figures and options rely on, so its unit tests run with the workspace's.
#![deny(missing_docs)]

use std::fmt;
use std::str::FromStr;

#[cfg(target_arch = "wasm32")]
mod bake;
#[cfg(target_arch = "wasm32")]
mod browser;
#[cfg(target_arch = "wasm32")]
pub use bake::BakedData;
#[cfg(target_arch = "wasm32")]
pub use browser::WebPlayer;

/// Which browser graphics API to play with (the page's `?backend=` parameter).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BrowserBackend {
    /// WebGPU where the browser offers a WebGPU adapter, WebGL2 otherwise.
    #[default]
    Auto,
    /// WebGPU only (an error where the browser has none).
    WebGpu,
    /// WebGL2 only.
    WebGl2,
}

impl BrowserBackend {
    /// The names the page accepts, in order.
    pub const NAMES: [&'static str; 3] = ["auto", "webgpu", "webgl2"];

    /// The name the page uses (`auto`, `webgpu`, `webgl2`).
    pub fn name(self) -> &'static str {
        match self {
            BrowserBackend::Auto => "auto",
            BrowserBackend::WebGpu => "webgpu",
            BrowserBackend::WebGl2 => "webgl2",
        }
    }
}

impl fmt::Display for BrowserBackend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for BrowserBackend {
    type Err = String;

    fn from_str(s: &str) -> Result<BrowserBackend, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "" | "auto" => Ok(BrowserBackend::Auto),
            "webgpu" => Ok(BrowserBackend::WebGpu),
            "webgl2" | "webgl" | "gl" => Ok(BrowserBackend::WebGl2),
            other => Err(format!(
                "unknown backend '{other}' (expected one of: {})",
                BrowserBackend::NAMES.join(", ")
            )),
        }
    }
}

/// What kind of failure an error thrown to JavaScript reports: its `kind` property, which the
/// npm package (`web/pkg`) maps to its error classes (`TrisortFormatError`, …).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// The bytes are not a baked file this player reads: damaged, cut short, another format
    /// version.
    Format,
    /// The browser's graphics: no WebGPU adapter, no surface for the canvas, a device that
    /// cannot play the file, a GPU error while drawing.
    Device,
    /// An option or a name the caller chose: an unknown backend, mode, shading, tone map,
    /// clip or variant, or a variant the bake refuses.
    Option,
}

impl ErrorKind {
    /// The `kind` property's value: `format`, `device` or `option`.
    pub fn name(self) -> &'static str {
        match self {
            ErrorKind::Format => "format",
            ErrorKind::Device => "device",
            ErrorKind::Option => "option",
        }
    }
}

/// One frame's figures as the page shows them under the canvas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameFigures {
    /// The frame shown (0-based).
    pub frame: u32,
    /// Frames in the file.
    pub frames: u32,
    /// Triangles drawn (the frame's window).
    pub triangles: u64,
    /// Draw calls issued (ranges of the window).
    pub draws: u32,
    /// Milliseconds the page measured for encoding and submitting the frame.
    pub ms: f64,
}

impl fmt::Display for FrameFigures {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "frame {}/{} · {} triangles · {} draws · {:.2} ms",
            self.frame + 1,
            self.frames,
            group_thousands(self.triangles),
            self.draws,
            self.ms
        )
    }
}

/// The frame after (`step` 1) or before (`step` −1) `frame` when playing the clip that spans
/// the file's frames `first .. first + count`: playback loops within the clip, and a frame
/// outside it (another clip's, shown when the clip was chosen) goes to the clip's first frame.
/// `count` 0 (no frames) stays at `first`.
pub fn step_in_clip(frame: u32, first: u32, count: u32, step: i32) -> u32 {
    if count == 0 || frame < first || frame - first >= count {
        return first;
    }
    let k = i64::from(frame - first) + i64::from(step);
    first + k.rem_euclid(i64::from(count)) as u32
}

/// What the figures line adds for a file of several clips: the clip's name and the frame's
/// place in it (`frame` among the file's frames; the clip spans `first .. first + count`).
pub fn clip_figures(name: &str, frame: u32, first: u32, count: u32) -> String {
    if frame < first || frame - first >= count {
        return format!(" · clip {name} (frame outside it)");
    }
    format!(" · clip {name} {}/{count}", frame - first + 1)
}

/// `37126` → `37,126`.
fn group_thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backends_parse_by_name_and_refuse_others() {
        for name in BrowserBackend::NAMES {
            let b: BrowserBackend = name.parse().unwrap();
            assert_eq!(b.name(), name);
        }
        assert_eq!("".parse::<BrowserBackend>(), Ok(BrowserBackend::Auto));
        assert_eq!(
            " WebGL2 ".parse::<BrowserBackend>(),
            Ok(BrowserBackend::WebGl2)
        );
        let err = "vulkan".parse::<BrowserBackend>().unwrap_err();
        assert!(err.contains("'vulkan'") && err.contains("webgl2"), "{err}");
    }

    #[test]
    fn error_kinds_are_the_packages_codes() {
        let names = [ErrorKind::Format, ErrorKind::Device, ErrorKind::Option].map(ErrorKind::name);
        assert_eq!(names, ["format", "device", "option"]);
    }

    #[test]
    fn playback_loops_within_the_clip() {
        // A clip over frames 20..48.
        assert_eq!(step_in_clip(20, 20, 28, 1), 21);
        assert_eq!(step_in_clip(47, 20, 28, 1), 20);
        assert_eq!(step_in_clip(20, 20, 28, -1), 47);
        assert_eq!(step_in_clip(30, 20, 28, -1), 29);
        // Another clip's frame goes to the clip's start.
        assert_eq!(step_in_clip(5, 20, 28, 1), 20);
        assert_eq!(step_in_clip(48, 20, 28, -1), 20);
        // A one-frame clip stays; a clip at the file's end near u32::MAX does not overflow.
        assert_eq!(step_in_clip(7, 7, 1, 1), 7);
        assert_eq!(step_in_clip(u32::MAX - 1, u32::MAX - 2, 2, 1), u32::MAX - 2);
        assert_eq!(step_in_clip(3, 3, 0, 1), 3);
        assert_eq!(clip_figures("door", 21, 20, 28), " · clip door 2/28");
        assert_eq!(
            clip_figures("door", 2, 20, 28),
            " · clip door (frame outside it)"
        );
    }

    #[test]
    fn figures_read_as_the_page_shows_them() {
        let f = FrameFigures {
            frame: 0,
            frames: 48,
            triangles: 1_037_126,
            draws: 38,
            ms: 5.234,
        };
        assert_eq!(
            f.to_string(),
            "frame 1/48 · 1,037,126 triangles · 38 draws · 5.23 ms"
        );
        assert_eq!(group_thousands(0), "0");
        assert_eq!(group_thousands(999), "999");
        assert_eq!(group_thousands(1000), "1,000");
    }
}
