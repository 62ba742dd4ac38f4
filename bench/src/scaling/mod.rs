//! Scaling of the bake cost: record and merge cost against the scene's
//! triangle count (the procedural demo car, 10 k … 5 M triangles) and against the path's
//! frame count (real recordings of the demo car along an orbit, 10 … 1,000 frames, each merged
//! as one matrix and again in segments; synthetic recordings of
//! `trisort_merger::synth::turntable` up to 10,000 frames, merged in segments).
//!
//! Every run is one [`ScalingRow`]; [`write_outputs`] writes them as CSV and JSON (with the
//! growth exponent of each series: the least-squares slope in log-log) and draws the growth
//! as SVG plots. Times are wall times (`std::time::Instant`) of the recorder's and the
//! merger's library calls alone: generating the scene, hashing it and building the path are
//! not counted, nor is writing files (nothing is written during a run).

use std::time::Instant;

use serde::Serialize;
use trisort_bake::{record_in_memory, RecordTarget};
use trisort_format::{Phase, RecordSettings, Recording};
use trisort_gpu::Gpu;
use trisort_merger::synth::{split_frames, turntable, Turntable};
use trisort_merger::MergeOptions;

use crate::BenchError;

/// Axis name of the triangle-count runs.
pub const AXIS_TRIANGLES: &str = "triangles";
/// Axis name of the real-frame runs.
pub const AXIS_FRAMES: &str = "frames";
/// Axis name of the real-frame runs merged again in segments of [`ScalingConfig::segment`]
/// frames (the same recordings: record times repeat those of [`AXIS_FRAMES`]).
pub const AXIS_FRAMES_SEGMENTED: &str = "frames-segmented";
/// Axis name of the synthetic long-path runs.
pub const AXIS_SYNTHETIC: &str = "synthetic-frames";

/// What to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalingConfig {
    /// Recording size in pixels (width, height), for both real-frame axes.
    pub size: (u32, u32),
    /// Samples per pixel of the recording (1 or 4).
    pub samples: u32,
    /// Demo-car triangle counts of the triangle axis (the car has *about* this many; the rows
    /// give the exact count).
    pub triangle_counts: Vec<u32>,
    /// Frame counts of the real-frame axis.
    pub frame_counts: Vec<u32>,
    /// Frame counts of the synthetic axis (no GPU), e.g. 10,000.
    pub synthetic_frames: Vec<u32>,
    /// Segment length (`--segment`) of the synthetic long paths, and of the second merge of
    /// every real-frame recording ([`AXIS_FRAMES_SEGMENTED`]).
    pub segment: u32,
    /// Path generator spec of the frame axis, with `{frames}` replaced by the frame count and
    /// `{frames*X}` by the frame count times the number X (so that `degrees={frames*3.6}`
    /// keeps the camera's step per frame fixed and longer paths go further).
    pub path: String,
    /// Frames recorded per run of the triangle axis.
    pub triangle_axis_frames: u32,
    /// Path generator spec of the triangle axis (same placeholders as [`Self::path`]).
    pub triangle_path: String,
    /// Demo-car triangle count of the frame axis.
    pub frames_axis_triangles: u32,
}

impl ScalingConfig {
    /// A tiny configuration for tests: 10 k and 20 k triangles at 32×32, 3 and 6 frames of a
    /// 10 k car, 200 synthetic frames in segments of 50.
    pub fn quick() -> Self {
        ScalingConfig {
            size: (32, 32),
            samples: 4,
            triangle_counts: vec![10_000, 20_000],
            frame_counts: vec![3, 6],
            synthetic_frames: vec![200],
            segment: 50,
            path: "orbit:frames={frames},degrees={frames*3.6},elevation=15,distance=2.75".into(),
            triangle_axis_frames: 2,
            triangle_path: "orbit:frames={frames},degrees=360,elevation=15,distance=2.75".into(),
            frames_axis_triangles: 10_000,
        }
    }

