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
//! 1/255 units. Nothing passes unchecked: off the pattern without `--max-error` is
//! an error, and measuring without verifying needs `--measure-only`, which says that nothing
//! was verified and exits 4 unless `--allow-unverified` is given. The error of an 8-bit sRGB
//! deployment target is reported separately (`srgb8`) and never gated on.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::{json, Value};
use trisort_format::{Baked, Recording};
use trisort_gpu::{Gpu, GpuOptions};
use trisort_player::headless::HeadlessRenderer;
use trisort_player::Mode;
use trisort_reference::frames::{verify_images, write_diff, Frames, FramesToVerify, ImageReport};
use trisort_reference::html::{html_report, thumbnails, HtmlReport, ReportFile, Thumbnails};
use trisort_reference::report::{json_report, junit_report, text_report};
use trisort_reference::ImageCheck;

use crate::common::{load_scene, parse_range, parse_size, print_json, FrameRange};
use trisort_bake::inputs::{read_recordings, recorded_scene, Recorded};

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
    /// Camera path of a presorted file (`trisort presort`): a path spec as `bake --path`
    /// takes, or `random:N[:SEED]` (N random cameras outside its bounding polyhedron).
    #[arg(long, value_name = "P")]
    path: Option<String>,
    /// Opacity transmissive glass is drawn at, for a presorted file (default: the one it
    /// stores); a baked file is checked at its recorded opacity.
    #[arg(long, value_name = "ALPHA")]
    glass_opacity: Option<f32>,
    /// Where a presorted file's half-space test runs: fragment (default) or vertex (paper 000
    /// measures both; BENCHMARKS § Free viewpoints has ours).
    #[arg(long, value_enum)]
    test_stage: Option<super::presort::StageArg>,
    /// Compositing mode of the image check.
    #[arg(long, default_value = "blend")]
    mode: Mode,
    /// Image size WIDTHxHEIGHT (default: the recorded size).
    #[arg(long, value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// MSAA samples (default: the recorded count).
    #[arg(long)]
    samples: Option<u32>,
    /// Frames to check, half-open `a..b` (default: all; with `--clip`, relative to the clip).
    #[arg(long, value_parser = parse_range)]
    frames: Option<FrameRange>,
    /// Check only the frames of clip NAME (one camera path of a bundle; `inspect` lists the
    /// clips). The graph rules stay file-wide (copies and windows span the clips); the
    /// reports list the clip's frames.
    #[arg(long, value_name = "NAME")]
    clip: Option<String>,
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
    /// the checked size (with `--clip`, numbered within the clip, as `play --clip` writes
    /// them). Needs `--scene`.
    #[arg(long, value_name = "DIR", requires = "scene")]
    frames_dir: Option<PathBuf>,
    /// Check material variant NAME (as `play --variant NAME` plays it): the player and the
    /// exact reference both draw the variant's materials. Needs `--scene`.
    #[arg(long, value_name = "NAME", requires = "scene")]
    variant: Option<String>,
    /// Shift the projection of the player and of the exact reference by X,Y pixels (x right,
    /// y down; decimals or fractions such as `1/16,0`): a test aid standing for another GPU's
    /// vertex snapping. Off the recorded pattern: measured, failing only above --max-error.
    #[arg(long, value_name = "X,Y", value_parser = crate::common::parse_subpixel_offset, allow_hyphen_values = true)]
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
    /// Also write the verdict as JUnit XML to FILE, a test case per checked frame (for CI
    /// systems); written by rename, beside whatever the report prints.
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Also write a self-contained HTML sign-off report as DIR/index.html (created; written by
    /// rename): the files' BLAKE3 hashes, the bake's settings and raster profile, a verdict
    /// per clip and per frame (worst first) with thumbnails of the player's frame, the
    /// reference and a difference heat map embedded.
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
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
    let player = trisort_reference::frames::checked_player(gpu, baked, check)?;
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

/// `verify` of a presorted file (`None`: the file is not one; `--path` is then refused).
fn presorted(a: &VerifyArgs) -> Option<Result<ExitCode>> {
    if super::presort::is_presorted(&a.baked) {
        let run = super::presort::PresortedRun {
            file: &a.baked,
            path: a.path.as_deref(),
            size: a.size,
            samples: a.samples,
            mode: a.mode,
            frames: a.frames,
            glass_opacity: a.glass_opacity,
            shading: a.shading.shading,
            tone_map: a.shading.tonemap,
            json: a.json,
            stage: a.test_stage.unwrap_or_default(),
        };
        let diff_dir = a.diff_dir.as_deref().map(|d| (d, a.diff_all));
        return Some(super::presort::verify(&run, a.scene.as_deref(), diff_dir));
    }
    (a.path.is_some() || a.glass_opacity.is_some() || a.test_stage.is_some()).then(|| {
        Err(anyhow::anyhow!(
            "{}: --path, --glass-opacity and --test-stage apply to presorted files; a baked \
             file is checked along its own path at its recorded opacity",
            a.baked.display()
        ))
    })
}

pub fn run(a: VerifyArgs) -> Result<ExitCode> {
    if let Some(checked) = presorted(&a) {
        return checked;
    }
    let baked: Baked = trisort_player::open_baked(&a.baked)?;
    if a.recording.is_empty() && a.scene.is_none() && a.environment.is_none() {
        bail!("nothing to verify against: give --recording REC (graph rules) and/or --scene SCENE (images), or --environment studio|FILE.hdr (the stored light)");
    }
    // The stored light against the one named (None: not asked).
    let environment = (a.environment.as_ref())
        .map(|spec| -> Result<_> {
            let expected = trisort_bake::Light::parse(spec).load()?;
            Ok(baked.environment.difference(&expected))
        })
        .transpose()?;
    let clip = (a.clip.as_ref())
        .map(|name| {
            baked
                .clip(name)
                .map_err(|e| anyhow::anyhow!("--clip {name}: {e}"))
        })
        .transpose()?;
    let recs = read_recordings(&a.recording)?;
    let played = match a.mode {
        Mode::Depth => trisort_verify::PlayedIn::Depth,
        Mode::Blend | Mode::Saturate => trisort_verify::PlayedIn::Blend,
    };
    let mut graph =
        (!recs.is_empty()).then(|| trisort_verify::check_graph_for(&recs, &baked, played));
    if let (Some(g), Some(c)) = (&mut graph, &clip) {
        // The verdict stays file-wide; the frames listed are the clip's.
        g.frames.retain(|f| c.frames().contains(&f.frame));
    }
    let mut thumbs = BTreeMap::new();
    let mut textures = None;
    let images = match &a.scene {
        None => None,
        Some(spec) => {
            match image_check(&a, spec, &baked, &recs, clip, &mut thumbs, &mut textures) {
                Ok(r) => Some(r),
                // The graph rules failed already (the files disagree): that is the verdict.
                Err(e) if graph.as_ref().is_some_and(|g| !g.ok) => {
                    eprintln!("trisort: the images were not compared: {e:#}");
                    None
                }
                Err(e) => return Err(e),
            }
        }
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
    if let Some(file) = &a.junit {
        let xml = junit_report(
            &a.baked,
            &baked.clips,
            graph.as_ref(),
            images.as_ref(),
            a.measure_only,
        );
        trisort_format::container::write_bytes_atomic(file, xml.as_bytes())?;
    }
    let check = images.as_ref().map(|(report, _)| {
        if a.measure_only {
            "measured_only"
        } else if report.at_recorded_pattern {
            "recorded_pattern"
        } else {
            "max_error"
        }
    });
    let verdict = verdict_line(&a.baked, code, unverified);
    if let Some(dir) = &a.report {
        let what = Checked {
            ok,
            verdict: &verdict,
            graph: graph.as_ref(),
            images: images.as_ref(),
            thumbnails: &thumbs,
        };
        write_html(&a, dir, &baked, what)?;
    }
    if a.json {
        let mut v = json_report(ok, graph.as_ref(), images.as_ref());
        add_clips_json(&mut v, &a, &baked);
        if let Some(dir) = &a.frames_dir {
            v["frames_dir"] = json!(dir.display().to_string());
        }
        v["image_check"] = json!(check);
        // Block-compressed textures: what the image check drew them with, and their colour
        // error against the scene's RGBA8 (null: the file stores RGBA8).
        v["textures"] = json!(textures.as_ref().map(|t| t.to_json()));
        v["graph_check"] = json!(graph.as_ref().map(|g| g.checked));
        v["verified"] = json!(!unverified);
        v["environment"] = environment_json(&a, &baked, &environment, graph.is_some());
        if unverified {
            // Measured, not judged: no frame passed or failed.
            v["images_ok"] = Value::Null;
            for f in v["frames"].as_array_mut().into_iter().flatten() {
                f["ok"] = Value::Null;
            }
        }
        print_json(&v);
    } else {
        print!(
            "{}",
            text_report(&a.baked, graph.as_ref(), images.as_ref(), a.measure_only)
        );
        print_environment(&a, &baked, environment.as_ref(), graph.is_some());
        if let Some(t) = &textures {
            print_textures(t);
        }
        if let Some(dir) = &a.report {
            println!("report: {}", dir.join("index.html").display());
        }
        println!("{verdict}");
    }
    Ok(ExitCode::from(code))
}

/// The text report's line on the stored light: `environment` is its difference from the
/// light `--environment` names (`None`: not asked); `graph`: whether the graph rules ran
/// (they check a file that names the built-in studio).
fn print_environment(
    a: &VerifyArgs,
    baked: &Baked,
    environment: Option<&Option<String>>,
    graph: bool,
) {
    let name = &baked.environment.name;
    match (environment, &a.environment) {
        (Some(Some(what)), Some(spec)) => {
            println!("environment: FAILED: the stored light ({name:?}) is not {spec}: {what}")
        }
        (Some(None), Some(spec)) => println!("environment: OK (the stored light is {spec})"),
        _ if graph && name == "studio" => {
            println!("environment: checked with the graph rules (the built-in studio)")
        }
        _ => println!(
            "environment: {name:?}, not checked (give --environment FILE.hdr, the light it was baked with)"
        ),
    }
}

/// What the checks found, for the HTML report.
struct Checked<'a> {
    ok: bool,
    verdict: &'a str,
    graph: Option<&'a trisort_verify::GraphReport>,
    images: Option<&'a (ImageReport, ImageCheck)>,
    thumbnails: &'a BTreeMap<u32, Thumbnails>,
}

/// `--report DIR`: the HTML sign-off report as DIR/index.html.
fn write_html(a: &VerifyArgs, dir: &Path, baked: &Baked, what: Checked<'_>) -> Result<()> {
    let html = html_report(&HtmlReport {
        baked: hashed_file(&a.baked)?,
        scene: a.scene.as_deref().map(scene_file).transpose()?,
        recordings: a
            .recording
            .iter()
            .map(|p| hashed_file(p))
            .collect::<Result<_>>()?,
        tool_version: env!("CARGO_PKG_VERSION"),
        baked_tool_version: &baked.tool_version,
        settings: settings_rows(baked),
        raster_profile: trisort_bake::figures::profile_summary(&baked.settings),
        clips: &baked.clips,
        clip: a.clip.as_deref(),
        ok: what.ok,
        verdict: what.verdict.to_string(),
        graph: what.graph,
        images: what.images,
        measure_only: a.measure_only,
        thumbnails: what.thumbnails,
    });
    trisort_reference::html::write_report(dir, &html)?;
    Ok(())
}

/// `--json`'s clip keys: `clip` (the one given) and each frame's `clip`; and `report`.
fn add_clips_json(v: &mut Value, a: &VerifyArgs, baked: &Baked) {
    for f in v["frames"].as_array_mut().into_iter().flatten() {
        let clip = f["frame"]
            .as_u64()
            .and_then(|n| baked.clip_of_frame(n as u32))
            .map(|(_, c)| c.name.clone());
        f["clip"] = json!(clip);
    }
    v["clip"] = json!(a.clip);
    if let Some(dir) = &a.report {
        v["report"] = json!(dir.join("index.html").display().to_string());
    }
}

/// The verdict's last line: the file and OK, FAILED or NOT VERIFIED as exit `code` says.
fn verdict_line(baked: &Path, code: u8, unverified: bool) -> String {
    format!(
        "{}: {}",
        baked.display(),
        match code {
            0 if unverified => "images NOT VERIFIED (--measure-only --allow-unverified)",
            0 => "OK",
            UNVERIFIED => "images NOT VERIFIED (--measure-only; exit 4 unless --allow-unverified)",
            _ => "FAILED",
        }
    )
}

/// BLAKE3 of a file's bytes, hex.
fn blake3_hex(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(hex(&trisort_format::hash_bytes(&bytes)))
}

/// Bytes as lower-case hex.
fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// A file of the report with its hash.
fn hashed_file(path: &Path) -> Result<ReportFile> {
    Ok(ReportFile {
        path: path.display().to_string(),
        blake3: Some(blake3_hex(path)?),
        note: String::new(),
    })
}

/// The scene of `--scene SPEC` for the report: a file's hash (a .gltf's buffers and images
/// are files of their own, not hashed here: the baked file's scene hash covers the geometry),
/// or a built-in scene.
fn scene_file(spec: &str) -> Result<ReportFile> {
    let path = Path::new(spec);
    if path.is_file() {
        let gltf = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("gltf"));
        Ok(ReportFile {
            note: if gltf {
                "(the .gltf file itself; its buffers and images are not hashed here)".into()
            } else {
                String::new()
            },
            ..hashed_file(path)?
        })
    } else {
        Ok(ReportFile {
            path: spec.to_string(),
            blake3: None,
            note: "built-in scene, no file to hash".into(),
        })
    }
}

