//! `trisort play BAKED`: headless playback to PNG frames.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;
use serde_json::json;
use trisort_format::{Baked, FileKind};
use trisort_gpu::{DeviceBackend, DeviceLimits, Gpu, GpuOptions, Shading, ToneMap};
use trisort_player::headless::{HeadlessConfig, RenderedFrame};
use trisort_player::{Mode, SelfCheck, SelfCheckFrame};

use trisort_reference::frames::{play_frames_to, PlayFrames, PlayedPath};

use crate::common::{
    parse_range, parse_size, parse_subpixel_offset, print_json, progress_bar, FrameRange,
};

/// Arguments of `play`.
#[derive(Args, Debug)]
pub struct PlayArgs {
    /// Baked file.
    baked: PathBuf,
    /// Frames to play, half-open `a..b` (default: all; with --clip, frames of the clip, 0 its
    /// first).
    #[arg(long, value_parser = parse_range)]
    frames: Option<FrameRange>,
    /// Play only clip NAME of a bundle (one of its camera paths; `inspect` lists them):
    /// --frames counts from the clip's first frame, the PNGs and `--json` frames are numbered
    /// within the clip, and --window starts at it and plays at its rate.
    #[arg(long, value_name = "NAME")]
    clip: Option<String>,
    /// Where to write PNG frames (`frame-NNNNN.png`; with --clip, numbered within the clip);
    /// none: render and time only.
    #[arg(long)]
    out_dir: Option<PathBuf>,
    /// Camera path of a presorted file (`trisort presort`), which plays along any path of
    /// cameras outside its bounding polyhedron: a path spec as `bake --path` takes, or
    /// `random:N[:SEED]` (N random cameras outside the polyhedron).
    #[arg(long, value_name = "P")]
    path: Option<String>,
    /// Playback size (default: the recorded size).
    #[arg(long, value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// MSAA samples (default: the recorded count).
    #[arg(long)]
    samples: Option<u32>,
    /// blend (back to front, no depth test), depth (front to back, depth test) or saturate.
    #[arg(long, default_value = "blend")]
    mode: Mode,
    /// Glass opacity (default: the recorded one).
    #[arg(long)]
    glass_opacity: Option<f32>,
    /// Where a presorted file's half-space test runs: fragment (default) or vertex.
    #[arg(long, value_enum)]
    test_stage: Option<super::presort::StageArg>,
    /// Open a window (needs X11 or Wayland) to play, pause, step and scrub.
    ///
    /// Keys: Space play/pause, Right/Left step, Home/End first/last frame, drag with the left
    /// button or 0-9 to scrub, Tab/C next clip (Shift: previous), F1-F9 clip 1-9, Escape/Q
    /// quit.
    #[arg(long)]
    window: bool,
    /// With --window: playback rate in frames per second (default: the path's, stored in the
    /// baked file, or the clip's; 30 for files that store none).
    #[arg(long, requires = "window")]
    fps: Option<f64>,
    /// Play the file's materials as material variant NAME (glTF KHR_materials_variants;
    /// `inspect` lists them): colours and textures change, the sorted order stays. Refused when
    /// the variant changes what decides visibility (alpha mode, alpha, cutoff, transmission,
    /// double-sidedness).
    #[arg(long, value_name = "NAME")]
    variant: Option<String>,
    /// With --window, for tests and automation: quit after presenting N frames and print how
    /// many were presented.
    #[arg(long, value_name = "N", requires = "window")]
    window_frames: Option<u64>,
    /// Print per-frame figures as JSON.
    #[arg(long)]
    json: bool,
    /// Shift the projection by X,Y pixels (x right, y down; decimals or fractions such as
    /// `1/16,0`): a test aid standing for another GPU's vertex snapping. The bake's order was
    /// recorded for the unshifted sample pattern.
    #[arg(long, value_name = "X,Y", value_parser = parse_subpixel_offset, allow_hyphen_values = true)]
    subpixel_offset: Option<[f64; 2]>,
    /// Also check every played frame for holes on this device: its depth-mode frame against a
    /// z-buffer of the baked file's own triangles (any differing pixel is a triangle of the
    /// file that the frame leaves out but that is the nearest surface here). Exit 3 when a
    /// frame has a hole; `--json` adds per frame `holes`.
    #[arg(long)]
    self_check: bool,
    /// Refuse to play on a device outside the bake's raster profile (`inspect`'s
    /// `raster_profile`): the sub-pixel precision the Vulkan API reports, and what a raster
    /// probe of sub-pixel test quads measures (the sample positions and the snapping). Without
    /// it such a device gets a warning naming what differs; `--json` has `profile_check`.
    #[arg(long)]
    strict_profile: bool,
    /// Upload block-compressed textures (a file baked with `--textures etc2|astc|bc7`) as
    /// their decoded RGBA8 texels even where the device samples the blocks: what a device
    /// without the compression feature draws, and allocates, for comparison (headless or
    /// `--window`). `--json`'s `texture_upload` says how each texture array was uploaded.
    #[arg(long)]
    decode_textures: bool,
    #[command(flatten)]
    shading: ShadingArgs,
    #[command(flatten)]
    device: DeviceArgs,
}

