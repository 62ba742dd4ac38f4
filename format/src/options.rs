//! The merge options a bake is made with, as types: [`Strategy`], [`Layout`], [`Bridge`] and
//! [`Seeding`], and [`Choice`] (one value, or `auto` to try them all). [`crate::MergeInfo`]
//! stores them, and the merger, the validator, the benchmarks and the CLI all speak these
//! types, so each list of values, each name and each default is written once, here.
//!
//! Text form ([`Display`](fmt::Display), [`FromStr`], [`OptionValue::name`]): the CLI's
//! lower-case spelling (`lib`, `compact`, `visible`, `interval`), which is also the value of
//! the `--json` keys. Serde form: the same name in self-describing formats (JSON); in the
//! container's postcard payload, the variant's index, so reordering or removing a variant
//! changes the file format (bump [`crate::FORMAT_VERSION`]); adding one at the end does too
//! for readers that do not know it.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// A typed option with a fixed list of named values (implemented by [`Strategy`], [`Layout`],
/// [`Bridge`] and [`Seeding`]): what generic code (the CLI's value parsers, [`Choice`]) needs.
pub trait OptionValue: Copy + Eq + fmt::Debug + Send + Sync + 'static {
    /// What the option is called in messages (`strategy`).
    const WHAT: &'static str;
    /// Every value, in the fixed order every list uses (and `auto` tries).
    const ALL: &'static [Self];
    /// The value's name on the command line and in `--json` (`lib`).
    fn name(self) -> &'static str;
    /// One line describing the value (the CLI's help for it).
    fn help(self) -> &'static str;
}

/// A name that is not among an option's values.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} `{found}` (expected {expected})")]
pub struct ParseOptionError {
    /// The option ([`OptionValue::WHAT`]).
    pub what: &'static str,
    /// The name given.
    pub found: String,
    /// The names accepted, as a phrase (`lib, lbi or auto`).
    pub expected: String,
}

impl ParseOptionError {
    pub(crate) fn new<'a>(
        what: &'static str,
        found: &str,
        names: impl IntoIterator<Item = &'a str>,
    ) -> Self {
        let names: Vec<&str> = names.into_iter().collect();
        let expected = match names.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => names.join(""),
        };
        ParseOptionError {
            what,
            found: found.to_string(),
            expected,
        }
    }
}

/// Defines an option enum from one table of `Variant = "name", "help"` rows: the enum (with
/// serde names equal to the CLI names), its inherent `ALL`, `name` and `help`, and its
/// [`OptionValue`], [`fmt::Display`] and [`FromStr`] implementations.
macro_rules! option_enum {
    (
        $(#[$meta:meta])*
        pub enum $ty:ident: $what:literal {
            $(
                $(#[$vmeta:meta])*
                $var:ident = $name:literal, $help:literal;
            )+
        }
    ) => {
        $(#[$meta])*
        #[derive(
            Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize,
            Deserialize,
        )]
        pub enum $ty {
            $(
                $(#[$vmeta])*
                #[serde(rename = $name)]
                $var,
            )+
        }

        impl $ty {
            /// Every value, in the fixed order every list uses.
            pub const ALL: [$ty; [$(stringify!($var)),+].len()] = [$($ty::$var),+];

            /// The CLI's name of the value (also its `--json` value).
            pub fn name(self) -> &'static str {
                match self {
                    $($ty::$var => $name,)+
                }
            }

            /// One line describing the value (the CLI's help for it).
            pub fn help(self) -> &'static str {
                match self {
                    $($ty::$var => $help,)+
                }
            }
        }

        impl OptionValue for $ty {
            const WHAT: &'static str = $what;
            const ALL: &'static [$ty] = &$ty::ALL;
            fn name(self) -> &'static str {
                $ty::name(self)
            }
            fn help(self) -> &'static str {
                $ty::help(self)
            }
        }

        impl fmt::Display for $ty {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }

        impl FromStr for $ty {
            type Err = ParseOptionError;
            fn from_str(s: &str) -> Result<$ty, ParseOptionError> {
                $ty::ALL
                    .iter()
                    .copied()
                    .find(|v| v.name() == s)
                    .ok_or_else(|| {
                        ParseOptionError::new($what, s, $ty::ALL.iter().map(|v| v.name()))
                    })
            }
        }
    };
}