    /// The BENCHMARKS run: 10 k … 5 M triangles (4 frames of a full orbit each) and 10 … 1,000
    /// frames of the 20 k demo car (3.6° per frame: 100 frames make one turn, 1,000 ten), both
    /// at 128×128 with 4 samples; synthetic long paths of 100 … 10,000 frames (24 objects × 16
    /// sides, 128 samples, 0.36° per frame, as `tests/long_paths.rs`). Segments of 64 frames,
    /// `trisort merge`'s default.
    pub fn full() -> Self {
        ScalingConfig {
            size: (128, 128),
            samples: 4,
            triangle_counts: vec![
                10_000, 20_000, 50_000, 100_000, 200_000, 500_000, 1_000_000, 2_000_000, 5_000_000,
            ],
            frame_counts: vec![10, 30, 100, 300, 1_000],
            synthetic_frames: vec![100, 300, 1_000, 3_000, 10_000],
            segment: MergeOptions::DEFAULT_SEGMENT,
            path: "orbit:frames={frames},degrees={frames*3.6},elevation=15,distance=2.75".into(),
            triangle_axis_frames: 4,
            triangle_path: "orbit:frames={frames},degrees=360,elevation=15,distance=2.75".into(),
            frames_axis_triangles: 20_000,
        }
    }

    /// The recording settings of every run. Scaling measures the recorder and the merger on
    /// the procedural car as generated, so nothing is split before recording.
    fn settings(&self) -> RecordSettings {
        RecordSettings {
            split_intersections: false,
            ..RecordSettings::new(self.size, self.samples)
        }
    }
}

/// One measured run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScalingRow {
    /// `triangles`, `frames`, `frames-segmented` or `synthetic-frames`.
    pub axis: String,
    /// Triangles of the scene.
    pub triangles: u64,
    /// Frames of the path.
    pub frames: u32,
    /// |G|: triangles visible in at least one frame.
    pub unique_visible: u64,
    /// Wall time of `trisort_recorder::record` (both phases); NaN (JSON `null`, empty in the
    /// CSV) for synthetic recordings, which are generated, not recorded.
    pub record_seconds: f64,
    /// `record_seconds / frames`.
    pub record_seconds_per_frame: f64,
    /// Wall time of `trisort_merger::merge`.
    pub merge_seconds: f64,
    /// Triangles in the baked index buffer (copies).
    pub index_triangles: u64,
    /// Mean draws per frame of the bake.
    pub draws_per_frame_mean: f64,
    /// Most draws in one frame.
    pub draws_per_frame_max: u32,
    /// Peak resident memory of the process during the run (VmHWM, reset before the run
    /// through `/proc/self/clear_refs`), in MiB; `None` where it cannot be reset or read. It
    /// includes what the process held before the run (the GPU driver's memory, on lavapipe
    /// the "GPU" buffers too).
    pub peak_rss_mib: Option<f64>,
    /// Mean layers peeled per frame (both phases together); 2 for synthetic recordings.
    pub layers_mean: f64,
    /// CPU time (user + system, every thread of the process: lavapipe's too) spent during
    /// the record call, in seconds; `None` for synthetic recordings and where
    /// `/proc/self/stat` cannot be read. Less sensitive than wall time to other processes
    /// sharing the machine.
    pub record_cpu_seconds: Option<f64>,
    /// CPU time spent during the merge call (as [`Self::record_cpu_seconds`]).
    pub merge_cpu_seconds: Option<f64>,
}

impl ScalingRow {
    /// `index_triangles / unique_visible` (copies per triangle of G).
    pub fn index_ratio(&self) -> f64 {
        self.index_triangles as f64 / self.unique_visible.max(1) as f64
    }
}

/// The growth of one series: `y ∝ x^exponent`, fitted by least squares in log-log.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Growth {
    /// The axis of the rows fitted.
    pub axis: String,
    /// The column on x.
    pub x: String,
    /// The column on y.
    pub y: String,
    /// The least-squares slope of ln y against ln x.
    pub exponent: f64,
    /// The same over the upper half of the points by x (the larger half when odd, at least
    /// two): the asymptotic growth, once fixed per-run costs no longer dominate; `None` with
    /// fewer than three points.
    pub exponent_upper: Option<f64>,
    /// Points fitted (positive, finite x and y).
    pub points: usize,
}

