//! `trisort verify BAKED`: the graph rules against recordings (`--recording`), the images
//! against the exact reference of the full scene (`--scene`), or both.
//!
//! Images: each frame of `--frames` is played by the player (or read from `--frames-dir`,
//! frames drawn elsewhere) and rendered by the exact reference (`trisort_reference`) at the
//! same size, sample count and mode. At the recorded pattern (the recorded size and samples,
//! on the recording device; for captured frames, whatever the device) a frame fails when
//! `depth` mode is not bit-exact, or when `blend`/`saturate` differ by more than 1/255 in a
//! colour channel at an ordered pixel. Which pixels are unordered (excused) comes from the
//! recordings' cycles only: with `--scene` alone no pixel is excused. Off the pattern a frame
//! fails above `--max-error N`: the largest colour-channel difference on ordered pixels, in
//! 1/255 units. Nothing passes unchecked (issue 28): off the pattern without `--max-error` is
//! an error, and measuring without verifying needs `--measure-only`, which says that nothing
//! was verified and exits 4 unless `--allow-unverified` is given. The error of an 8-bit sRGB
//! deployment target is reported separately (`srgb8`) and never gated on.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::{json, Value};
use trisort_format::{Baked, Geometry, RecordSettings, Recording};
use trisort_gpu::{Gpu, GpuOptions};
use trisort_player::headless::{HeadlessConfig, HeadlessRenderer};
use trisort_player::Mode;
use trisort_reference::compare::{difference_image, mask_image};
use trisort_reference::{FrameImageReport, ImageCheck, ImageVerifier, VerifiedFrame};

use crate::cmd::merge::read_recordings;
use crate::cmd::play::write_png;
use crate::common::{load_scene, parse_range, parse_size, print_json, FrameRange};
use trisort_bake::working_scene;

/// Exit code of a verification that ran and found the baked file wrong.
pub const VERIFY_FAILED: u8 = 3;

/// Exit code of `verify --measure-only` without `--allow-unverified`: the images were measured,
/// nothing was verified.
pub const UNVERIFIED: u8 = 4;

/// Arguments of `verify`.
#[derive(Args, Debug)]
pub struct VerifyArgs {
    /// Baked file.
    baked: PathBuf,
    /// Recording(s) the file was merged from: checks the graph rules, and gives the image
    /// check its unordered pixels (the recordings' cycles), path and recorded pattern.
    #[arg(long, num_args = 1..)]
    recording: Vec<PathBuf>,
    /// Scene (.glb/.gltf or `demo[:TRIANGLES]`): checks the images against the exact reference.
    #[arg(long)]
    scene: Option<String>,
    /// Compositing mode of the image check.
    #[arg(long, default_value = "blend")]
    mode: Mode,
    /// Image size WIDTHxHEIGHT (default: the recorded size).
    #[arg(long, value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// MSAA samples (default: the recorded count).
    #[arg(long)]
    samples: Option<u32>,
    /// Frames to check, half-open `a..b` (default: all).
    #[arg(long, value_parser = parse_range)]
    frames: Option<FrameRange>,
    /// Off the recorded pattern: fail a frame whose largest colour-channel difference on
    /// ordered pixels exceeds N/255. Off the pattern, a check needs this (or `--measure-only`).
    #[arg(long, value_name = "N", conflicts_with = "measure_only")]
    max_error: Option<u8>,
    /// Measure the images without verifying them: no frame fails, the report says that
    /// nothing was verified, and the exit code is 4 unless `--allow-unverified` is given. The
    /// graph rules (`--recording`) are checked all the same.
    #[arg(long, requires = "scene")]
    measure_only: bool,
    /// With `--measure-only`: exit 0 after measuring (the report still says that the images
    /// were not verified).
    #[arg(long, requires = "measure_only")]
    allow_unverified: bool,
    /// Write, for each failing frame, the player's frame, the reference, a difference image
    /// and the unordered mask as PNGs.
    #[arg(long)]
    diff_dir: Option<PathBuf>,
    /// With `--diff-dir`: write the images of every checked frame, not only failing ones.
    #[arg(long)]
    diff_all: bool,
    /// Check frames drawn elsewhere (another GPU, the target device, a browser) instead of
    /// playing them here: PNGs named as `play --out-dir` writes them (`frame-NNNNN.png`), at
    /// the checked size. Needs `--scene`.
    #[arg(long, value_name = "DIR", requires = "scene")]
    frames_dir: Option<PathBuf>,
    /// Check material variant NAME (as `play --variant NAME` plays it): the player and the
    /// exact reference both draw the variant's materials. Needs `--scene`.
    #[arg(long, value_name = "NAME", requires = "scene")]
    variant: Option<String>,
    /// Shift the projection of the player and of the exact reference by X,Y pixels (x right,
    /// y down; decimals or fractions such as `1/16,0`): a test aid standing for another GPU's
    /// vertex snapping. Off the recorded pattern: measured, failing only above --max-error.
    #[arg(long, value_name = "X,Y", value_parser = crate::cmd::play::parse_subpixel_offset, allow_hyphen_values = true)]
    subpixel_offset: Option<[f64; 2]>,
    /// The light the file was baked with (`studio`, or the .hdr file given to
    /// `bake`/`merge --environment`): made anew and compared with the file's stored
    /// environment, which fails the file when it differs. Without it `--recording` checks a
    /// file that names the built-in studio, and a file light is reported as not checked.
    #[arg(long, value_name = "studio|FILE.hdr")]
    environment: Option<String>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    /// `--shading` and `--tonemap`: the player and the exact reference light alike, with the
    /// baked file's environment.
    #[command(flatten)]
    shading: crate::cmd::play::ShadingArgs,
    /// `--backend` and `--limits`: other than `auto`/`default`, the frames are played on that
    /// device (webgl2: the player's GLES 3.0 / WebGL2 path) and checked as captured frames
    /// against the reference on the default device (the reference needs storage buffers and
    /// depth-texture loads that GL lacks).
    #[command(flatten)]
    device: crate::cmd::play::DeviceArgs,
}

