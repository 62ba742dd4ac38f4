//! The factors the sweep varies, their values around the defaults, and the variants (one
//! configuration each) they give.

use std::str::FromStr;

use trisort_format::{ProfileName, RecordSettings, Robust};
use trisort_merger::{Bridge, Choice, Layout, MergeOptions, Strategy};

use super::SweepConfig;
use crate::BenchError;

/// What the sweep varies, one factor at a time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Factor {
    /// Recording size: 0.5×, 1×, 2× the playback size.
    RecordSize,
    /// Recorded MSAA samples: 1, 4.
    Samples,
    /// Saturation threshold: 0.99, 0.998, 1.0.
    Saturation,
    /// Glass opacity: 0, 0.3, 0.6 (recorded, played and referenced at it).
    GlassOpacity,
    /// Bridge policy: hidden, ignored.
    Bridge,
    /// Strategy × layout: auto, and the six strategies × paper, compact.
    StrategyLayout,
    /// Segment length: none, 64, 16, 4.
    Segment,
    /// Robust recording: 1, 2, 4, 8 sample patterns, conservative with 1 and 4; each point
    /// is also played off its pattern ([`super::robustness`]).
    Robust,
}

impl Factor {
    /// Every factor, in the order the sweep runs them.
    pub const ALL: [Factor; 8] = [
        Factor::RecordSize,
        Factor::Samples,
        Factor::Saturation,
        Factor::GlassOpacity,
        Factor::Bridge,
        Factor::StrategyLayout,
        Factor::Segment,
        Factor::Robust,
    ];

    /// The factor's name on the command line and in the outputs (`record-size`, …).
    pub fn name(self) -> &'static str {
        match self {
            Factor::RecordSize => "record-size",
            Factor::Samples => "samples",
            Factor::Saturation => "saturation",
            Factor::GlassOpacity => "glass-opacity",
            Factor::Bridge => "bridge",
            Factor::StrategyLayout => "strategy-layout",
            Factor::Segment => "segment",
            Factor::Robust => "robust",
        }
    }

    /// Whether the factor changes the recording (otherwise only the merge is redone).
    pub fn records(self) -> bool {
        matches!(
            self,
            Factor::RecordSize
                | Factor::Samples
                | Factor::Saturation
                | Factor::GlassOpacity
                | Factor::Robust
        )
    }

    /// Parses a comma-separated list of factor names; `all` (or an empty string) gives every
    /// factor. Duplicates are dropped; the sweep runs them in [`Factor::ALL`]'s order.
    pub fn parse_list(list: &str) -> Result<Vec<Factor>, BenchError> {
        let mut out = Vec::new();
        for word in list.split(',').map(str::trim).filter(|w| !w.is_empty()) {
            if word == "all" {
                return Ok(Factor::ALL.to_vec());
            }
            let f: Factor = word.parse()?;
            if !out.contains(&f) {
                out.push(f);
            }
        }
        if out.is_empty() {
            return Ok(Factor::ALL.to_vec());
        }
        out.sort_by_key(|f| Factor::ALL.iter().position(|a| a == f));
        Ok(out)
    }
}

impl FromStr for Factor {
    type Err = BenchError;
    fn from_str(s: &str) -> Result<Factor, BenchError> {
        Factor::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Factor::ALL.iter().map(|f| f.name()).collect();
                BenchError::Invalid(format!(
                    "unknown sweep factor `{s}` (expected {} or all)",
                    names.join(", ")
                ))
            })
    }
}

impl std::fmt::Display for Factor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One configuration to bake and measure.
#[derive(Clone, Debug)]
pub(super) struct Variant {
    pub(super) factor: Factor,
    pub(super) value: String,
    pub(super) settings: RecordSettings,
    pub(super) merge: MergeOptions,
}

type SettingsKey = (
    u32,
    u32,
    u32,
    u32,
    u32,
    u32,
    (u32, u32, bool, trisort_format::RasterProfile),
);

