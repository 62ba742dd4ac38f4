//! Generated paths around the scene's bounding sphere: `orbit:` and `dolly:` (parameters in
//! the crate root's documentation).

use glam::{DMat4, DVec3};
use trisort_format::{Camera, FrameState};

use crate::error::Problem;
use crate::keyframes::MAX_FRAMES;
use crate::view::{default_clip, look_at, Bounds, DEFAULT_YFOV_DEGREES};

/// Parameters of an orbit: the camera circles the bounding-box centre about the world +Y axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Orbit {
    /// Number of frames, ≥ 1.
    pub frames: usize,
    /// Total azimuth swept, degrees (positive: from +Z towards +X).
    pub degrees: f64,
    /// Elevation above the horizontal plane through the centre, degrees, in (−90, 90).
    pub elevation: f64,
    /// Distance from the centre in bounding radii, > 0.
    pub distance: f64,
    /// Vertical field of view, degrees, in (0, 180).
    pub fov: f64,
    /// Azimuth of frame 0, degrees (0: the eye on the centre's +Z side).
    pub start: f64,
}

impl Default for Orbit {
    fn default() -> Self {
        Orbit {
            frames: 48,
            degrees: 360.0,
            elevation: 20.0,
            distance: 2.75,
            fov: DEFAULT_YFOV_DEGREES,
            start: 0.0,
        }
    }
}

impl Orbit {
    /// The eye position of frame `i`. A sweep of a whole number of turns places the frames
    /// at `i / frames` of it (the loop closes without repeating frame 0); any other sweep at
    /// `i / (frames − 1)` (the last frame ends the sweep).
    pub(crate) fn eye(&self, bounds: &Bounds, i: usize) -> DVec3 {
        let turns = self.degrees / 360.0;
        let whole_turns = self.degrees != 0.0 && turns == turns.round();
        let fraction = if whole_turns {
            i as f64 / self.frames as f64
        } else if self.frames > 1 {
            i as f64 / (self.frames - 1) as f64
        } else {
            0.0
        };
        let az = (self.start + self.degrees * fraction).to_radians();
        let el = self.elevation.to_radians();
        let dir = DVec3::new(az.sin() * el.cos(), el.sin(), az.cos() * el.cos());
        bounds.centre + dir * (self.distance * bounds.radius)
    }

    /// The frames of the orbit, looking at the centre with +Y up; clip planes from the
    /// bounds ([`default_clip`]). Requires parameters checked by [`parse_orbit`].
    pub(crate) fn frames(&self, bounds: &Bounds) -> Result<Vec<FrameState>, Problem> {
        let eyes: Vec<DVec3> = (0..self.frames).map(|i| self.eye(bounds, i)).collect();
        cameras(bounds, &eyes, self.fov)
    }
}

/// Parameters of a dolly: the eye moves on a straight line, looking at the bounding-box
/// centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Dolly {
    /// Number of frames, ≥ 1.
    pub frames: usize,
    /// Eye at frame 0 (world space); by default centre + (0, 0.25, 3) × radius.
    pub from: Option<DVec3>,
    /// Eye at the last frame; by default centre + (0, 0.1, 1.5) × radius.
    pub to: Option<DVec3>,
    /// Vertical field of view, degrees, in (0, 180).
    pub fov: f64,
}

impl Default for Dolly {
    fn default() -> Self {
        Dolly {
            frames: 48,
            from: None,
            to: None,
            fov: DEFAULT_YFOV_DEGREES,
        }
    }
}

impl Dolly {
    /// The frames of the dolly: frame i's eye at `from + (to − from) · i / (frames − 1)`.
    pub(crate) fn frames(&self, bounds: &Bounds) -> Result<Vec<FrameState>, Problem> {
        let r = bounds.radius;
        let from = self
            .from
            .unwrap_or(bounds.centre + DVec3::new(0.0, 0.25, 3.0) * r);
        let to = self
            .to
            .unwrap_or(bounds.centre + DVec3::new(0.0, 0.1, 1.5) * r);
        let eyes: Vec<DVec3> = (0..self.frames)
            .map(|i| {
                if self.frames == 1 {
                    from
                } else {
                    let s = i as f64 / (self.frames - 1) as f64;
                    (1.0 - s) * from + s * to
                }
            })
            .collect();
        cameras(bounds, &eyes, self.fov)
    }
}

/// One camera per eye, looking at the bounds' centre with +Y up.
fn cameras(bounds: &Bounds, eyes: &[DVec3], fov_degrees: f64) -> Result<Vec<FrameState>, Problem> {
    let (znear, zfar) = default_clip(bounds, eyes.iter().copied());
    eyes.iter()
        .enumerate()
        .map(|(f, &eye)| {
            let view: DMat4 = look_at(eye, bounds.centre, DVec3::Y, f)?;
            Ok(FrameState {
                camera: Camera {
                    view: view.to_cols_array(),
                    yfov: fov_degrees.to_radians(),
                    znear,
                    zfar: Some(zfar),
                },
                poses: Vec::new(),
            })
        })
        .collect()
}

/// `key=value` pairs of a generator spec (after the colon), each key at most once.
pub(crate) fn pairs<'a>(
    params: &'a str,
    known: &[&str],
) -> Result<Vec<(&'a str, &'a str)>, Problem> {
    let mut out: Vec<(&str, &str)> = Vec::new();
    for item in params.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let Some((k, v)) = item.split_once('=') else {
            return Err(Problem::BadParameter {
                name: item.into(),
                reason: "expected name=value".into(),
            });
        };
        let (k, v) = (k.trim(), v.trim());
        if !known.contains(&k) {
            return Err(Problem::BadParameter {
                name: k.into(),
                reason: format!("unknown parameter (known: {})", known.join(", ")),
            });
        }
        if out.iter().any(|(seen, _)| *seen == k) {
            return Err(Problem::BadParameter {
                name: k.into(),
                reason: "given twice".into(),
            });
        }
        out.push((k, v));
    }
    Ok(out)
}