pub(crate) use option_enum;

option_enum! {
    /// The order of L = (i, j−1), I = (i, j) and B = (i+1, j) in every window (paper §5.1).
    /// Every order gives a valid index buffer, but of another size, so the merge's default,
    /// [`Choice::Auto`], tries them all; the default here (`Lib`, the first) only fills a
    /// [`crate::MergeInfo::default`].
    pub enum Strategy: "strategy" {
        /// L, then I, then B: rows top to bottom, each row left to right.
        #[default]
        Lib = "lib", "Left, intersection, bottom";
        /// L, then B, then I.
        Lbi = "lbi", "Left, bottom, intersection";
        /// I, then L, then B: the corner (longest-lived) cells first.
        Ilb = "ilb", "Intersection, left, bottom";
        /// I, then B, then L.
        Ibl = "ibl", "Intersection, bottom, left";
        /// B, then L, then I.
        Bli = "bli", "Bottom, left, intersection";
        /// B, then I, then L: the exact reverse of LIB.
        Bil = "bil", "Bottom, intersection, left";
    }
}

option_enum! {
    /// How the matrix's cells are linearized into the index buffer. The default (`Paper`, the
    /// first) only fills a [`crate::MergeInfo::default`]; the merge's default is
    /// [`Choice::Auto`].
    pub enum Layout: "layout" {
        /// The paper's: row-wise for LIB and BIL, by diagonals for the other four (a window
        /// then needs up to F ranges).
        #[default]
        Paper = "paper", "The paper's layout (rows for LIB/BIL, diagonals otherwise)";
        /// Rows or columns chosen so that frame f's window needs at most max(f+1, F−f)
        /// ranges: LIB column-major; ILB rows with j descending; BLI rows descending, j
        /// ascending; IBL columns descending; LBI columns ascending, i descending; BIL columns
        /// descending, i descending.
        Compact = "compact", "The compact layout (at most max(f+1, F−f) ranges per frame)";
    }
}

option_enum! {
    /// Where a copy may span frames in which its triangle is not visible (the validator's
    /// rule 2, `trisort_verify`).
    ///
    /// A copy always starts and ends at frames where its triangle is visible; this decides
    /// what the frames between may be.
    pub enum Bridge: "bridge" {
        /// Any frame where the triangle is not visible: covered but hidden (t ∈ C_f \ V_f,
        /// costs fill, and the copy is then ordered there like any drawn triangle), or with no
        /// fragment at all (t ∉ C_f, the ignore list: drawing it changes nothing).
        Hidden = "hidden",
            "Copies may span frames where the triangle is covered but hidden (or has no fragment)";
        /// Only frames where the triangle has no fragment (t ∉ C_f): drawing it changes nothing
        /// and costs no fill.
        Ignored = "ignored", "Copies may span only frames where the triangle has no fragment";
        /// None: a copy spans only frames where its triangle is visible, so every frame draws
        /// exactly its V_f (no drawn-not-visible triangle, the `source` lower bound in
        /// triangles) at the price of more copies. The default: drawing fewer triangles per frame
        /// outweighs the extra copies (on the demo car, merged / source frame time 1.06 against
        /// 1.31 for `hidden`, for 26 % more copies; BENCHMARKS.md).
        #[default]
        Visible = "visible",
            "Copies span only frames where the triangle is visible: every frame draws exactly \
             its visible set (fewest triangles per frame), at the price of more copies";
    }
}

option_enum! {
    /// How the matrix is seeded before interval splitting makes it valid.
    pub enum Seeding: "seeding" {
        /// One copy per maximal bridgeable run of a triangle's visible frames (the
        /// specification).
        #[default]
        Interval = "interval", "Interval splitting (the specification)";
        /// The paper's diagonal-by-diagonal merge of adjacent cells (§3.2, Figures 4 and 12),
        /// with copies trimmed so rule 1 holds; interval splitting then repairs what it misses.
        Paper = "paper", "The paper's diagonal-by-diagonal merge";
    }
}