/// `--shading` and `--tonemap`: how `play` and `verify` light the scene (the player and the
/// reference alike), with the baked file's environment.
#[derive(Args, Debug, Clone, Copy)]
pub struct ShadingArgs {
    /// Surface model: pbr (glTF metallic-roughness, normal, occlusion, emissive maps and
    /// clearcoat, lit by the baked file's environment and sun, tone mapped) or basic (one
    /// light plus ambient, no tone map: what trisort drew before, and what the C host draws).
    #[arg(long, default_value = "pbr")]
    pub shading: Shading,
    /// Tone map of --shading pbr: neutral (Khronos PBR Neutral) or aces.
    #[arg(long, default_value = "neutral")]
    pub tonemap: ToneMap,
}

/// `--backend` and `--limits`: the device `play`, `verify` and `bench` open.
#[derive(Args, Debug, Clone, Copy)]
pub struct DeviceArgs {
    /// GPU backend: vulkan, gl (OpenGL/GLES; headless through EGL) or auto (wgpu's choice,
    /// `WGPU_BACKEND` where set).
    #[arg(long, default_value = "auto")]
    pub backend: DeviceBackend,
    /// Device limits: default (the adapter's) or webgl2 (WebGL2's: the player takes its
    /// GLES 3.0 / WebGL2 path, data-texture bindings and one draw per range, on any adapter).
    #[arg(long, default_value = "default")]
    pub limits: DeviceLimits,
}

impl DeviceArgs {
    /// The options to open the device with.
    pub fn options(self) -> GpuOptions {
        GpuOptions {
            backend: self.backend,
            limits: self.limits,
        }
    }
}

/// Renders frames of a baked file, optionally writing PNGs; prints the player's warnings.
pub fn play_frames(
    gpu: &Gpu,
    baked: &Baked,
    config: &HeadlessConfig,
    frames: std::ops::Range<u32>,
    out_dir: Option<&Path>,
) -> Result<Vec<RenderedFrame>> {
    let what = PlayFrames {
        baked,
        config,
        frames,
        out_dir,
        offset: [0.0, 0.0],
        variant: None,
        numbered_from: 0,
    };
    Ok(play_with_progress(gpu, what)?.0)
}

/// [`play_frames_to`] with a progress bar on stderr and the player's warnings printed.
fn play_with_progress(gpu: &Gpu, what: PlayFrames<'_>) -> Result<(Vec<RenderedFrame>, PlayedPath)> {
    let bar = progress_bar(what.frames.len() as u64, "play");
    let played = play_frames_to(gpu, what, |_| bar.inc(1))?;
    bar.finish_and_clear();
    for w in &played.1.warnings {
        eprintln!("trisort: warning: {w}");
    }
    Ok(played)
}

/// Checks the device against the bake's raster profile at `samples` with the projection moved
/// by `offset` ([`trisort_gpu::raster_probe::check_profile`]): a warning naming what differs,
/// or with `strict` an error.
pub fn check_profile(
    gpu: &trisort_gpu::Gpu,
    baked: &Baked,
    samples: u32,
    offset: [f64; 2],
    file: &std::path::Path,
    strict: bool,
) -> Result<trisort_gpu::raster_probe::ProfileCheck> {
    let check = trisort_gpu::raster_probe::check_profile(gpu, &baked.settings, samples, offset)
        .context("probing the device's rasterizer")?;
    if !check.ok {
        let what = format!(
            "{} is outside the raster profile `{}` that {} was baked for: {}",
            gpu.info.name,
            baked.settings.robust.profile.name,
            file.display(),
            check.differences.join("; ")
        );
        if strict {
            anyhow::bail!("--strict-profile: {what}");
        }
        eprintln!("trisort: warning: {what} (frames may show holes or order errors there)");
    }
    Ok(check)
}