/// The bake's settings as rows for the report: the recording settings (flattened), how it
/// was merged, its frames, clips, light and stored hashes.
fn settings_rows(baked: &Baked) -> Vec<(String, String)> {
    fn flatten(prefix: &str, v: &Value, out: &mut Vec<(String, String)>) {
        match v {
            Value::Object(map) => {
                for (k, v) in map {
                    let key = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    flatten(&key, v, out);
                }
            }
            Value::String(s) => out.push((prefix.to_string(), s.clone())),
            other => out.push((prefix.to_string(), other.to_string())),
        }
    }
    let mut rows = Vec::new();
    let settings = serde_json::to_value(baked.settings).unwrap_or(Value::Null);
    flatten("settings", &settings, &mut rows);
    let m = &baked.merge;
    let merge = json!({
        "strategy": m.strategy,
        "layout": m.layout,
        "bridge": m.bridge,
        "depth_only": m.depth_only,
        "segment": m.segment,
        "seeding": m.seeding,
    });
    flatten("merge", &merge, &mut rows);
    rows.push(("frames".into(), baked.frames.len().to_string()));
    rows.push((
        "fps".into(),
        baked.fps.map_or_else(|| "-".into(), |f| f.to_string()),
    ));
    rows.push(("copies".into(), baked.copies.len().to_string()));
    rows.push(("triangles".into(), baked.scene_ids.len().to_string()));
    rows.push(("environment".into(), baked.environment.name.clone()));
    let device = serde_json::to_value(&baked.device).unwrap_or(Value::Null);
    flatten("recording device", &device, &mut rows);
    rows.push(("scene hash (stored)".into(), hex(&baked.scene_hash)));
    rows.push(("path hash (stored)".into(), hex(&baked.path_hash)));
    rows
}