fn settings_key(s: &RecordSettings) -> SettingsKey {
    (
        s.width,
        s.height,
        s.samples,
        s.saturation.to_bits(),
        s.glass_opacity.to_bits(),
        s.max_layers,
        (
            s.robust.patterns,
            s.robust.tolerance.to_bits(),
            s.robust.conservative,
            s.robust.profile,
        ),
    )
}

/// A robust setting as the sweep names it (`1`, `4`: patterns; `conformant`, `browser+4`: a
/// conservative raster profile, with patterns beyond the first).
pub(super) fn robust_name(r: &Robust) -> String {
    match (r.conservative, r.patterns) {
        (false, n) => n.to_string(),
        (true, 1) => r.profile.name.to_string(),
        (true, n) => format!("{}+{n}", r.profile.name),
    }
}

pub(super) fn same_settings(a: &RecordSettings, b: &RecordSettings) -> bool {
    settings_key(a) == settings_key(b)
}

/// A float as the sweep names it (`0.998`, `1`, `0.3`).
pub(super) fn number(v: f32) -> String {
    let s = format!("{v}");
    if s.contains('.') {
        s
    } else {
        format!("{s}.0")
    }
}

/// `values` with `default` added (at its sorted place) when it is not among them.
fn with_default(mut values: Vec<f32>, default: f32) -> Vec<f32> {
    if !values.contains(&default) {
        values.push(default);
        values.sort_by(f32::total_cmp);
    }
    values
}