pub fn run(a: PlayArgs) -> Result<ExitCode> {
    if super::presort::is_presorted(&a.baked) {
        if a.window {
            return super::presort::orbit_window(super::presort::OrbitArgs {
                file: &a.baked,
                size: a.size,
                samples: a.samples,
                mode: a.mode,
                glass_opacity: a.glass_opacity,
                shading: a.shading.shading,
                tone_map: a.shading.tonemap,
                exit_after: a.window_frames,
                json: a.json,
                stage: a.test_stage.unwrap_or_default(),
            });
        }
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
        return super::presort::play(&run, a.out_dir.as_deref());
    }
    if a.path.is_some() || a.test_stage.is_some() {
        anyhow::bail!(
            "{}: --path and --test-stage play presorted files; a baked file plays the path it \
             was baked for",
            a.baked.display()
        );
    }
    if a.window {
        return run_window(&a);
    }
    let baked: Baked = trisort_format::read_file(FileKind::Baked, &a.baked)?;
    baked
        .check_structure()
        .map_err(|e| anyhow::anyhow!("{}: malformed baked file: {e}", a.baked.display()))?;
    let clip = match &a.clip {
        Some(name) => Some(
            baked
                .clip(name)
                .map_err(|e| anyhow::anyhow!("{}: {e}", a.baked.display()))?,
        ),
        None => None,
    };
    // The frames played are the clip's (the whole file's without --clip); --frames and the
    // numbers reported count from its first frame.
    let (base, n) = clip.map_or((0, baked.frames.len() as u32), |c| (c.first, c.count));
    let range = match a.frames {
        Some(r) => r.resolve(n)?,
        None => 0..n,
    };
    let range = range.start + base..range.end + base;
    let config = headless_config(&a, &baked);
    let gpu = crate::common::open_gpu_with(a.device.options())?;
    let offset = a.subpixel_offset.unwrap_or([0.0, 0.0]);
    let profile = check_profile(
        &gpu,
        &baked,
        config.samples,
        offset,
        &a.baked,
        a.strict_profile,
    )?;
    if offset != [0.0, 0.0] {
        eprintln!(
            "trisort: warning: projection shifted by ({}, {}) px: the sorted order was recorded for the unshifted sample pattern",
            offset[0], offset[1]
        );
    }
    let what = PlayFrames {
        baked: &baked,
        config: &config,
        frames: range.clone(),
        out_dir: a.out_dir.as_deref(),
        offset,
        variant: a.variant.as_deref(),
        numbered_from: base,
    };
    let (frames, path) =
        play_with_progress(&gpu, what).with_context(|| format!("playing {}", a.baked.display()))?;
    let checks = if a.self_check {
        Some(self_check_frames(&gpu, &baked, &config, offset, range)?)
    } else {
        None
    };
    let holes: u64 = checks.iter().flatten().map(|c| c.holes).sum();
    let played = Played {
        gpu: &gpu,
        config: &config,
        frames: &frames,
        clip,
        path,
        checks: checks.as_deref(),
        holes,
    };
    if a.json {
        print_play_json(&a, &baked, &played, offset, &profile);
    } else {
        print_play_text(&a, &played);
    }
    if holes > 0 {
        return Ok(ExitCode::from(super::verify::VERIFY_FAILED));
    }
    Ok(ExitCode::SUCCESS)
}

/// `play --window`: refuses the headless-only options, then hands over to the viewer.
fn run_window(a: &PlayArgs) -> Result<ExitCode> {
    if a.device.options() != GpuOptions::default() {
        anyhow::bail!("--backend and --limits apply to headless playback, not --window");
    }
    if a.subpixel_offset.is_some() || a.self_check {
        anyhow::bail!(
            "--subpixel-offset and --self-check apply to headless playback, not --window"
        );
    }
    super::window::run(super::window::WindowArgs {
        baked: &a.baked,
        frames: a.frames,
        size: a.size,
        samples: a.samples,
        mode: a.mode,
        glass_opacity: a.glass_opacity,
        fps: a.fps,
        variant: a.variant.clone(),
        clip: a.clip.clone(),
        shading: a.shading,
        exit_after: a.window_frames,
        json: a.json,
        strict_profile: a.strict_profile,
        decode_textures: a.decode_textures,
    })
}

/// The headless playback settings: the recorded ones with the command line's overrides.
fn headless_config(a: &PlayArgs, baked: &Baked) -> HeadlessConfig {
    let mut config = HeadlessConfig::recorded(baked);
    config.mode = a.mode;
    config.glass_opacity = a.glass_opacity;
    config.shading = a.shading.shading;
    config.tone_map = a.shading.tonemap;
    config.decode_textures = a.decode_textures;
    if let Some(s) = a.size {
        config.size = s;
    }
    if let Some(s) = a.samples {
        config.samples = s;
    }
    config
}

/// `--self-check`: every frame of `range` checked for holes on this device.
fn self_check_frames(
    gpu: &Gpu,
    baked: &Baked,
    config: &HeadlessConfig,
    offset: [f64; 2],
    range: std::ops::Range<u32>,
) -> Result<Vec<SelfCheckFrame>> {
    let check = SelfCheck::new(gpu, baked, config.size, config.samples)?;
    check.set_subpixel_offset(offset);
    let bar = progress_bar(range.len() as u64, "self-check");
    let mut out = Vec::with_capacity(range.len());
    for f in range {
        out.push(check.check(f)?);
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(out)
}

/// What a headless `play` did, for its report.
struct Played<'a> {
    gpu: &'a Gpu,
    config: &'a HeadlessConfig,
    /// The frames, numbered within the clip played (the file's frames without `--clip`).
    frames: &'a [RenderedFrame],
    /// The clip played (`--clip`).
    clip: Option<&'a trisort_format::Clip>,
    path: PlayedPath,
    /// Per-frame self-check results (with `--self-check`).
    checks: Option<&'a [SelfCheckFrame]>,
    /// Hole pixels over all checked frames.
    holes: u64,
}

