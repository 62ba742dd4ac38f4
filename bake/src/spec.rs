//! The pipeline's settings as a command line or a batch script spells them: sizes
//! (`WIDTHxHEIGHT`), frame ranges (`a..b`), sub-pixel grids (`N` or `LEAST..MOST` bits) and
//! sub-pixel offsets (`X,Y` pixels). Each parser's error says what it expected.

use std::ops::Range;
use std::sync::OnceLock;

use trisort_format::{DepthAt, ProfileName, RecordSettings, Robust};

use crate::BakeError;

/// A value that does not parse, with what was expected.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct SpecError(pub String);

impl From<String> for SpecError {
    fn from(text: String) -> SpecError {
        SpecError(text)
    }
}

/// Parses `WIDTHxHEIGHT` or a single number for a square.
pub fn parse_size(s: &str) -> Result<(u32, u32), SpecError> {
    let parse = |x: &str| {
        x.trim()
            .parse::<u32>()
            .map_err(|_| format!("bad size {s:?}: expected WIDTHxHEIGHT"))
    };
    let (w, h) = match s.split_once(['x', 'X']) {
        Some((w, h)) => (parse(w)?, parse(h)?),
        None => {
            let n = parse(s)?;
            (n, n)
        }
    };
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("size {s}: each side must be 1..=16384").into());
    }
    Ok((w, h))
}

/// Parses a half-open frame range `a..b` (also `a..` and `..b`, and a single frame `a`).
pub fn parse_range(s: &str) -> Result<FrameRange, SpecError> {
    let num = |x: &str| -> Result<Option<u32>, String> {
        if x.is_empty() {
            Ok(None)
        } else {
            x.parse()
                .map(Some)
                .map_err(|_| format!("bad frame range {s:?}: expected a..b"))
        }
    };
    let (a, b) = match s.split_once("..") {
        Some((a, b)) => (num(a)?, num(b)?),
        None => {
            let a = num(s)?.ok_or_else(|| format!("bad frame range {s:?}"))?;
            (Some(a), Some(a + 1))
        }
    };
    Ok(FrameRange { start: a, end: b })
}

/// A frame range whose open ends are resolved against the path length.
#[derive(Clone, Copy, Debug)]
pub struct FrameRange {
    start: Option<u32>,
    end: Option<u32>,
}

impl From<Range<u32>> for FrameRange {
    fn from(r: Range<u32>) -> FrameRange {
        FrameRange {
            start: Some(r.start),
            end: Some(r.end),
        }
    }
}

impl FrameRange {
    /// The concrete range for a path of `n` frames; an error if it is empty or past the end.
    pub fn resolve(&self, n: u32) -> Result<Range<u32>, BakeError> {
        let r = self.start.unwrap_or(0)..self.end.unwrap_or(n);
        if r.start >= r.end || r.end > n {
            return Err(BakeError::FrameRange {
                start: r.start,
                end: r.end,
                frames: n,
            });
        }
        Ok(r)
    }
}

/// Parses `--subpixel-offset X,Y`: two finite numbers of pixels, each a decimal or a fraction
/// `a/b`, at most 16 pixels.
pub fn parse_subpixel_offset(s: &str) -> Result<[f64; 2], SpecError> {
    let bad = || format!("bad offset {s:?}: expected X,Y in pixels, e.g. 0.0625,0 or 1/16,0");
    let number = |x: &str| -> Result<f64, String> {
        let x = x.trim();
        let v = match x.split_once('/') {
            Some((a, b)) => {
                let (a, b) = (
                    a.trim().parse::<f64>().map_err(|_| bad())?,
                    b.trim().parse::<f64>().map_err(|_| bad())?,
                );
                if b == 0.0 {
                    return Err(bad());
                }
                a / b
            }
            None => x.parse::<f64>().map_err(|_| bad())?,
        };
        if !v.is_finite() || v.abs() > 16.0 {
            return Err(format!(
                "offset {s}: each component must be a finite number of pixels in [-16, 16]"
            ));
        }
        Ok(v)
    };
    let (x, y) = s.split_once(',').ok_or_else(bad)?;
    Ok([number(x)?, number(y)?])
}

/// Parses `--subpixel-bits`: `N` or `LEAST..MOST`.
pub fn parse_bits(s: &str) -> Result<(u32, u32), SpecError> {
    let bits = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{t}` is not a number of bits"))
    };
    let (lo, hi) = match s.split_once("..") {
        Some((a, b)) => (bits(a)?, bits(b.trim_start_matches('='))?),
        None => (bits(s)?, bits(s)?),
    };
    trisort_format::RasterProfile::check_bits(lo, hi).map_err(|e| e.to_string())?;
    Ok((lo, hi))
}

/// A raster profile as a command line chooses it: by name (or none: the default, `exact`
/// when not conservative), the conservative switch, and knobs set on top of the profile.
#[derive(Clone, Copy, Debug, Default)]
pub struct ProfileChoice {
    /// `--raster-profile`.
    pub name: Option<ProfileName>,
    /// `--conservative` (`Some(false)`: the recorded pattern only).
    pub conservative: Option<bool>,
    /// `--robust`: sample patterns recorded.
    pub patterns: u32,
    /// `--robust-tolerance`, in pixels.
    pub tolerance: Option<f32>,
    /// `--subpixel-bits`: least and most bits.
    pub subpixel_bits: Option<(u32, u32)>,
    /// `--depth-at`.
    pub depth_at: Option<DepthAt>,
}

impl ProfileChoice {
    /// The robust recording settings: the named profile with the knobs on top; an error when
    /// the name and the conservative switch contradict each other.
    pub fn robust(&self) -> Result<Robust, SpecError> {
        let name = match (self.name, self.conservative) {
            (Some(ProfileName::Exact), Some(true)) => {
                return Err(SpecError(
                    "--raster-profile exact records the pattern only; it cannot be \
                     --conservative"
                        .into(),
                ))
            }
            (Some(n), Some(false)) if n != ProfileName::Exact => {
                return Err(SpecError(format!(
                    "--raster-profile {n} records conservatively; --conservative=false is \
                     --raster-profile exact"
                )))
            }
            (Some(n), _) => n,
            (None, Some(false)) => ProfileName::Exact,
            (None, _) => Robust::DEFAULT.profile.name,
        };
        let mut robust = Robust::profile_named(name);
        robust.patterns = self.patterns;
        if let Some(t) = self.tolerance {
            robust.tolerance = t;
        }
        if let Some(c) = self.conservative {
            robust.conservative = c;
        }
        if let Some((lo, hi)) = self.subpixel_bits {
            robust.profile.subpixel_bits_min = lo;
            robust.profile.subpixel_bits_max = hi;
        }
        if let Some(d) = self.depth_at {
            robust.profile.depth_at = d;
        }
        Ok(robust)
    }
}

/// The default recording size as `--size` spells it (`512x512`: [`RecordSettings::DEFAULT_SIZE`]),
/// for a command line's default value.
pub fn default_size() -> &'static str {
    static SIZE: OnceLock<String> = OnceLock::new();
    SIZE.get_or_init(|| {
        let (w, h) = RecordSettings::DEFAULT_SIZE;
        format!("{w}x{h}")
    })
}