/// Image verification of a range of frames.
pub struct ImageReport {
    /// Whether every frame passed.
    pub ok: bool,
    /// Whether the check ran at the recorded pattern.
    pub at_recorded_pattern: bool,
    /// Whether the frames were played here on a device other than the one the recording (or
    /// the file) names (checked all the same at the recorded pattern).
    pub on_other_device: bool,
    /// Per frame.
    pub frames: Vec<FrameImageReport>,
}

/// Checks the scene against the file's scene hash: the reference must render the scene the
/// file was baked from.
pub fn check_scene(baked: &Baked, scene: &trisort_scene::Scene, spec: &str) -> Result<()> {
    let hash = scene.hash();
    if hash != baked.scene_hash {
        bail!(
            "scene {spec} (hash {}) is not the scene the baked file was made from (hash {}): give the same scene file, or for demo the same demo:TRIANGLES",
            &trisort_format::hash_hex(&hash)[..16],
            &trisort_format::hash_hex(&baked.scene_hash)[..16]
        );
    }
    Ok(())
}

/// Verifies `frames` of `baked` against the exact reference of `geometry`, calling `each`
/// with every verified frame (for difference images and progress). `recordings` (may be
/// empty) decide which pixels may be unordered and give the reference its path and pattern;
/// `captured` is a directory of frames drawn elsewhere to check instead of playing them
/// (`check.captured` must then be set).
#[allow(clippy::too_many_arguments)]
pub fn verify_images(
    gpu: &Gpu,
    baked: &Baked,
    geometry: &Geometry,
    check: ImageCheck,
    recordings: &[Recording],
    frames: Range<u32>,
    captured: Frames<'_>,
    mut each: impl FnMut(&VerifiedFrame) -> Result<()>,
) -> Result<ImageReport> {
    let verifier = ImageVerifier::new(gpu, baked, geometry, check, recordings)?;
    let mut report = ImageReport {
        ok: true,
        at_recorded_pattern: verifier.at_recorded_pattern(),
        on_other_device: verifier.on_other_device(),
        frames: Vec::with_capacity(frames.len()),
    };
    for f in frames {
        let v = match captured {
            Frames::Play => verifier.verify(f),
            Frames::Dir(dir) => verifier.verify_captured(f, read_captured(dir, f, check.size)?),
            Frames::Elsewhere(player) => verifier.verify_captured(f, player.render(f)?.rgba8),
        }
        .with_context(|| format!("verifying frame {f}"))?;
        each(&v)?;
        report.ok &= v.report.ok;
        report.frames.push(v.report);
    }
    Ok(report)
}