/// The least-squares slope of ln y against ln x over the points with positive, finite x and
/// y; `None` with fewer than two such points or when every x is the same.
pub fn growth_exponent(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as f64;
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// The series [`write_outputs`] fits, per axis present in `rows`: on the triangle axis
/// record seconds, merge seconds, |G| and index triangles against triangles; on both frame
/// axes record seconds per frame (real frames only), merge seconds, index triangles and
/// index/|G| against frames; peak RSS against the axis' x where it was measured; and on the
/// triangle axis also merge seconds against |G|.
pub fn growth(rows: &[ScalingRow]) -> Vec<Growth> {
    type Column = (&'static str, fn(&ScalingRow) -> f64);
    let mut out = Vec::new();
    for axis in [
        AXIS_TRIANGLES,
        AXIS_FRAMES,
        AXIS_FRAMES_SEGMENTED,
        AXIS_SYNTHETIC,
    ] {
        let of_axis: Vec<&ScalingRow> = rows.iter().filter(|r| r.axis == axis).collect();
        if of_axis.is_empty() {
            continue;
        }
        let x: Column = if axis == AXIS_TRIANGLES {
            ("triangles", |r| r.triangles as f64)
        } else {
            ("frames", |r| f64::from(r.frames))
        };
        let mut ys: Vec<Column> = vec![
            ("record_seconds", |r| r.record_seconds),
            ("record_seconds_per_frame", |r| r.record_seconds_per_frame),
            ("merge_seconds", |r| r.merge_seconds),
            ("record_cpu_seconds", |r| {
                r.record_cpu_seconds.unwrap_or(f64::NAN)
            }),
            ("merge_cpu_seconds", |r| {
                r.merge_cpu_seconds.unwrap_or(f64::NAN)
            }),
            ("unique_visible", |r| r.unique_visible as f64),
            ("index_triangles", |r| r.index_triangles as f64),
            ("index_per_unique_visible", ScalingRow::index_ratio),
            ("peak_rss_mib", |r| r.peak_rss_mib.unwrap_or(f64::NAN)),
        ];
        if axis == AXIS_SYNTHETIC {
            ys.retain(|(name, _)| !name.starts_with("record_"));
        }
        let mut fits: Vec<(Column, Column)> = ys.into_iter().map(|y| (x, y)).collect();
        if axis == AXIS_TRIANGLES {
            // The merger works on G, not on the scene: its cost against |G|.
            let g: Column = ("unique_visible", |r| r.unique_visible as f64);
            fits.push((g, ("merge_seconds", |r| r.merge_seconds)));
            fits.push((
                g,
                ("merge_cpu_seconds", |r| {
                    r.merge_cpu_seconds.unwrap_or(f64::NAN)
                }),
            ));
        }
        for (x, (name, y)) in fits {
            let mut pts: Vec<(f64, f64)> = of_axis
                .iter()
                .map(|r| (x.1(r), y(r)))
                .filter(|(a, b)| a.is_finite() && b.is_finite() && *a > 0.0 && *b > 0.0)
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            if let Some(exponent) = growth_exponent(&pts) {
                let upper = &pts[pts.len() / 2..];
                out.push(Growth {
                    axis: axis.into(),
                    x: x.0.into(),
                    y: name.into(),
                    exponent,
                    exponent_upper: if pts.len() >= 3 {
                        growth_exponent(upper)
                    } else {
                        None
                    },
                    points: pts.len(),
                });
            }
        }
    }
    out
}

/// Replaces `{frames}` by `frames` and `{frames*X}` by `frames × X` in a path spec.
pub fn path_spec(template: &str, frames: u32) -> Result<String, BenchError> {
    let mut out = String::new();
    let mut rest = template;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let close = rest[open..]
            .find('}')
            .map(|c| open + c)
            .ok_or_else(|| BenchError::Invalid(format!("path {template:?}: unclosed '{{'")))?;
        let inner = rest[open + 1..close].trim();
        let value = match inner.strip_prefix("frames") {
            Some("") => f64::from(frames),
            Some(m) => {
                let factor: f64 = m
                    .trim()
                    .strip_prefix('*')
                    .and_then(|x| x.trim().parse().ok())
                    .ok_or_else(|| {
                        BenchError::Invalid(format!(
                            "path {template:?}: expected {{frames}} or {{frames*NUMBER}}, found {{{inner}}}"
                        ))
                    })?;
                f64::from(frames) * factor
            }
            None => {
                return Err(BenchError::Invalid(format!(
                    "path {template:?}: unknown placeholder {{{inner}}}"
                )))
            }
        };
        // Six decimals at most: 30 × 3.6 is 108, not 108.00000000000001.
        out.push_str(&format!("{}", (value * 1e6).round() / 1e6));
        rest = &rest[close + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Resets the process's peak resident set size (VmHWM) to its current size; false where the
/// kernel does not allow it. On glibc, memory that earlier runs freed but the allocator kept
/// is first handed back to the system (`malloc_trim`), so that it does not count as this
/// run's.
fn reset_peak_rss() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        extern "C" {
            fn malloc_trim(pad: usize) -> std::os::raw::c_int;
        }
        // SAFETY: glibc's malloc_trim takes no pointer, only releases free heap memory, and
        // is thread-safe (it locks every arena).
        unsafe {
            malloc_trim(0);
        }
    }
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// VmHWM of this process in MiB.
fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: f64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))?
        .trim()
        .strip_suffix("kB")?
        .trim()
        .parse()
        .ok()?;
    Some(kb / 1024.0)
}

