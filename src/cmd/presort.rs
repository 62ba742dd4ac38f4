//! `trisort presort SCENE -o FILE` (paper 000's preprocessing), and playing and verifying the
//! presorted file it writes along any camera path (`play FILE --path P`, `verify FILE --path
//! P`; `random:N[:SEED]` is N random cameras outside the file's polyhedron).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use glam::{DMat4, DVec3};
use serde_json::json;
use trisort_bake::{working_scene, Light};
use trisort_format::{Camera, FileKind, FrameState, Mode, Presorted, RecordSettings};
use trisort_gpu::scene_gpu::View;
use trisort_gpu::{Gpu, Lighting, Shading, ToneMap};
use trisort_presort::{presort, PresortOptions};
use trisort_reference::{
    compare, ExactReference, PresortedRenderer, ReferenceConfig, UnorderedEdges,
};
use trisort_scene::Scene;

use crate::common::{load_scene, print_json, progress_bar};

/// Arguments of `presort`.
#[derive(Args, Debug)]
pub struct PresortArgs {
    /// Scene (.glb/.gltf or `demo[:TRIANGLES]`).
    scene: String,
    /// Output presorted file.
    #[arg(short, long)]
    output: PathBuf,
    /// Faces of the bounding polyhedron, one viewpoint partition (and list) each: 4
    /// (tetrahedron), 6 (cube), 8 (octahedron), or 10 to 256 (directions spread over the
    /// sphere). More partitions: shorter lists per frame, more copies in the file.
    #[arg(long, default_value_t = 6)]
    partitions: u32,
    /// How far cameras may go from the scene's centre, per axis, in scene radii (the
    /// viewpoint regions are bounded there; farther cameras are refused).
    #[arg(long, default_value_t = 100.0)]
    reach: f64,
    /// The light players shade with: `studio` or an equirectangular .hdr file.
    #[arg(long, default_value = "studio")]
    environment: String,
    /// Opacity transmissive glass is drawn at (stored; `play --glass-opacity` overrides it).
    /// Visibly tinted by default, as `demo` draws it: at 0 (`bake`'s default, see-through)
    /// glass shows nothing and its order nothing either.
    #[arg(long, default_value_t = super::demo::DEMO_GLASS_OPACITY)]
    glass_opacity: f32,
    /// Do not split triangles that pass through each other first (no order exists for them).
    #[arg(long)]
    keep_intersections: bool,
    /// Fail (exit 1, no file) on an occlusion cycle no cutting plane breaks, instead of
    /// keeping its copies out of order and reporting them (`unresolved_cycles`).
    #[arg(long)]
    strict: bool,
    /// Print the figures as JSON.
    #[arg(long)]
    json: bool,
}

/// A camera at the scene's rest pose, for the split (which only reads the poses).
fn rest_frame() -> FrameState {
    FrameState {
        camera: Camera {
            view: DMat4::IDENTITY.to_cols_array(),
            yfov: 1.0,
            znear: 0.1,
            zfar: None,
        },
        poses: Vec::new(),
    }
}