/// Frame `f` as drawn elsewhere: `DIR/frame-NNNNN.png` (the name `play --out-dir` gives it),
/// which must be `size`, as RGBA8. A missing, unreadable or wrong-size file is an error
/// naming it.
fn read_captured(dir: &Path, f: u32, size: (u32, u32)) -> Result<Vec<u8>> {
    let path = dir.join(format!("frame-{f:05}.png"));
    if !path.is_file() {
        bail!(
            "{}: frame {f} is missing (--frames-dir holds one PNG per checked frame, named frame-NNNNN.png as play --out-dir writes them)",
            path.display()
        );
    }
    let image = image::open(&path)
        .with_context(|| format!("{}: not a readable image", path.display()))?
        .to_rgba8();
    if image.dimensions() != size {
        bail!(
            "{}: the image is {}x{}, the frames are checked at {}x{} (the recorded size, or --size)",
            path.display(),
            image.width(),
            image.height(),
            size.0,
            size.1
        );
    }
    Ok(image.into_raw())
}

/// Where the checked frames come from.
#[derive(Clone, Copy)]
pub enum Frames<'a> {
    /// Played here by the player on the verifying device.
    Play,
    /// Drawn elsewhere: PNGs in a directory (`--frames-dir`).
    Dir(&'a Path),
    /// Played on another device (`--backend`/`--limits`), one frame at a time as it is
    /// checked.
    Elsewhere(&'a HeadlessRenderer<'a>),
}

/// `--backend`/`--limits` other than the defaults: the device the frames are played on before
/// they are checked as captured frames.
fn elsewhere_device(a: &VerifyArgs) -> Result<Gpu> {
    if a.frames_dir.is_some() {
        bail!("--backend/--limits play the frames themselves: they cannot be combined with --frames-dir");
    }
    crate::common::open_gpu_with(a.device.options())
}

/// The player on the `--backend`/`--limits` device, saying where it plays.
fn elsewhere_player<'g>(
    a: &VerifyArgs,
    gpu: &'g Gpu,
    baked: &Baked,
    check: &ImageCheck,
) -> Result<HeadlessRenderer<'g>> {
    let config = HeadlessConfig {
        size: check.size,
        samples: check.samples,
        mode: check.mode,
        shading: check.shading,
        tone_map: check.tone_map,
        ..HeadlessConfig::recorded(baked)
    };
    let player = HeadlessRenderer::new(gpu, baked, &config)?;
    player.set_subpixel_offset(check.subpixel_offset);
    for w in player.player().warnings() {
        eprintln!("trisort: warning: {w}");
    }
    if !a.json {
        println!(
            "played on: {} with {:?} limits ({} bindings, {} draws)",
            gpu.describe(),
            a.device.limits,
            player.player().bindings().name(),
            player.player().config().draw_path.name()
        );
    }
    Ok(player)
}

fn write_diff(dir: &Path, v: &VerifiedFrame, size: (u32, u32)) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let f = v.report.frame;
    let (w, h) = size;
    let r = &v.reference;
    write_png(&dir.join(format!("{f:05}-player.png")), w, h, &v.player)?;
    write_png(&dir.join(format!("{f:05}-reference.png")), w, h, &r.rgba8)?;
    write_png(
        &dir.join(format!("{f:05}-diff.png")),
        w,
        h,
        &difference_image(&v.player, &r.rgba8, &r.unordered),
    )?;
    write_png(
        &dir.join(format!("{f:05}-unordered.png")),
        w,
        h,
        &mask_image(&r.unordered),
    )?;
    Ok(())
}

