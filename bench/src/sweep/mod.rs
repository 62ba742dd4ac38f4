//! The speed/accuracy sweep (`trisort bench SCENE --path P --sweep --out DIR`): one factor at
//! a time around the defaults, each point baked, played and compared with the exact reference
//! at the playback settings.
//!
//! Factors and the values tried (the default is the configuration's value, added where it is
//! not among them):
//!
//! | factor | values | what is redone |
//! |---|---|---|
//! | `record-size` | 0.5×, 1×, 2× the playback size | record + merge |
//! | `samples` | 1, 4 (recorded; played at the playback count) | record + merge |
//! | `saturation` | 0.99, 0.998, 1.0 | record + merge |
//! | `glass-opacity` | 0, 0.3, 0.6 (recorded, played and referenced at it) | record + merge |
//! | `bridge` | hidden, ignored | merge |
//! | `strategy-layout` | auto, and lib lbi ilb ibl bli bil × paper compact | merge |
//! | `segment` | none, 64, 16, 4 | merge |
//! | `robust` | 1, 2, 4, 8 sample patterns; conservative, conservative + 4 patterns (`record --robust N`, `--conservative`) | record + merge |
//!
//! The `robust` factor's points are also played off their recorded pattern
//! ([`robustness`]: the projection shifted by 1/16, 1/8 and 1/4 px, and 1.5× and 2× the
//! size), their error split into holes and order errors: `sweep-robust.csv` and
//! `sweep-holes-vs-triangles.svg`.
//!
//! Every point with the default recording shares it; identical bakes (the default point of
//! every factor) are baked and played once. `bake_seconds` is what it costs to get the point
//! from what the factor cannot reuse: record + merge for the recording factors, the merge
//! alone for the merge factors (`bake_includes_record` says which); `record_seconds` and
//! `merge_seconds` are always both reported.
//!
//! Error is measured against [`ExactReference`](trisort_reference::ExactReference) at the
//! playback size and samples in `blend` mode with the point's glass opacity; reference frames
//! are rendered once per glass opacity.
//! Pixels at unordered samples (cycles the merger broke) count as differing like any other:
//! this is the error a user sees.
//!
//! Outputs in the output folder, each written atomically: `sweep.csv`, `sweep.json`,
//! `sweep-error-vs-bake-time.svg`, `sweep-error-vs-baked-size.svg`,
//! `sweep-draws-along-path.svg`.
//!
//! | file | what |
//! |---|---|
//! | `factors.rs` | the factors, their values and the variants to bake |
//! | `run.rs` | the sweep itself: recordings, references, merges |
//! | `measurement.rs` | one bake's size, play time and error |
//! | `robustness.rs` | the robust factor's error off the recorded pattern |
//! | `output.rs` | CSV, JSON and the plots |

mod factors;
mod measurement;
mod output;
pub mod robustness;
mod run;

use serde::Serialize;
use trisort_format::RecordSettings;

pub use factors::Factor;
pub use output::{robust_csv, to_csv, CSV_COLUMNS, ROBUST_CSV_COLUMNS};
pub use run::run;

/// Timed renders of each compared frame per point (after one untimed warm-up render of each);
/// a frame's time is their median.
pub const PLAY_REPEATS: u32 = 5;

/// The sweep's defaults and playback settings.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepConfig {
    /// Playback size (width, height); also the default recording size.
    pub size: (u32, u32),
    /// Playback MSAA samples (1 or 4); also the default recorded count.
    pub samples: u32,
    /// Default saturation threshold.
    pub saturation: f32,
    /// Default glass opacity.
    pub glass_opacity: f32,
    /// Frames to play and compare (every bake covers the whole path); empty: every frame.
    pub frames: Vec<u32>,
    /// Factors to run; empty: every factor.
    pub factors: Vec<Factor>,
}

impl SweepConfig {
    /// The CLI's defaults at playback `size` and `samples`: the recording defaults of
    /// [`RecordSettings`] (saturation, glass opacity), every frame, every factor.
    pub fn new(size: (u32, u32), samples: u32) -> SweepConfig {
        let defaults = RecordSettings::default();
        SweepConfig {
            size,
            samples,
            saturation: defaults.saturation,
            glass_opacity: defaults.glass_opacity,
            frames: Vec::new(),
            factors: Factor::ALL.to_vec(),
        }
    }