option_enum! {
    /// How a baked frame is composited (see the player's crate documentation for the
    /// equations): `play`, `verify` and `bench --mode`.
    pub enum Mode: "mode" {
        /// Back to front, *over*, no depth test.
        #[default]
        Blend = "blend", "Back to front, over, no depth test";
        /// Front to back with the depth test (`Less`, depth writes) and *over*.
        Depth = "depth", "Front to back with the depth test";
        /// Front to back, *under* on a target cleared to alpha 0, no depth test.
        Saturate = "saturate", "Front to back, under, no depth test";
    }
}

impl Mode {
    /// Whether the mode plays the stored order reversed (back to front).
    pub fn back_to_front(self) -> bool {
        self == Mode::Blend
    }
}

option_enum! {
    /// The surface model the shaders light with (`--shading`).
    pub enum Shading: "shading" {
        /// One view-space directional light plus ambient, plus the emissive factor, no tone
        /// map: what trisort drew before physically based shading (the C host draws this).
        Basic = "basic", "one light plus ambient, no tone map (what the C host draws)";
        /// glTF metallic-roughness with normal, occlusion, emissive maps and clearcoat, lit by
        /// the baked file's environment and sun, exposed and tone mapped.
        #[default]
        Pbr = "pbr", "glTF metallic-roughness lit by the baked file's environment, tone mapped";
    }
}

option_enum! {
    /// The tone mapping of [`Shading::Pbr`] (after exposure, before blending; `--tonemap`).
    pub enum ToneMap: "tone map" {
        /// Khronos PBR Neutral.
        #[default]
        Neutral = "neutral", "Khronos PBR Neutral";
        /// ACES filmic (Narkowicz's fit).
        Aces = "aces", "ACES filmic (Narkowicz's fit)";
    }
}

option_enum! {
    /// Which GPU backend a device is opened on (`--backend`).
    pub enum DeviceBackend: "backend" {
        /// wgpu's choice (`WGPU_BACKEND` where set).
        #[default]
        Auto = "auto", "wgpu's choice (WGPU_BACKEND where set)";
        /// Vulkan only.
        Vulkan = "vulkan", "Vulkan only";
        /// OpenGL / GLES only (EGL headless on Linux).
        Gl = "gl", "OpenGL/GLES only (headless through EGL)";
    }
}

option_enum! {
    /// The limits a device is opened with (`--limits`).
    pub enum DeviceLimits: "limits" {
        /// The adapter's own limits.
        #[default]
        Adapter = "default", "The adapter's own limits";
        /// WebGL2's (`wgpu::Limits::downlevel_webgl2_defaults`, at the adapter's texture
        /// sizes): no storage buffers, 16 KiB uniform bindings. The player then takes its
        /// WebGL2 path (data-texture bindings, direct draws) on any adapter.
        Webgl2 = "webgl2", "WebGL2's limits: the player's GLES 3.0 / WebGL2 path";
    }
}

/// An option whose values the merger can also try all of ([`Choice::Auto`]): [`Strategy`]
/// and [`Layout`].
pub trait Choosable: OptionValue {
    /// One line describing `auto` for this option (the CLI's help for it).
    const AUTO_HELP: &'static str;
}

impl Choosable for Strategy {
    const AUTO_HELP: &'static str =
        "Try all, keep the best (index triangles, then worst-frame draws), on the first segment where the path has several";
}

impl Choosable for Layout {
    const AUTO_HELP: &'static str = "Try both";
}

/// One value of an option, or `auto`: every value, the best kept by the merger's objective
/// (fewest index triangles, then fewest draws in the worst frame). Its text form is the
/// value's name or `auto`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Choice<T> {
    /// Every value of [`OptionValue::ALL`]; the best by the merger's objective.
    #[default]
    Auto,
    /// This value only.
    Only(T),
}

impl<T: Choosable> Choice<T> {
    /// The values this choice tries, in [`OptionValue::ALL`]'s order.
    pub fn candidates(self) -> Vec<T> {
        match self {
            Choice::Auto => T::ALL.to_vec(),
            Choice::Only(v) => vec![v],
        }
    }

    /// Every choice, as the CLI lists them: each value, then `auto`.
    pub fn all() -> Vec<Choice<T>> {
        T::ALL
            .iter()
            .map(|&v| Choice::Only(v))
            .chain([Choice::Auto])
            .collect()
    }