pub fn run(a: VerifyArgs) -> Result<ExitCode> {
    let baked: Baked = trisort_player::open_baked(&a.baked)?;
    if a.recording.is_empty() && a.scene.is_none() && a.environment.is_none() {
        bail!("nothing to verify against: give --recording REC (graph rules) and/or --scene SCENE (images), or --environment studio|FILE.hdr (the stored light)");
    }
    // The stored light against the one named (None: not asked).
    let environment = match &a.environment {
        None => None,
        Some(spec) => {
            let expected = trisort_bake::Light::parse(spec).load()?;
            Some(baked.environment.difference(&expected))
        }
    };
    let recs = read_recordings(&a.recording)?;
    let played = match a.mode {
        Mode::Depth => trisort_verify::PlayedIn::Depth,
        Mode::Blend | Mode::Saturate => trisort_verify::PlayedIn::Blend,
    };
    let graph = (!recs.is_empty()).then(|| trisort_verify::check_graph_for(&recs, &baked, played));
    let images = match &a.scene {
        None => None,
        Some(spec) => match image_check(&a, spec, &baked, &recs) {
            Ok(r) => Some(r),
            // The graph rules failed already (the files disagree): that is the verdict.
            Err(e) if graph.as_ref().is_some_and(|g| !g.ok) => {
                eprintln!("trisort: the images were not compared: {e:#}");
                None
            }
            Err(e) => return Err(e),
        },
    };
    let graph_ok =
        graph.as_ref().is_none_or(|g| g.ok) && environment.as_ref().is_none_or(|d| d.is_none());
    // Measured only: the images cannot fail, and they did not pass either.
    let images_ok = images.as_ref().is_none_or(|i| a.measure_only || i.0.ok);
    let unverified = a.measure_only && images.is_some();
    let code = if !(graph_ok && images_ok) {
        VERIFY_FAILED
    } else if unverified && !a.allow_unverified {
        UNVERIFIED
    } else {
        0
    };
    let ok = code == 0;
    let check = images.as_ref().map(|(report, _)| {
        if a.measure_only {
            "measured_only"
        } else if report.at_recorded_pattern {
            "recorded_pattern"
        } else {
            "max_error"
        }
    });
    if a.json {
        let mut v = json_report(ok, graph.as_ref(), images.as_ref());
        if let Some(dir) = &a.frames_dir {
            v["frames_dir"] = json!(dir.display().to_string());
        }
        v["image_check"] = json!(check);
        v["graph_check"] = json!(graph.as_ref().map(|g| g.checked));
        v["verified"] = json!(!unverified);
        v["environment"] = json!({
            "name": baked.environment.name,
            "checked": match (&a.environment, graph.is_some()) {
                (Some(_), _) => "given",
                (None, true) if baked.environment.name == "studio" => "studio",
                _ => "no",
            },
            "difference": environment.clone().flatten(),
        });
        if unverified {
            // Measured, not judged: no frame passed or failed.
            v["images_ok"] = Value::Null;
            for f in v["frames"].as_array_mut().into_iter().flatten() {
                f["ok"] = Value::Null;
            }
        }
        print_json(&v);
    } else {
        print_report(&a.baked, graph.as_ref(), images.as_ref(), a.measure_only);
        let name = &baked.environment.name;
        match (&environment, &a.environment) {
            (Some(Some(what)), Some(spec)) => {
                println!("environment: FAILED: the stored light ({name:?}) is not {spec}: {what}")
            }
            (Some(None), Some(spec)) => println!("environment: OK (the stored light is {spec})"),
            _ if graph.is_some() && name == "studio" => {
                println!("environment: checked with the graph rules (the built-in studio)")
            }
            _ => println!(
                "environment: {name:?}, not checked (give --environment FILE.hdr, the light it was baked with)"
            ),
        }
        println!(
            "{}: {}",
            a.baked.display(),
            match code {
                0 if unverified => "images NOT VERIFIED (--measure-only --allow-unverified)",
                0 => "OK",
                UNVERIFIED =>
                    "images NOT VERIFIED (--measure-only; exit 4 unless --allow-unverified)",
                _ => "FAILED",
            }
        );
    }
    Ok(ExitCode::from(code))
}