/// `--json`'s `environment`: the stored light's name, what it was checked against and the
/// difference found (`environment`: `None` when no light was named).
fn environment_json(
    a: &VerifyArgs,
    baked: &Baked,
    environment: &Option<Option<String>>,
    graph: bool,
) -> Value {
    json!({
        "name": baked.environment.name,
        "checked": match (&a.environment, graph) {
            (Some(_), _) => "given",
            (None, true) if baked.environment.name == "studio" => "studio",
            _ => "no",
        },
        "difference": environment.clone().flatten(),
    })
}

/// The text report's line on a file's block-compressed textures.
fn print_textures(t: &trisort_bake::textures::TextureReport) {
    let worst = t.worst_psnr_db().map_or("unchanged".into(), |p| {
        format!("worst PSNR {p:.1} dB against the scene's RGBA8")
    });
    println!(
        "textures: {} stored as {} blocks, drawn decoded by both sides; alpha that decides \
         visibility equal to the scene's; colour {worst}",
        t.compressed(),
        t.format.name()
    );
}

/// The image check of `verify --scene SPEC`: the scene as recorded (split where the
/// recording split it, by the recording's path and settings where given), checked against the
/// files' scene hashes, then every frame of `--frames`.
fn image_check(
    a: &VerifyArgs,
    spec: &str,
    baked: &Baked,
    recs: &[Recording],
    clip: Option<&trisort_format::Clip>,
    thumbs: &mut BTreeMap<u32, Thumbnails>,
    textures: &mut Option<trisort_bake::textures::TextureReport>,
) -> Result<(ImageReport, ImageCheck)> {
    let settings = recs.first().map_or(baked.settings, |r| r.settings);
    let mut scene = load_scene(spec)?;
    let recorded = Recorded {
        baked,
        baked_file: &a.baked,
        recordings: recs,
        files: &a.recording,
    };
    recorded_scene(&mut scene, spec, &recorded)?;
    // Block-compressed textures: the reference draws the file's decoded texels once they
    // are checked against the scene's (alpha that decides visibility exact; colour measured).
    *textures = trisort_bake::textures::adopt_stored(scene.geometry_mut(), &baked.geometry)
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.baked.display()))?;
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
    let (first, n) = clip.map_or((0, baked.frames.len() as u32), |c| (c.first, c.count));
    let range = match a.frames {
        Some(r) => {
            let r = r.resolve(n).with_context(|| match clip {
                Some(c) => format!(
                    "--frames counts within clip {:?} ({} frames)",
                    c.name, c.count
                ),
                None => "--frames".into(),
            })?;
            first + r.start..first + r.end
        }
        None if n == 0 => bail!("the baked file has no frames"),
        None => first..first + n,
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
        (Some(dir), _) => Frames::Dir(dir, first),
        (None, Some(player)) => Frames::Elsewhere(player),
        (None, None) => Frames::Play,
    };
    let what = FramesToVerify {
        baked,
        geometry,
        check,
        recordings: recs,
        frames: range,
        source: captured,
    };
    let report = verify_images(&gpu, what, |v| {
        if a.report.is_some() {
            thumbs.insert(v.report.frame, thumbnails(v, size)?);
        }
        match &a.diff_dir {
            Some(dir) if a.diff_all || !v.report.ok => write_diff(dir, v, size),
            _ => Ok(()),
        }
    })?;
    Ok((report, check))
}