    /// The default point's recording settings: the playback size and samples, the
    /// configuration's saturation and glass opacity, the default layer bound.
    fn base_settings(&self) -> RecordSettings {
        RecordSettings {
            saturation: self.saturation,
            // + 0.0: −0 is 0 here, so that it matches the listed value 0 bit for bit.
            glass_opacity: self.glass_opacity + 0.0,
            ..RecordSettings::new(self.size, self.samples)
        }
    }
}

/// One point of the sweep.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepPoint {
    /// The factor varied ([`Factor::name`]).
    pub factor: String,
    /// Its value here (e.g. `0.5x (128x128)`, `lib/paper`, `none`).
    pub value: String,
    /// Whether this is the default configuration (the same bake under every factor).
    pub is_default: bool,
    /// Wall time of the recording this point's bake was merged from, seconds.
    pub record_seconds: f64,
    /// Wall time of the merge, seconds.
    pub merge_seconds: f64,
    /// Cost of the point: record + merge for the recording factors, merge only for the others.
    pub bake_seconds: f64,
    /// Whether `bake_seconds` includes the recording.
    pub bake_includes_record: bool,
    /// Size of the baked file (the exact bytes `trisort merge` writes).
    pub baked_bytes: u64,
    /// Triangles in the index buffer (copies).
    pub index_triangles: u64,
    /// |G|: triangles visible at least once.
    pub unique_visible: u64,
    /// Weight of the intra-frame cycle edges the merger removed (samples whose order it
    /// could not keep).
    pub unordered_samples: u64,
    /// Mean over frames of triangles drawn but not visible.
    pub drawn_not_visible_mean: f64,
    /// Mean indirect draws per frame over the path.
    pub draws_per_frame_mean: f64,
    /// Most indirect draws in one frame.
    pub draws_per_frame_max: u32,
    /// Mean over the compared frames of a frame's GPU time (timestamp queries; the median of
    /// [`PLAY_REPEATS`] renders), ms; NaN (null in JSON) where the device has no timestamps.
    pub play_ms_mean: f64,
    /// Largest frame GPU time (each the median of its repeats), ms (NaN without timestamps).
    pub play_ms_max: f64,
    /// Mean wall time of a played frame (submit, wait, read back; median of its repeats), ms.
    pub wall_ms_mean: f64,
    /// Pixels differing from the reference, summed over the compared frames.
    pub pixels_differing: u64,
    /// `pixels_differing` ÷ (compared frames × pixels).
    pub pixels_differing_fraction: f64,
    /// Largest colour-channel difference over the compared frames, 1/255 units.
    pub max_channel_diff: u8,
    /// Mean LDR-FLIP over the compared frames (0 identical).
    pub flip_mean: f64,
    /// Σ|V_f| ÷ frames: triangles the frame's own visible set holds (the bake draws at least
    /// these).
    pub source_triangles_per_frame: f64,
    /// The `robust` factor's points: the error played off the recorded pattern, per
    /// condition ([`robustness`]); empty for the other factors.
    pub robustness: Vec<robustness::ConditionError>,
}

/// The sweep's results.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepReport {
    /// The device ([`Gpu::describe`](trisort_gpu::Gpu::describe)).
    pub device: String,
    /// Playback size.
    pub size: (u32, u32),
    /// Playback samples.
    pub samples: u32,
    /// Frames compared.
    pub frames: Vec<u32>,
    /// Frames of the path.
    pub path_frames: u32,
    /// Triangles of the scene.
    pub scene_triangles: u64,
    /// Strategy and layout the default (`auto`) merge chose.
    pub default_merge: String,
    /// The points, factor by factor in the order run, values in the order listed above.
    pub points: Vec<SweepPoint>,
    /// Draws per frame along the path of the default bake: (frame, draws).
    pub draws_along_path: Vec<(u32, u32)>,
}