/// The image check of `verify --scene SPEC`: the scene as recorded (split where the
/// recording split it, by the recording's path and settings where given), checked against the
/// files' scene hashes, then every frame of `--frames`.
fn image_check(
    a: &VerifyArgs,
    spec: &str,
    baked: &Baked,
    recs: &[Recording],
) -> Result<(ImageReport, ImageCheck)> {
    let (states, settings, from): (&[_], RecordSettings, _) =
        match (recs.first(), a.recording.first()) {
            (Some(r), Some(file)) => (&r.frame_states, r.settings, file),
            _ => (&baked.frame_states, baked.settings, &a.baked),
        };
    let mut scene = load_scene(spec)?;
    // The scene as it was recorded: split where the recording split it.
    working_scene(
        &mut scene,
        spec,
        states,
        &from.display().to_string(),
        &settings,
    )?;
    check_scene(baked, &scene, spec)?;
    for (file, r) in a.recording.iter().zip(recs) {
        if r.scene_hash != scene.hash() {
            bail!(
                "{}: the recording is not of scene {spec}: its pixels cannot excuse the scene's",
                file.display()
            );
        }
    }
    // A variant: the file and the scene both with the variant's material table (after the
    // hash checks, which are of the default materials).
    let with_variant;
    let baked = match &a.variant {
        None => baked,
        Some(name) => {
            let mut b = baked.clone();
            b.geometry.materials = (b.geometry.variant_materials(Some(name)))
                .with_context(|| format!("verifying {}", a.baked.display()))?;
            let table = (scene.geometry.variant_materials(Some(name)))
                .with_context(|| format!("scene {spec}"))?;
            scene.geometry_mut().materials = table;
            with_variant = b;
            &with_variant
        }
    };
    let n = baked.frames.len() as u32;
    let range = match a.frames {
        Some(r) => r.resolve(n)?,
        None if n == 0 => bail!("the baked file has no frames"),
        None => 0..n,
    };
    let check = ImageCheck {
        size: a.size.unwrap_or((settings.width, settings.height)),
        samples: a.samples.unwrap_or(settings.samples.max(1)),
        max_error: a.max_error,
        captured: a.frames_dir.is_some() || a.device.options() != GpuOptions::default(),
        subpixel_offset: a.subpixel_offset.unwrap_or([0.0, 0.0]),
        shading: a.shading.shading,
        tone_map: a.shading.tonemap,
        ..ImageCheck::recorded(baked, a.mode)
    };
    if check.samples != 1 && check.samples != 4 {
        bail!("--samples {}: only 1 and 4 are supported", check.samples);
    }
    if !a.measure_only && check.max_error.is_none() && !check.at_recorded_pattern(&settings) {
        bail!(
            "{}x{} with {}x MSAA{} is off the recorded pattern ({}x{}, {}x): nothing would be verified there unless you give --max-error N (fail a frame whose ordered pixels differ by more than N/255), or --measure-only to measure without verifying (exit 4 unless --allow-unverified)",
            check.size.0,
            check.size.1,
            check.samples,
            if check.subpixel_offset == [0.0, 0.0] {
                String::new()
            } else {
                format!(
                    " moved by {},{} px",
                    check.subpixel_offset[0], check.subpixel_offset[1]
                )
            },
            settings.width,
            settings.height,
            settings.samples.max(1)
        );
    }
    let gpu = crate::common::open_gpu()?;
    if !a.json {
        println!("device: {}", gpu.describe());
    }
    let size = check.size;
    let geometry = &scene.geometry;
    let elsewhere_gpu = if a.device.options() == GpuOptions::default() {
        None
    } else {
        Some(elsewhere_device(a)?)
    };
    let elsewhere = elsewhere_gpu
        .as_ref()
        .map(|g| elsewhere_player(a, g, baked, &check))
        .transpose()?;
    let captured = match (a.frames_dir.as_deref(), &elsewhere) {
        (Some(dir), _) => Frames::Dir(dir),
        (None, Some(player)) => Frames::Elsewhere(player),
        (None, None) => Frames::Play,
    };
    let report = verify_images(&gpu, baked, geometry, check, recs, range, captured, |v| {
        if let Some(dir) = &a.diff_dir {
            if a.diff_all || !v.report.ok {
                write_diff(dir, v, size)?;
            }
        }
        Ok(())
    })?;
    Ok((report, check))
}

fn json_report(
    ok: bool,
    graph: Option<&trisort_verify::GraphReport>,
    images: Option<&(ImageReport, ImageCheck)>,
) -> Value {
    let graph_frame = |f: u32| graph.and_then(|g| g.frames.iter().find(|r| r.frame == f));
    let frames: Vec<Value> = match images {
        Some((report, _)) => report
            .frames
            .iter()
            .map(|fr| {
                let mut v = serde_json::to_value(fr).expect("report serializes");
                if let Some(g) = graph_frame(fr.frame) {
                    v["graph_violations"] = json!(g.graph_violations);
                    v["graph"] = serde_json::to_value(g).expect("report serializes");
                }
                v
            })
            .collect(),
        None => graph
            .map(|g| {
                g.frames
                    .iter()
                    .map(|f| serde_json::to_value(f).expect("report serializes"))
                    .collect()
            })
            .unwrap_or_default(),
    };
    let mut out = json!({ "ok": ok, "frames": frames });
    if let Some(g) = graph {
        out["graph_ok"] = json!(g.ok);
        out["problems"] = json!(g.problems);
        out["bad_copies"] = json!(g.bad_copies);
        out["depth_only"] = json!(g.depth_only);
        out["bridge"] = json!({ "claimed": g.bridge_claimed, "derived": g.bridge_derived });
    }
    if let Some((report, check)) = images {
        out["images_ok"] = json!(report.ok);
        out["mode"] = json!(check.mode.name());
        out["shading"] = json!(check.shading.name());
        out["tonemap"] = json!(check.tone_map.name());
        out["size"] = json!([check.size.0, check.size.1]);
        out["samples"] = json!(check.samples);
        out["at_recorded_pattern"] = json!(report.at_recorded_pattern);
        out["played_on_recording_device"] = json!(!report.on_other_device);
        out["max_error"] = json!(check.max_error);
        out["captured"] = json!(check.captured);
        out["subpixel_offset"] = json!(check.subpixel_offset);
        out["unordered_from_recording"] = json!(graph.is_some());
    }
    out
}