/// `presort`.
pub fn run(a: PresortArgs) -> Result<ExitCode> {
    let t0 = Instant::now();
    let environment = Light::parse(&a.environment).load()?;
    let mut scene = load_scene(&a.scene)?;
    let scene_hash = scene.hash();
    let settings = RecordSettings {
        split_intersections: !a.keep_intersections,
        ..RecordSettings::default()
    };
    let split = working_scene(
        &mut scene,
        &a.scene,
        &[rest_frame()],
        "its rest pose",
        &settings,
    )?;
    if let Some(r) = &split {
        if r.triangles_added > 0 {
            eprintln!(
                "trisort: split {} pairs of triangles that pass through each other (+{} triangles)",
                r.pairs_split + r.pairs_split_across_groups,
                r.triangles_added
            );
        }
    }
    // Copies placed, over all partitions' lists.
    let bar = progress_bar(0, "placed");
    let options = PresortOptions {
        partitions: a.partitions,
        reach: a.reach,
        strict: a.strict,
        ..PresortOptions::default()
    };
    let lists = presort(&scene.geometry, options, &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })
    .with_context(|| format!("presorting {}", a.scene))?;
    bar.finish_and_clear();
    let cycles = lists.cycles.clone();
    if let Some(c) = cycles.first() {
        eprintln!(
            "trisort: warning: {} copies left in occlusion cycles no cutting plane breaks (the \
             first: triangle {} before triangle {} in partition {}); frames from where they \
             overlap may draw them out of order: check with `trisort verify`, or refuse such \
             lists with --strict",
            cycles.len(),
            c.triangle,
            c.occluded,
            c.partition
        );
    }
    let mut file = lists.into_presorted(scene.geometry, environment, a.glass_opacity, scene_hash);
    file.stats.seconds = t0.elapsed().as_secs_f64();
    trisort_format::write_file_atomic(FileKind::Presorted, &a.output, &file)?;
    let s = &file.stats;
    let ratio = s.list_triangles as f64 / (s.sorted_triangles.max(1) as f64);
    if a.json {
        print_json(&json!({
            "triangles": s.triangles,
            "list_triangles": s.list_triangles,
            "partitions": file.segments.len(),
            "seconds": s.seconds,
            "sorted_triangles": s.sorted_triangles,
            "list_ratio": ratio,
            "per_partition_mean": s.list_triangles as f64 / file.segments.len() as f64,
            "duplicated": s.duplicated,
            "moved": s.moved,
            "regions": s.regions,
            "linear_programs": s.linear_programs,
            "planes": file.planes.len(),
            "unresolved_cycles": cycles.len(),
            "cycles": cycles.iter().map(|c| json!({
                "partition": c.partition,
                "triangle": c.triangle,
                "occluded": c.occluded,
            })).collect::<Vec<_>>(),
            "output": a.output,
        }));
    } else {
        println!(
            "presorted {}: {} triangles, {} need an order; {} partitions, {} copies in all \
             ({ratio:.2}× the sorted triangles, {:.0} a partition; {} duplicated, {} moved, \
             {} planes, {} unresolved cycles) in {:.2} s → {}",
            a.scene,
            s.triangles,
            s.sorted_triangles,
            file.segments.len(),
            s.list_triangles,
            s.list_triangles as f64 / file.segments.len() as f64,
            s.duplicated,
            s.moved,
            file.planes.len(),
            cycles.len(),
            s.seconds,
            a.output.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// Whether `path` is a presorted file (by its magic).
pub fn is_presorted(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && FileKind::sniff(&head) == Some(FileKind::Presorted)
}

/// Reads and checks a presorted file.
pub fn read(path: &Path) -> Result<Presorted> {
    let file: Presorted = trisort_format::read_file(FileKind::Presorted, path)?;
    file.check_structure()
        .map_err(|e| anyhow::anyhow!("{}: malformed presorted file: {e}", path.display()))?;
    Ok(file)
}

/// `N` random cameras outside `file`'s polyhedron (1.2 to 4 times its largest face distance
/// from the centre, in random directions; camera k in partition k mod the partitions), each
/// looking at the centre with the scene in view; deterministic for a seed.
pub fn random_views(file: &Presorted, n: u32, seed: u64) -> Vec<FrameState> {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let centre = DVec3::from(file.polyhedron.centre);
    let size = file
        .polyhedron
        .faces
        .iter()
        .map(|f| f[3])
        .fold(0.0, f64::max);
    let mut out = Vec::with_capacity(n as usize);
    let mut tries = 0u32;
    while out.len() < n as usize {
        tries += 1;
        let d = DVec3::new(next() * 2.0 - 1.0, next() * 2.0 - 1.0, next() * 2.0 - 1.0);
        if !(d.length() > 0.1 && d.length() <= 1.0) {
            continue;
        }
        let distance = size * (1.2 + 2.8 * next());
        let eye = centre + d.normalize() * distance;
        // Camera k in partition k mod faces, so that every list is drawn (on a flat scene
        // most directions leave through the top or bottom face).
        // (A partition no sampled camera reaches, after 10,000 tries, is given up for this one.)
        let wanted = out.len() % file.polyhedron.faces.len();
        match file.polyhedron.partition_of(eye.to_array()) {
            Ok(k) if k == wanted || tries > 10_000 => tries = 0,
            _ => continue,
        }
        let dir = (centre - eye).normalize();
        let up = if dir.y.abs() > 0.95 {
            DVec3::Z
        } else {
            DVec3::Y
        };
        out.push(FrameState {
            camera: Camera {
                view: DMat4::look_at_rh(eye, centre, up).to_cols_array(),
                yfov: 2.0 * (size / distance).min(0.95).asin(),
                znear: distance * 0.01,
                zfar: None,
            },
            poses: Vec::new(),
        });
    }
    out
}

/// The frames of `--path spec` over `file`: `random:N[:SEED]`, or any path spec the other
/// commands take (over the file's own scene).
pub fn frames_of(file: &Presorted, spec: &str, fps: f64) -> Result<Vec<FrameState>> {
    if let Some(rest) = spec.strip_prefix("random:") {
        let (n, seed) = rest.split_once(':').unwrap_or((rest, "1"));
        let n: u32 = n
            .parse()
            .ok()
            .filter(|&n| n > 0)
            .with_context(|| format!("--path {spec}: N must be a positive count"))?;
        let seed: u64 = seed
            .parse()
            .with_context(|| format!("--path {spec}: SEED must be a number"))?;
        return Ok(random_views(file, n, seed));
    }
    let scene = Scene {
        name: "presorted scene".into(),
        geometry: file.geometry.clone(),
        ..Scene::default()
    };
    let timeline = trisort_bake::load_path(spec, &scene, fps)?;
    Ok(timeline.frames)
}

/// `--test-stage`: where the half-space test selects a presorted file's copies.
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
pub enum StageArg {
    /// Per fragment, a fragment's copy by its primitive index (one indexed draw).
    #[default]
    Fragment,
    /// Per vertex, the list drawn from three vertices a copy, failing copies clipped away.
    Vertex,
}

impl From<StageArg> for trisort_reference::presorted::TestStage {
    fn from(s: StageArg) -> Self {
        match s {
            StageArg::Fragment => Self::Fragment,
            StageArg::Vertex => Self::Vertex,
        }
    }
}

/// How a presorted file is played or verified.
pub struct PresortedRun<'a> {
    /// The file.
    pub file: &'a Path,
    /// `--path`.
    pub path: Option<&'a str>,
    /// Image size.
    pub size: Option<(u32, u32)>,
    /// MSAA samples.
    pub samples: Option<u32>,
    /// Mode.
    pub mode: Mode,
    /// Frames, half-open.
    pub frames: Option<crate::common::FrameRange>,
    /// Glass opacity override.
    pub glass_opacity: Option<f32>,
    /// Shading.
    pub shading: Shading,
    /// Tone map.
    pub tone_map: ToneMap,
    /// JSON output.
    pub json: bool,
    /// Where the half-space test runs.
    pub stage: StageArg,
}

struct Loaded {
    file: Presorted,
    frames: Vec<FrameState>,
    range: std::ops::Range<u32>,
    view: View,
}

fn load(r: &PresortedRun<'_>) -> Result<Loaded> {
    let file = read(r.file)?;
    let Some(spec) = r.path else {
        bail!(
            "{}: a presorted file plays along any camera path: give one with --path (e.g. \
             --path orbit or --path random:64)",
            r.file.display()
        );
    };
    let frames = frames_of(&file, spec, 30.0)?;
    let n = frames.len() as u32;
    let range = match r.frames {
        Some(f) => f.resolve(n)?,
        None => 0..n,
    };
    let (w, h) = r.size.unwrap_or(RecordSettings::DEFAULT_SIZE);
    let view = View {
        width: w,
        height: h,
        samples: r.samples.unwrap_or(RecordSettings::DEFAULT_SAMPLES),
        glass_opacity: r.glass_opacity.unwrap_or(file.glass_opacity),
    };
    // Every frame of the path must be playable, not just the ones drawn: say which is not.
    trisort_reference::presorted::partitions_of(&file, &frames)
        .map_err(|e| anyhow::anyhow!("{}: --path {spec}: {e}", r.file.display()))?;
    Ok(Loaded {
        file,
        frames,
        range,
        view,
    })
}

fn renderer<'g>(gpu: &'g Gpu, l: &Loaded, r: &PresortedRun<'_>) -> Result<PresortedRenderer<'g>> {
    Ok(PresortedRenderer::with_stage(
        gpu,
        &l.file,
        &l.frames,
        l.view,
        Lighting {
            shading: r.shading,
            tone_map: r.tone_map,
            environment: &l.file.environment,
        },
        r.mode,
        r.stage.into(),
    )?)
}

/// `play FILE --path P` on a presorted file: PNG frames (with `out_dir`) and per-frame figures.
pub fn play(r: &PresortedRun<'_>, out_dir: Option<&Path>) -> Result<ExitCode> {
    let l = load(r)?;
    let gpu = crate::common::open_gpu()?;
    let renderer = renderer(&gpu, &l, r)?;
    if let Some(d) = out_dir {
        std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
    }
    let bar = progress_bar(l.range.len() as u64, "frames");
    let mut frames = Vec::new();
    for f in l.range.clone() {
        let t = Instant::now();
        let rgba = renderer.render(f)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        if let Some(d) = out_dir {
            trisort_reference::frames::write_png(
                &d.join(format!("frame-{f:05}.png")),
                l.view.width,
                l.view.height,
                &rgba,
            )?;
        }
        frames.push(json!({
            "frame": f,
            "partition": renderer.partition(f),
            "triangles": renderer.triangles(f),
            "wall_ms": ms,
        }));
        bar.inc(1);
    }
    bar.finish_and_clear();
    if r.json {
        print_json(&json!({
            "file": r.file,
            "kind": "presorted",
            "device": gpu.describe(),
            "size": [l.view.width, l.view.height],
            "samples": l.view.samples,
            "mode": r.mode.to_string(),
            "frames": frames,
        }));
    } else {
        println!(
            "played {} frames of {} on {} at {}x{}, {}x{}",
            frames.len(),
            r.file.display(),
            gpu.describe(),
            l.view.width,
            l.view.height,
            l.view.samples,
            out_dir.map_or(String::new(), |d| format!(" → {}", d.display()))
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `verify FILE --path P` on a presorted file: every frame against the exact reference of the
/// scene (`scene`, split as `presort` splits it; the file's own scene without it). At the
/// pattern both render, `depth` must be bit-exact and `blend`/`saturate` within 1/255 on every
/// pixel without an unordered sample: one where two sorted triangles that share a corner are
/// consecutive in the reference's peel (their depths there differ by rounding alone; the
/// pairs come from the reference's scene, not from the file).
pub fn verify(
    r: &PresortedRun<'_>,
    scene: Option<&str>,
    diff_dir: Option<(&Path, bool)>,
) -> Result<ExitCode> {
    let l = load(r)?;
    let geometry = reference_geometry(&l.file, r.file, scene)?;
    let gpu = crate::common::open_gpu()?;
    let renderer = renderer(&gpu, &l, r)?;
    let lighting = Lighting {
        shading: r.shading,
        tone_map: r.tone_map,
        environment: &l.file.environment,
    };
    let reference = ExactReference::new(
        &gpu,
        &geometry,
        &l.frames,
        lighting,
        ReferenceConfig {
            size: (l.view.width, l.view.height),
            samples: l.view.samples,
            mode: r.mode,
            glass_opacity: l.view.glass_opacity,
            max_layers: 4096,
        },
    )?;
    // Samples where two sorted triangles that meet (share a corner) are consecutive: their
    // depths there differ by rounding alone, so the rasterizer's order may not be the
    // geometric one the lists hold. Derived from the reference's scene, not from the file.
    let touching = touching_pairs(&geometry);
    let unordered = UnorderedEdges::of_pairs(geometry.triangles.len(), l.frames.len(), &touching)?;
    let bar = progress_bar(l.range.len() as u64, "verify");
    let mut ok = true;
    let mut frames = Vec::new();
    for f in l.range.clone() {
        let test = renderer.render(f)?;
        let truth = reference.render(f, Some(&unordered))?;
        let c = compare(
            &test,
            &truth.rgba8,
            l.view.width,
            l.view.height,
            &truth.unordered,
        );
        let pass = if r.mode == Mode::Depth {
            c.pixels_differing_ordered == 0
        } else {
            c.max_channel_diff_ordered <= 1
        };
        if let Some((dir, _)) = diff_dir.filter(|(_, all)| *all || !pass) {
            write_diff(dir, f, (l.view.width, l.view.height), &test, &truth.rgba8)?;
        }
        ok &= pass && !truth.truncated;
        frames.push(json!({
            "frame": f,
            "ok": pass,
            "partition": renderer.partition(f),
            "triangles": renderer.triangles(f),
            "unordered_samples": truth.unordered_samples,
            "pixels_differing": c.pixels_differing,
            "pixels_differing_ordered": c.pixels_differing_ordered,
            "max_channel_diff": c.max_channel_diff,
            "max_channel_diff_ordered": c.max_channel_diff_ordered,
            "psnr": c.psnr,
            "flip_mean": c.flip_mean,
            "truncated": truth.truncated,
        }));
        bar.inc(1);
    }
    bar.finish_and_clear();
    let failed = frames.iter().filter(|f| f["ok"] == false).count();
    if r.json {
        print_json(&json!({
            "ok": ok,
            "kind": "presorted",
            "device": gpu.describe(),
            "mode": r.mode.to_string(),
            "size": [l.view.width, l.view.height],
            "samples": l.view.samples,
            "reference_scene": scene.unwrap_or("the file's own"),
            "frames": frames,
        }));
    } else {
        println!(
            "{}: {} of {} frames {} in {} mode at {}x{}, {}x against the exact reference of {} \
             (every pixel without an unordered sample within {}; {} unordered samples)",
            r.file.display(),
            frames.len() - failed,
            frames.len(),
            if ok { "exact" } else { "checked" },
            r.mode,
            l.view.width,
            l.view.height,
            l.view.samples,
            scene.unwrap_or("the file's own scene"),
            if r.mode == Mode::Depth {
                "0 (bit-exact)"
            } else {
                "1/255"
            },
            frames
                .iter()
                .map(|f| f["unordered_samples"].as_u64().unwrap_or(0))
                .sum::<u64>()
        );
        for f in frames.iter().filter(|f| f["ok"] == false) {
            println!(
                "  frame {}: {} ordered pixels differ, largest {}/255",
                f["frame"], f["pixels_differing_ordered"], f["max_channel_diff_ordered"]
            );
        }
    }
    Ok(if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(super::verify::VERIFY_FAILED)
    })
}

/// `inspect FILE` of a presorted file: its figures and each partition's list.
pub fn inspect(path: &Path, as_json: bool) -> Result<ExitCode> {
    let file = read(path)?;
    let s = &file.stats;
    let partitions: Vec<serde_json::Value> = file
        .segments
        .iter()
        .zip(&file.polyhedron.faces)
        .map(|(seg, f)| {
            let copies = &file.copies[seg.first as usize..(seg.first + seg.count) as usize];
            json!({
                "copies": seg.count,
                "tested": copies.iter().filter(|c| c.tests > 0).count(),
                "normal": [f[0], f[1], f[2]],
            })
        })
        .collect();
    let v = json!({
        "kind": "presorted",
        "tool_version": file.tool_version,
        "triangles": s.triangles,
        "sorted_triangles": s.sorted_triangles,
        "list_triangles": s.list_triangles,
        "partitions": file.segments.len(),
        "duplicated": s.duplicated,
        "moved": s.moved,
        "planes": file.planes.len(),
        "seconds": s.seconds,
        "centre": file.polyhedron.centre,
        "reach": file.polyhedron.reach,
        "per_partition": partitions,
    });
    if as_json {
        print_json(&v);
    } else {
        println!(
            "{}: presorted file (paper 000), {} triangles ({} opaque drawn with the depth test, \
             {} sorted), {} partitions, {} copies ({} duplicated), {} planes; cameras outside \
             the polyhedron within {:.3} of ({:.3}, {:.3}, {:.3})",
            path.display(),
            s.triangles,
            file.opaque.len(),
            s.sorted_triangles,
            file.segments.len(),
            s.list_triangles,
            s.duplicated,
            file.planes.len(),
            file.polyhedron.reach,
            file.polyhedron.centre[0],
            file.polyhedron.centre[1],
            file.polyhedron.centre[2]
        );
        for (k, p) in partitions.iter().enumerate() {
            println!(
                "  partition {k}: {} copies, {} with tests",
                p["copies"], p["tested"]
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// What `play FILE --window` on a presorted file was asked for.
pub struct OrbitArgs<'a> {
    /// The file.
    pub file: &'a Path,
    /// Window size (default: 1280x480).
    pub size: Option<(u32, u32)>,
    /// MSAA samples (default 4).
    pub samples: Option<u32>,
    /// Mode.
    pub mode: Mode,
    /// Glass opacity (default: the file's).
    pub glass_opacity: Option<f32>,
    /// Shading.
    pub shading: Shading,
    /// Tone map.
    pub tone_map: ToneMap,
    /// Quit after this many presented frames.
    pub exit_after: Option<u64>,
    /// Print what was shown as JSON.
    pub json: bool,
    /// Where the half-space test runs.
    pub stage: StageArg,
}

/// `play FILE --window` on a presorted file: the free-viewpoint window
/// ([`trisort_viewer::orbit`]), a turntable the user can drag to orbit.
pub fn orbit_window(a: OrbitArgs<'_>) -> Result<ExitCode> {
    if !trisort_viewer::display_named() {
        bail!(super::window::NO_DISPLAY);
    }
    let file = read(a.file)?;
    let options = trisort_viewer::OrbitOptions {
        size: a.size.unwrap_or((1280, 480)),
        samples: a.samples.unwrap_or(RecordSettings::DEFAULT_SAMPLES),
        mode: a.mode,
        glass_opacity: a.glass_opacity,
        shading: a.shading,
        tone_map: a.tone_map,
        turntable_degrees: 1.5,
        exit_after: a.exit_after,
        stage: a.stage.into(),
    };
    let shown = trisort_viewer::orbit(a.file, file, options, &mut |line| {
        eprintln!("trisort: {line}")
    })
    .map_err(super::window::cli_error)?;
    if a.json {
        print_json(&json!({
            "file": a.file,
            "kind": "presorted",
            "device": shown.device,
            "presented": shown.presented,
            "partitions": shown.partitions,
            "last_camera": {"yaw": shown.last_camera[0], "pitch": shown.last_camera[1], "distance": shown.last_camera[2]},
        }));
    } else {
        println!(
            "showed {} frames of {} on {}, through partitions {:?}",
            shown.presented,
            a.file.display(),
            shown.device,
            shown.partitions
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// Frame `f`'s images where it was checked: `NNNNN-player.png` (the presorted renderer's),
/// `NNNNN-reference.png` and `NNNNN-diff.png` (differing pixels), as `verify --diff-dir`
/// writes them for baked files.
fn write_diff(dir: &Path, f: u32, size: (u32, u32), test: &[u8], truth: &[u8]) -> Result<()> {
    use trisort_reference::frames::write_png;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let (w, h) = size;
    write_png(&dir.join(format!("{f:05}-player.png")), w, h, test)?;
    write_png(&dir.join(format!("{f:05}-reference.png")), w, h, truth)?;
    let diff = trisort_reference::compare::difference_image(test, truth, &[]);
    write_png(&dir.join(format!("{f:05}-diff.png")), w, h, &diff)?;
    Ok(())
}

/// Pairs of triangles that need an order and share a corner (the same node and position):
/// where they meet, their depths differ by rounding alone.
fn touching_pairs(geometry: &trisort_format::Geometry) -> Vec<(u32, u32)> {
    use std::collections::{BTreeSet, HashMap};
    let mut at: HashMap<(u32, [u32; 3]), Vec<u32>> = HashMap::new();
    for t in 0..geometry.triangles.len() as u32 {
        if !geometry.needs_order(t) {
            continue;
        }
        for &v in &geometry.triangles[t as usize] {
            let vx = &geometry.vertices[v as usize];
            at.entry((vx.node, vx.position.map(f32::to_bits)))
                .or_default()
                .push(t);
        }
    }
    let mut pairs = BTreeSet::new();
    for ts in at.values() {
        for (i, &a) in ts.iter().enumerate() {
            for &b in &ts[i + 1..] {
                if a != b {
                    pairs.insert((a.min(b), a.max(b)));
                }
            }
        }
    }
    pairs.into_iter().collect()
}

/// The scene the reference renders: `scene` (which must be the one the file was made from)
/// split as `presort` splits it, or the file's own.
fn reference_geometry(
    file: &Presorted,
    path: &Path,
    scene: Option<&str>,
) -> Result<trisort_format::Geometry> {
    let Some(spec) = scene else {
        return Ok(file.geometry.clone());
    };
    let mut s = load_scene(spec)?;
    if s.hash() != file.scene_hash {
        bail!(
            "{}: made from another scene than {spec} (scene hashes differ)",
            path.display()
        );
    }
    working_scene(
        &mut s,
        spec,
        &[rest_frame()],
        "its rest pose",
        &RecordSettings::default(),
    )?;
    Ok(s.geometry)
}