/// CPU time (user + system) of this process so far, in seconds, from `/proc/self/stat`
/// (clock ticks of the Linux ABI's fixed `USER_HZ` = 100).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) start with the state (field 3);
    // utime and stime are fields 14 and 15.
    let rest = &stat[stat.rfind(')')? + 1..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |k: usize| fields.get(k - 3)?.parse::<u64>().ok();
    Some((ticks(14)? + ticks(15)?) as f64 / 100.0)
}

/// CPU seconds since `start` (a [`cpu_seconds`] reading).
fn cpu_since(start: Option<f64>) -> Option<f64> {
    Some(cpu_seconds()? - start?)
}

/// Starts a peak-memory window: the peak is attributable to the run only if it was reset.
struct PeakWindow(bool);

impl PeakWindow {
    fn start() -> Self {
        PeakWindow(reset_peak_rss())
    }
    fn peak(&self) -> Option<f64> {
        if self.0 {
            peak_rss_mib()
        } else {
            None
        }
    }
}

/// One measured recording: `frames` frames of `scene` along the path `template`, reported on
/// axis `axis`, merged again in segments of `segment` frames when given.
struct RealRun<'a> {
    axis: &'a str,
    scene: &'a trisort_scene::Scene,
    template: &'a str,
    frames: u32,
    segment: Option<u32>,
}