fn print_report(
    baked: &Path,
    graph: Option<&trisort_verify::GraphReport>,
    images: Option<&(ImageReport, ImageCheck)>,
    measure_only: bool,
) {
    if let Some(report) = graph {
        let bad: Vec<_> = report.frames.iter().filter(|f| !f.ok()).collect();
        println!(
            "graph rules: {} ({} frames checked, {} with problems, {} unordered samples)",
            if report.ok { "OK" } else { "FAILED" },
            report.frames.len(),
            bad.len(),
            report
                .frames
                .iter()
                .map(|f| f.unordered_samples)
                .sum::<u64>()
        );
        println!(
            "  order checked against: {}",
            match (report.checked, report.depth_only) {
                ("depth", _) => "the edges depth mode needs (a depth-only file, checked for --mode depth: ties, and edges behind translucent fragments)",
                (_, true) => "every edge of E_f (a depth-only file checked for blend: it plays right only in depth mode; --mode depth checks it for that)",
                _ => "every edge of E_f",
            }
        );
        println!(
            "  bridge: the file claims {}, its draws need {}",
            report.bridge_claimed, report.bridge_derived
        );
        for p in &report.problems {
            println!("  {p}");
        }
        for f in bad.iter().take(20) {
            println!("  frame {}: {:?}", f.frame, f);
        }
    }
    if let Some((report, check)) = images {
        let bad = report.frames.iter().filter(|f| !f.ok).count();
        println!(
            "{} of {} ({} mode, {}x{}, {}x MSAA, {}): {} ({} frames checked, {} failing)",
            if check.captured {
                "captured frames"
            } else {
                "images"
            },
            baked.display(),
            check.mode,
            check.size.0,
            check.size.1,
            check.samples,
            if measure_only {
                "measured only: NOTHING VERIFIED, no frame can fail".to_string()
            } else if report.at_recorded_pattern && report.on_other_device {
                "recorded pattern, played on another device than recorded: checked all the same"
                    .to_string()
            } else if report.at_recorded_pattern {
                "recorded pattern".to_string()
            } else {
                format!(
                    "off the recorded pattern, max error {}/255",
                    check.max_error.unwrap_or(0)
                )
            },
            if measure_only {
                "measured"
            } else if report.ok {
                "OK"
            } else {
                "FAILED"
            },
            report.frames.len(),
            if measure_only { 0 } else { bad }
        );
        println!(
            "  holes: differing pixels where the reference's nearest fragment is of a triangle the file does not draw; order: other differing ordered pixels"
        );
        println!(
            "  unordered (excused) pixels: {}",
            if graph.is_some() {
                "those with a sample on a cycle of the recording's E_f"
            } else {
                "none (no --recording)"
            }
        );
        println!(
            "  frame  ok  differing  ordered  max  max_ord  psnr   flip     unordered  holes  order  srgb8_max"
        );
        for f in &report.frames {
            let c = &f.comparison;
            println!(
                "  {:5}  {:3} {:9}  {:7}  {:3}  {:7}  {:5.1}  {:.5}  {:9}  {:5}  {:5}  {}",
                f.frame,
                match (measure_only, f.ok) {
                    (true, _) => "-",
                    (false, true) => "yes",
                    (false, false) => "NO",
                },
                c.pixels_differing,
                c.pixels_differing_ordered,
                c.max_channel_diff,
                c.max_channel_diff_ordered,
                c.psnr,
                c.flip_mean,
                f.unordered_samples,
                f.hole_pixels,
                f.order_error_pixels,
                f.srgb8
                    .map(|s| s.max_channel_diff.to_string())
                    .unwrap_or_else(|| "-".into())
            );
        }
    }
}