fn number(name: &str, v: &str) -> Result<f64, Problem> {
    let x: f64 = v.parse().map_err(|_| Problem::BadParameter {
        name: name.into(),
        reason: format!("{v:?} is not a number"),
    })?;
    if !x.is_finite() {
        return Err(Problem::NonFinite { what: name.into() });
    }
    Ok(x)
}

fn frame_count(v: &str) -> Result<usize, Problem> {
    let n: u64 = v.parse().map_err(|_| Problem::BadParameter {
        name: "frames".into(),
        reason: format!("{v:?} is not a whole number of frames"),
    })?;
    if n == 0 {
        return Err(Problem::ZeroFrames);
    }
    if n > MAX_FRAMES as u64 {
        return Err(Problem::BadParameter {
            name: "frames".into(),
            reason: format!("more than {MAX_FRAMES} frames"),
        });
    }
    Ok(n as usize)
}

fn fov(v: &str) -> Result<f64, Problem> {
    let x = number("fov", v)?;
    if x <= 0.0 || x >= 180.0 {
        return Err(Problem::FovOutOfRange { degrees: x });
    }
    Ok(x)
}

/// A point written as three numbers separated by `;` or `:` (commas separate parameters).
fn point(name: &str, v: &str) -> Result<DVec3, Problem> {
    let parts: Vec<&str> = v.split([';', ':']).map(str::trim).collect();
    if parts.len() != 3 {
        return Err(Problem::BadParameter {
            name: name.into(),
            reason: format!("{v:?} is not three numbers x;y;z"),
        });
    }
    Ok(DVec3::new(
        number(name, parts[0])?,
        number(name, parts[1])?,
        number(name, parts[2])?,
    ))
}

/// Parses the parameters of `orbit:` (the text after the colon).
pub(crate) fn parse_orbit(params: &str) -> Result<Orbit, Problem> {
    let mut o = Orbit::default();
    let known = ["frames", "degrees", "elevation", "distance", "fov", "start"];
    for (k, v) in pairs(params, &known)? {
        match k {
            "frames" => o.frames = frame_count(v)?,
            "degrees" => o.degrees = number(k, v)?,
            "elevation" => {
                o.elevation = number(k, v)?;
                if o.elevation.abs() >= 90.0 {
                    return Err(Problem::BadParameter {
                        name: k.into(),
                        reason: format!(
                            "{} is outside (−90°, 90°): the view direction would be parallel \
                             to the +Y up vector",
                            o.elevation
                        ),
                    });
                }
            }
            "distance" => {
                o.distance = number(k, v)?;
                if o.distance <= 0.0 {
                    return Err(Problem::BadParameter {
                        name: k.into(),
                        reason: format!("{} must be positive (bounding radii)", o.distance),
                    });
                }
            }
            "fov" => o.fov = fov(v)?,
            "start" => o.start = number(k, v)?,
            _ => unreachable!("pairs() only returns known names"),
        }
    }
    Ok(o)
}

/// Parses the parameters of `dolly:` (the text after the colon).
pub(crate) fn parse_dolly(params: &str) -> Result<Dolly, Problem> {
    let mut d = Dolly::default();
    for (k, v) in pairs(params, &["frames", "from", "to", "fov"])? {
        match k {
            "frames" => d.frames = frame_count(v)?,
            "from" => d.from = Some(point(k, v)?),
            "to" => d.to = Some(point(k, v)?),
            "fov" => d.fov = fov(v)?,
            _ => unreachable!("pairs() only returns known names"),
        }
    }
    Ok(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_parameters_parse_with_defaults() {
        assert_eq!(parse_orbit("").unwrap(), Orbit::default());
        let o =
            parse_orbit("frames=10, degrees=-90,elevation=5,distance=3,fov=30,start=45").unwrap();
        assert_eq!(
            o,
            Orbit {
                frames: 10,
                degrees: -90.0,
                elevation: 5.0,
                distance: 3.0,
                fov: 30.0,
                start: 45.0
            }
        );
    }

    #[test]
    fn orbit_sweep_spacing() {
        let b = Bounds::from_box(DVec3::splat(-1.0), DVec3::splat(1.0));
        let full = Orbit {
            frames: 4,
            elevation: 0.0,
            ..Orbit::default()
        };
        // Whole turn: frames at 0°, 90°, 180°, 270°; frame 1 on +X.
        let e = full.eye(&b, 1);
        assert!((e.normalize() - DVec3::X).length() < 1e-12, "{e:?}");
        let part = Orbit {
            frames: 4,
            degrees: 90.0,
            elevation: 0.0,
            ..Orbit::default()
        };
        // Partial sweep: the last frame ends it.
        let e = part.eye(&b, 3);
        assert!((e.normalize() - DVec3::X).length() < 1e-12, "{e:?}");
    }

    #[test]
    fn points_accept_semicolons_and_colons() {
        assert_eq!(
            point("from", "1;-2.5;3").unwrap(),
            DVec3::new(1.0, -2.5, 3.0)
        );
        assert_eq!(point("from", "1:2:3").unwrap(), DVec3::new(1.0, 2.0, 3.0));
        assert!(point("from", "1;2").is_err());
        assert!(matches!(
            point("from", "1;nan;2"),
            Err(Problem::NonFinite { .. })
        ));
    }
}