pub(super) fn variants(config: &SweepConfig, base: RecordSettings) -> Vec<Variant> {
    let merge = MergeOptions::default();
    let factors: Vec<Factor> = if config.factors.is_empty() {
        Factor::ALL.to_vec()
    } else {
        Factor::ALL
            .into_iter()
            .filter(|f| config.factors.contains(f))
            .collect()
    };
    let mut out = Vec::new();
    for factor in factors {
        let v = |value: String, settings: RecordSettings, merge: MergeOptions| Variant {
            factor,
            value,
            settings,
            merge,
        };
        match factor {
            Factor::RecordSize => {
                for (k, name) in [(0.5, "0.5x"), (1.0, "1x"), (2.0, "2x")] {
                    let w = ((base.width as f64 * k).round() as u32).max(1);
                    let h = ((base.height as f64 * k).round() as u32).max(1);
                    let s = RecordSettings {
                        width: w,
                        height: h,
                        ..base
                    };
                    out.push(v(format!("{name} ({w}x{h})"), s, merge));
                }
            }
            Factor::Samples => {
                let mut counts = vec![1, 4];
                if !counts.contains(&base.samples) {
                    counts.push(base.samples);
                    counts.sort();
                }
                for n in counts {
                    let s = RecordSettings { samples: n, ..base };
                    out.push(v(format!("{n}"), s, merge));
                }
            }
            Factor::Saturation => {
                let values = vec![0.99, RecordSettings::DEFAULT_SATURATION, 1.0];
                for x in with_default(values, base.saturation) {
                    let s = RecordSettings {
                        saturation: x,
                        ..base
                    };
                    out.push(v(number(x), s, merge));
                }
            }
            Factor::GlassOpacity => {
                for x in with_default(vec![0.0, 0.3, 0.6], base.glass_opacity) {
                    let s = RecordSettings {
                        glass_opacity: x,
                        ..base
                    };
                    out.push(v(number(x), s, merge));
                }
            }
            Factor::Bridge => {
                for b in Bridge::ALL {
                    let m = MergeOptions { bridge: b, ..merge };
                    out.push(v(b.to_string(), base, m));
                }
            }
            Factor::StrategyLayout => {
                let auto = format!("{}/{}", merge.strategy, merge.layout);
                out.push(v(auto, base, merge));
                for s in Strategy::ALL {
                    for l in Layout::ALL {
                        let m = MergeOptions {
                            strategy: Choice::Only(s),
                            layout: Choice::Only(l),
                            ..merge
                        };
                        out.push(v(format!("{s}/{l}"), base, m));
                    }
                }
            }
            Factor::Robust => {
                // The recorded pattern unioned with up to 7 jittered ones (±1/8 px), then the
                // conformant profile (the default) and the widest, `browser` (±1/8 px), alone and
                // with 4 patterns.
                let mut values: Vec<Robust> = [1, 2, 4, 8]
                    .into_iter()
                    .map(|patterns| Robust {
                        patterns,
                        ..Robust::OFF
                    })
                    .collect();
                values.push(Robust::DEFAULT);
                for patterns in [1, 4] {
                    values.push(Robust {
                        patterns,
                        ..Robust::profile_named(ProfileName::Browser)
                    });
                }
                if !values.contains(&base.robust) {
                    values.push(base.robust);
                }
                for r in values {
                    let s = RecordSettings { robust: r, ..base };
                    out.push(v(robust_name(&r), s, merge));
                }
            }
            Factor::Segment => {
                let default = Some(MergeOptions::DEFAULT_SEGMENT);
                for seg in [None, default, Some(16), Some(4)] {
                    let m = MergeOptions {
                        segment: seg,
                        ..merge
                    };
                    let name = seg.map_or("none".to_string(), |n| n.to_string());
                    out.push(v(name, base, m));
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_parse_and_name() {
        for f in Factor::ALL {
            assert_eq!(f.name().parse::<Factor>().unwrap(), f);
        }
        assert_eq!(Factor::parse_list("all").unwrap(), Factor::ALL.to_vec());
        assert_eq!(Factor::parse_list("").unwrap(), Factor::ALL.to_vec());
        assert_eq!(
            Factor::parse_list("segment, bridge,segment").unwrap(),
            vec![Factor::Bridge, Factor::Segment]
        );
        let e = Factor::parse_list("bridge,colour").unwrap_err().to_string();
        assert!(e.contains("colour") && e.contains("record-size"), "{e}");
    }

    #[test]
    fn variants_cover_every_value_around_the_defaults() {
        let config = SweepConfig::new((256, 128), 4);
        let base = RecordSettings::new((256, 128), 4);
        let v = variants(&config, base);
        let count = |f: Factor| v.iter().filter(|x| x.factor == f).count();
        assert_eq!(count(Factor::RecordSize), 3);
        assert_eq!(count(Factor::Samples), 2);
        assert_eq!(count(Factor::Saturation), 3);
        assert_eq!(count(Factor::GlassOpacity), 3);
        assert_eq!(count(Factor::Bridge), 3);
        assert_eq!(count(Factor::StrategyLayout), 13);
        assert_eq!(count(Factor::Segment), 4);
        assert_eq!(count(Factor::Robust), 7);
        let robust: Vec<_> = v
            .iter()
            .filter(|x| x.factor == Factor::Robust)
            .map(|x| x.value.as_str())
            .collect();
        assert_eq!(
            robust,
            ["1", "2", "4", "8", "conformant", "browser", "browser+4"]
        );
        // Each factor has exactly one default point, and it is the same bake.
        for f in Factor::ALL {
            let defaults = v
                .iter()
                .filter(|x| {
                    x.factor == f
                        && same_settings(&x.settings, &base)
                        && x.merge == MergeOptions::default()
                })
                .count();
            assert_eq!(defaults, 1, "{f}");
        }
        let sizes: Vec<_> = v
            .iter()
            .filter(|x| x.factor == Factor::RecordSize)
            .map(|x| (x.settings.width, x.settings.height))
            .collect();
        assert_eq!(sizes, vec![(128, 64), (256, 128), (512, 256)]);
        // Merge factors reuse the default recording.
        assert!(v
            .iter()
            .filter(|x| !x.factor.records())
            .all(|x| same_settings(&x.settings, &base)));
        // A default outside the listed values is added.
        let odd = SweepConfig {
            saturation: 0.95,
            glass_opacity: 0.1,
            factors: vec![Factor::Saturation, Factor::GlassOpacity],
            ..config
        };
        let v = variants(
            &odd,
            RecordSettings {
                saturation: 0.95,
                glass_opacity: 0.1,
                ..base
            },
        );
        let values: Vec<_> = v.iter().map(|x| x.value.as_str()).collect();
        assert_eq!(
            values,
            ["0.95", "0.99", "0.998", "1.0", "0.0", "0.1", "0.3", "0.6"]
        );
    }
}