/// Records `frames` frames of `scene` along `template`, merges them with the default options
/// (`auto`, one matrix) and measures both; with `segment`, merges the same recording again
/// in segments of that many frames (a second row on [`AXIS_FRAMES_SEGMENTED`], whose
/// record figures repeat the first's and whose peak memory covers that merge alone, with
/// the recording in memory).
fn run_real(
    gpu: &Gpu,
    config: &ScalingConfig,
    run: RealRun<'_>,
    progress: &dyn Fn(&str),
) -> Result<Vec<ScalingRow>, BenchError> {
    let RealRun {
        axis,
        scene,
        template,
        frames,
        segment,
    } = run;
    let spec = path_spec(template, frames)?;
    let timeline = trisort_paths::load(&spec, scene, &trisort_paths::PathOptions::default())
        .map_err(|e| BenchError::Invalid(format!("path {spec}: {e}")))?;
    let n = timeline.frames.len() as u32;
    let triangles = scene.geometry.triangles.len() as u64;
    // The demo car as generated: the scaling measures recording and merging cost against
    // the scene's own size, without splitting its crossing triangles first.
    let settings = config.settings();
    let target = || RecordTarget {
        settings: &settings,
        frames: None,
        phase: Phase::Graphs,
        known_visible: None,
    };
    progress(&format!(
        "{axis}: recording {triangles} triangles, {n} frames ({spec}) at {}x{} {}x",
        config.size.0, config.size.1, config.samples
    ));
    let window = PeakWindow::start();
    let cpu0 = cpu_seconds();
    let t0 = Instant::now();
    let step = (n / 10).max(1);
    let mut events = Progress {
        axis,
        step,
        t0,
        progress,
    };
    let rec: Recording = record_in_memory(gpu, scene, &timeline, target(), &mut events)?;
    let record_seconds = t0.elapsed().as_secs_f64();
    let record_cpu_seconds = cpu_since(cpu0);
    progress(&format!(
        "{axis}: recorded in {record_seconds:.2} s ({} CPU), |G| = {}; merging",
        record_cpu_seconds.map_or("?".into(), |c| format!("{c:.1} s")),
        rec.unique_visible.len()
    ));
    let layers: u64 = rec
        .frames
        .iter()
        .map(|f| u64::from(f.layers[0]) + u64::from(f.layers[1]))
        .sum();
    let measure = |axis: &str, opts: &MergeOptions, window: PeakWindow| {
        let cpu1 = cpu_seconds();
        let t1 = Instant::now();
        // The rows need the merge's statistics, not a lit file: no light is made or stored.
        let merged = trisort_merger::merge(std::slice::from_ref(&rec), opts)?;
        let merge_seconds = t1.elapsed().as_secs_f64();
        let merge_cpu_seconds = cpu_since(cpu1);
        let peak = window.peak();
        let s = merged.stats();
        let row = ScalingRow {
            axis: axis.into(),
            triangles,
            frames: n,
            unique_visible: rec.unique_visible.len() as u64,
            record_seconds,
            record_seconds_per_frame: record_seconds / f64::from(n),
            merge_seconds,
            index_triangles: s.index_triangles,
            draws_per_frame_mean: s.draws_per_frame_mean,
            draws_per_frame_max: s.draws_per_frame_max,
            peak_rss_mib: peak,
            layers_mean: layers as f64 / rec.frames.len().max(1) as f64,
            record_cpu_seconds,
            merge_cpu_seconds,
        };
        progress(&format!(
            "{axis}: merged in {merge_seconds:.2} s ({} CPU): {} copies ({:.2} x |G|), draws {:.1} / {}",
            merge_cpu_seconds.map_or("?".into(), |c| format!("{c:.1} s")),
            s.index_triangles,
            row.index_ratio(),
            s.draws_per_frame_mean,
            s.draws_per_frame_max
        ));
        Ok::<_, BenchError>(row)
    };
    let whole = MergeOptions {
        segment: None,
        ..MergeOptions::default()
    };
    let mut rows = vec![measure(axis, &whole, window)?];
    if let Some(segment) = segment {
        let opts = MergeOptions {
            segment: Some(segment),
            ..MergeOptions::default()
        };
        rows.push(measure(AXIS_FRAMES_SEGMENTED, &opts, PeakWindow::start())?);
    }
    Ok(rows)
}

/// Record and merge cost against triangles: for each of `config.triangle_counts`, the demo
/// car of about that many triangles, recorded along `config.triangle_path` with
/// `config.triangle_axis_frames` frames at `config.size` and `config.samples`, then merged
/// with the default options.
pub fn triangles(
    gpu: &Gpu,
    config: &ScalingConfig,
    progress: &dyn Fn(&str),
) -> Result<Vec<ScalingRow>, BenchError> {
    let mut rows = Vec::new();
    for &n in &config.triangle_counts {
        progress(&format!(
            "triangles: building the demo car of ~{n} triangles"
        ));
        let scene = trisort_scene::demo_car::demo_car(n);
        rows.extend(run_real(
            gpu,
            config,
            RealRun {
                axis: AXIS_TRIANGLES,
                scene: &scene,
                template: &config.triangle_path,
                frames: config.triangle_axis_frames,
                segment: None,
            },
            progress,
        )?);
    }
    Ok(rows)
}