/// `play --json`: the device, how it played and per-frame figures.
fn print_play_json(
    a: &PlayArgs,
    baked: &Baked,
    p: &Played<'_>,
    offset: [f64; 2],
    profile: &trisort_gpu::raster_probe::ProfileCheck,
) {
    let list: Vec<_> = p
        .frames
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let mut v = json!({"frame": f.frame, "gpu_ms": f.gpu_ms});
            if let Some(c) = p.checks.map(|c| c[k]) {
                v["holes"] = json!(c.holes);
                v["holes_max_channel_diff"] = json!(c.max_channel_diff);
            }
            v
        })
        .collect();
    let mut v = json!({
        "device": p.gpu.info.name,
        "backend": format!("{:?}", p.gpu.info.backend),
        "bindings": p.path.bindings,
        "draw_path": p.path.draw_path,
        "mode": a.mode.name(),
        "shading": p.config.shading.name(),
        "tonemap": p.config.tone_map.name(),
        "texture_bytes": p.path.texture_bytes,
        // What the player created, counted where it was created (`inspect`'s `gpu_bytes`
        // budgets it).
        "gpu_bytes_allocated": super::inspect::gpu_bytes_json(&p.path.gpu_bytes_allocated),
        // How each material texture array was uploaded: `bc7`, `etc2-rgb8`, `etc2-rgba8`,
        // `astc-4x4` (the file's blocks, sampled by the device), `rgba8`, or `rgba8 (decoded
        // from etc2)` (without the device's compression feature, or with --decode-textures).
        "texture_upload": {
            "srgb": p.path.texture_uploads[0].name(),
            "linear": p.path.texture_uploads[1].name(),
        },
        // Creating the player and waiting for its uploads, in milliseconds.
        "load_ms": p.path.load_ms,
        "variant": a.variant,
        // The clip played (`--clip`; null: the file's frames, numbered as in the file).
        "clip": p.clip.map(|c| &c.name),
        "subpixel_offset": offset,
        "profile_check": trisort_bake::figures::profile_check_json(baked, profile),
        "frames": list,
    });
    if p.checks.is_some() {
        v["self_check"] = json!({"ok": p.holes == 0, "holes": p.holes});
    }
    print_json(&v);
}

/// `play` without `--json`: timing, where the frames went and the self-check's holes.
fn print_play_text(a: &PlayArgs, p: &Played<'_>) {
    let ms: Vec<f64> = p.frames.iter().filter_map(|f| f.gpu_ms).collect();
    let timing = if ms.is_empty() {
        "no GPU timestamps on this adapter".to_string()
    } else {
        format!(
            "GPU {:.3} ms per frame mean, {:.3} max",
            ms.iter().sum::<f64>() / ms.len() as f64,
            ms.iter().cloned().fold(0.0, f64::max)
        )
    };
    println!(
        "played {} frames{} ({} mode) on {} ({:?}; {} bindings, {} draws): {timing}",
        p.frames.len(),
        p.clip
            .map_or(String::new(), |c| format!(" of clip {}", c.name)),
        a.mode.name(),
        p.gpu.info.name,
        p.gpu.info.backend,
        p.path.bindings,
        p.path.draw_path
    );
    let allocated = &p.path.gpu_bytes_allocated;
    println!(
        "GPU memory allocated: {} bytes (buffers {}, textures {}; texture arrays sRGB {}, linear {})",
        allocated.total(),
        allocated.buffers(),
        allocated.textures(),
        p.path.texture_uploads[0].name(),
        p.path.texture_uploads[1].name()
    );
    if let Some(d) = &a.out_dir {
        println!("wrote {}", d.display());
    }
    if let Some(checks) = p.checks {
        let bad: Vec<_> = checks.iter().filter(|c| c.holes > 0).collect();
        println!(
            "self-check ({}x{}, {}x MSAA, depth mode, against a z-buffer of the file's own triangles): {} holes in {} of {} frames",
            p.config.size.0,
            p.config.size.1,
            p.config.samples,
            p.holes,
            bad.len(),
            checks.len()
        );
        for c in bad.iter().take(20) {
            println!(
                "  frame {}: {} hole pixels (max {}/255)",
                c.frame - p.clip.map_or(0, |c| c.first),
                c.holes,
                c.max_channel_diff
            );
        }
    }
}