    /// `auto` or the value's name.
    pub fn name(self) -> &'static str {
        match self {
            Choice::Auto => "auto",
            Choice::Only(v) => v.name(),
        }
    }

    /// One line describing the choice (the CLI's help for it).
    pub fn help(self) -> &'static str {
        match self {
            Choice::Auto => T::AUTO_HELP,
            Choice::Only(v) => v.help(),
        }
    }
}

impl<T: Choosable> fmt::Display for Choice<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl<T: Choosable> FromStr for Choice<T> {
    type Err = ParseOptionError;
    fn from_str(s: &str) -> Result<Choice<T>, ParseOptionError> {
        Choice::<T>::all()
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| {
                ParseOptionError::new(T::WHAT, s, Choice::<T>::all().iter().map(|c| c.name()))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip<T>()
    where
        T: OptionValue + FromStr<Err = ParseOptionError> + fmt::Display + Serialize,
    {
        for &v in T::ALL {
            assert_eq!(v.name().parse::<T>().unwrap(), v);
            assert_eq!(v.to_string(), v.name());
            assert_eq!(
                serde_json::to_value(v).unwrap(),
                serde_json::json!(v.name())
            );
        }
        let e = "nonsense".parse::<T>().unwrap_err().to_string();
        assert!(e.contains(T::WHAT) && e.contains("nonsense"), "{e}");
    }

    fn choices_round_trip<T: Choosable>() {
        for c in Choice::<T>::all() {
            assert_eq!(c.name().parse::<Choice<T>>().unwrap(), c);
            assert_eq!(c.to_string(), c.name());
        }
    }

    #[test]
    fn names_are_the_cli_spellings() {
        round_trip::<Strategy>();
        round_trip::<Layout>();
        round_trip::<Bridge>();
        round_trip::<Seeding>();
        choices_round_trip::<Strategy>();
        choices_round_trip::<Layout>();
        let names = |v: Vec<&str>| v.join("|");
        assert_eq!(
            names(Choice::<Strategy>::all().iter().map(|c| c.name()).collect()),
            "lib|lbi|ilb|ibl|bli|bil|auto"
        );
        assert_eq!(
            names(Choice::<Layout>::all().iter().map(|c| c.name()).collect()),
            "paper|compact|auto"
        );
        assert_eq!(
            names(Bridge::ALL.iter().map(|b| b.name()).collect()),
            "hidden|ignored|visible"
        );
        assert_eq!(
            names(Seeding::ALL.iter().map(|s| s.name()).collect()),
            "interval|paper"
        );
        assert_eq!(
            "best".parse::<Choice<Layout>>().unwrap_err().to_string(),
            "unknown layout `best` (expected paper, compact or auto)"
        );
        assert_eq!(Choice::<Layout>::Auto.help(), "Try both");
        assert!(Choice::<Strategy>::Auto.help().starts_with("Try all"));
    }

    #[test]
    fn serde_uses_the_names_in_json_and_indices_in_postcard() {
        let json =
            serde_json::to_string(&(Strategy::Ilb, Layout::Compact, Bridge::Visible)).unwrap();
        assert_eq!(json, r#"["ilb","compact","visible"]"#);
        let back: (Strategy, Layout, Bridge) = serde_json::from_str(&json).unwrap();
        assert_eq!(back, (Strategy::Ilb, Layout::Compact, Bridge::Visible));
        // One byte each: the variant index.
        let bytes = postcard::to_allocvec(&(Strategy::Bil, Seeding::Paper)).unwrap();
        assert_eq!(bytes, [5, 1]);
    }

    #[test]
    fn auto_tries_every_value_in_order() {
        assert_eq!(
            Choice::<Strategy>::Auto.candidates(),
            Strategy::ALL.to_vec()
        );
        assert_eq!(
            Choice::Only(Layout::Compact).candidates(),
            vec![Layout::Compact]
        );
        assert_eq!(Choice::<Strategy>::default(), Choice::Auto);
        assert_eq!(Bridge::default(), Bridge::Visible);
        assert_eq!(Seeding::default(), Seeding::Interval);
    }
}