/// Record and merge cost against frames: for each of `config.frame_counts`, the demo car of
/// `config.frames_axis_triangles` triangles recorded along `config.path` at `config.size` and
/// `config.samples` and merged with the default options (`auto`, one matrix), then merged
/// again in segments of `config.segment` frames (rows `frames` and `frames-segmented`, in
/// that order for each count); then for each of `config.synthetic_frames`, a synthetic
/// turntable recording of that many frames (24 objects × 16 sides, 128 samples, 0.36° per
/// frame), cut into four recordings as four machines would record them, merged with `auto`
/// in segments of `config.segment` frames.
pub fn frames(
    gpu: &Gpu,
    config: &ScalingConfig,
    progress: &dyn Fn(&str),
) -> Result<Vec<ScalingRow>, BenchError> {
    if config.segment == 0 {
        return Err(BenchError::Invalid("segment must be at least 1".into()));
    }
    let mut rows = Vec::new();
    if !config.frame_counts.is_empty() {
        let scene = trisort_scene::demo_car::demo_car(config.frames_axis_triangles);
        for &n in &config.frame_counts {
            rows.extend(run_real(
                gpu,
                config,
                RealRun {
                    axis: AXIS_FRAMES,
                    scene: &scene,
                    template: &config.path,
                    frames: n,
                    segment: Some(config.segment),
                },
                progress,
            )?);
        }
    }
    for &n in &config.synthetic_frames {
        rows.push(synthetic(n, config.segment, progress)?);
    }
    Ok(rows)
}

/// One synthetic long path of `frames` frames, merged in segments.
fn synthetic(frames: u32, segment: u32, progress: &dyn Fn(&str)) -> Result<ScalingRow, BenchError> {
    if frames == 0 {
        return Err(BenchError::Invalid(
            "a path needs at least one frame".into(),
        ));
    }
    progress(&format!(
        "{AXIS_SYNTHETIC}: generating a {frames}-frame turntable recording"
    ));
    let rec = turntable(&Turntable {
        objects: 24,
        sides: 16,
        frames,
        samples: 128,
        degrees: 0.36 * f64::from(frames),
        ..Turntable::default()
    });
    // Four recordings of unequal length whose boundaries miss the segment boundaries, as in
    // tests/long_paths.rs (fewer for very short paths).
    let mut starts: Vec<u32> = [0.0, 0.2345, 0.5, 0.7777]
        .iter()
        .map(|q| (q * f64::from(frames)) as u32)
        .collect();
    starts.dedup();
    let parts = split_frames(&rec, &starts);
    let layers: u64 = rec
        .frames
        .iter()
        .map(|f| u64::from(f.layers[0]) + u64::from(f.layers[1]))
        .sum();
    let unique_visible = rec.unique_visible.len() as u64;
    let triangles = u64::from(rec.scene_triangles);
    drop(rec);
    progress(&format!(
        "{AXIS_SYNTHETIC}: merging {frames} frames from {} recordings, segments of {segment}",
        parts.len()
    ));
    let window = PeakWindow::start();
    let cpu0 = cpu_seconds();
    let t0 = Instant::now();
    let merged = trisort_merger::merge(
        &parts,
        &MergeOptions {
            segment: Some(segment),
            ..MergeOptions::default()
        },
    )?;
    let merge_seconds = t0.elapsed().as_secs_f64();
    let merge_cpu_seconds = cpu_since(cpu0);
    let peak = window.peak();
    let s = merged.stats();
    progress(&format!(
        "{AXIS_SYNTHETIC}: merged in {merge_seconds:.2} s: {} copies, draws {:.1} / {}",
        s.index_triangles, s.draws_per_frame_mean, s.draws_per_frame_max
    ));
    Ok(ScalingRow {
        axis: AXIS_SYNTHETIC.into(),
        triangles,
        frames,
        unique_visible,
        record_seconds: f64::NAN,
        record_seconds_per_frame: f64::NAN,
        merge_seconds,
        index_triangles: s.index_triangles,
        draws_per_frame_mean: s.draws_per_frame_mean,
        draws_per_frame_max: s.draws_per_frame_max,
        peak_rss_mib: peak,
        layers_mean: layers as f64 / f64::from(frames),
        record_cpu_seconds: None,
        merge_cpu_seconds,
    })
}

mod outputs;
pub use outputs::{to_csv, write_outputs};

/// Recording progress as a line every tenth of the frames.
struct Progress<'a> {
    axis: &'a str,
    step: u32,
    t0: Instant,
    progress: &'a dyn Fn(&str),
}

impl trisort_bake::Events for Progress<'_> {
    fn progress(&mut self, p: &trisort_recorder::Progress) {
        if p.done.is_multiple_of(self.step) || p.done == p.total {
            (self.progress)(&format!(
                "{}: phase {} {}/{} frames ({:.1} s)",
                self.axis,
                p.phase,
                p.done,
                p.total,
                self.t0.elapsed().as_secs_f64()
            ));
        }
    }
}
