//! Frames as images: a range of frames played to PNGs ([`play_frames_to`]), and image
//! verification of a range of frames, each played here, read from PNGs drawn elsewhere, or
//! played on another device, checked against the exact reference ([`ImageVerifier`]), with
//! difference images for the frames that fail.

use std::ops::Range;
use std::path::{Path, PathBuf};

use trisort_format::{Baked, Geometry, Recording};
use trisort_gpu::Gpu;
use trisort_player::headless::{HeadlessConfig, HeadlessRenderer, RenderedFrame};

use crate::compare::{difference_image, mask_image};
use crate::{FrameImageReport, ImageCheck, ImageVerifier, ReferenceError, VerifiedFrame};

/// Why a range of frames could not be verified (a frame that is wrong is not an error: its
/// report says so).
#[derive(Debug, thiserror::Error)]
pub enum FramesError {
    /// The verifier could not be built.
    #[error(transparent)]
    Reference(#[from] ReferenceError),
    /// A frame could not be played, rendered or compared.
    #[error("verifying frame {frame}: {source}")]
    Frame {
        /// The frame.
        frame: u32,
        /// Why.
        source: ReferenceError,
    },
    /// A frame drawn elsewhere is missing, unreadable or of the wrong size.
    #[error("{}: {problem}", .path.display())]
    Captured {
        /// The PNG.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// The other device's player failed.
    #[error(transparent)]
    Player(#[from] trisort_player::PlayerError),
    /// Writing an image failed.
    #[error("{}: {problem}", .path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// What failed.
        problem: String,
    },
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

/// Where the checked frames come from.
#[derive(Clone, Copy)]
pub enum Frames<'a> {
    /// Played here by the player on the verifying device.
    Play,
    /// Drawn elsewhere: PNGs in a directory (`--frames-dir`), frame `f` in the file named
    /// `frame-NNNNN.png` with NNNNN = `f` − the second field (the first frame of the clip
    /// played, as `play --clip NAME --out-dir` numbers them; 0 for the whole file).
    Dir(&'a Path, u32),
    /// Played on another device (`--backend`/`--limits`), one frame at a time as it is
    /// checked.
    Elsewhere(&'a HeadlessRenderer<'a>),
}

/// What [`verify_images`] checks: the file, the full scene's geometry its reference renders,
/// the recordings that decide which pixels may be unordered (may be empty: then none), the
/// frames and where they come from.
pub struct FramesToVerify<'a> {
    /// The baked file.
    pub baked: &'a Baked,
    /// The scene as recorded (split where the recording split it).
    pub geometry: &'a Geometry,
    /// Size, samples, mode, tolerance.
    pub check: ImageCheck,
    /// The recordings: their cycles excuse pixels, and they give the reference its path.
    pub recordings: &'a [Recording],
    /// The frames checked.
    pub frames: Range<u32>,
    /// Where they come from (`check.captured` must be set unless [`Frames::Play`]).
    pub source: Frames<'a>,
}

/// Verifies the frames `what` names against the exact reference, calling `each` with every
/// verified frame (for difference images and progress).
pub fn verify_images(
    gpu: &Gpu,
    what: FramesToVerify<'_>,
    mut each: impl FnMut(&VerifiedFrame) -> Result<(), FramesError>,
) -> Result<ImageReport, FramesError> {
    let check = what.check;
    let verifier = ImageVerifier::new(gpu, what.baked, what.geometry, check, what.recordings)?;
    let mut report = ImageReport {
        ok: true,
        at_recorded_pattern: verifier.at_recorded_pattern(),
        on_other_device: verifier.on_other_device(),
        frames: Vec::with_capacity(what.frames.len()),
    };
    for f in what.frames {
        let v = match what.source {
            Frames::Play => verifier.verify(f),
            Frames::Dir(dir, base) => {
                verifier.verify_captured(f, read_captured(dir, f, base, check.size)?)
            }
            Frames::Elsewhere(player) => player
                .render(f)
                .map_err(ReferenceError::from)
                .and_then(|r| verifier.verify_captured(f, r.rgba8)),
        }
        .map_err(|source| FramesError::Frame { frame: f, source })?;
        each(&v)?;
        report.ok &= v.report.ok;
        report.frames.push(v.report);
    }
    Ok(report)
}

/// Frame `f` as drawn elsewhere: `DIR/frame-NNNNN.png` with NNNNN = `f − base` (the name
/// `play --out-dir` gives it; with `--clip`, numbered within the clip that starts at frame
/// `base`), which must be `size`, as RGBA8. A missing, unreadable or wrong-size file is an
/// error naming it.
fn read_captured(dir: &Path, f: u32, base: u32, size: (u32, u32)) -> Result<Vec<u8>, FramesError> {
    let path = dir.join(format!("frame-{:05}.png", f - base));
    let captured = |problem: String| FramesError::Captured {
        path: path.clone(),
        problem,
    };
    if !path.is_file() {
        return Err(captured(format!(
            "frame {f}{} is missing (--frames-dir holds one PNG per checked frame, named \
             frame-NNNNN.png as play --out-dir writes them)",
            if base == 0 {
                String::new()
            } else {
                format!(" (frame {} of the clip)", f - base)
            }
        )));
    }
    let image = image::open(&path)
        .map_err(|e| captured(format!("not a readable image: {e}")))?
        .to_rgba8();
    if image.dimensions() != size {
        return Err(captured(format!(
            "the image is {}x{}, the frames are checked at {}x{} (the recorded size, or --size)",
            image.width(),
            image.height(),
            size.0,
            size.1
        )));
    }
    Ok(image.into_raw())
}

/// PNG bytes of an RGBA8 image (what [`write_png`] writes; the HTML report embeds them).
pub fn encode_png(rgba8: &[u8], width: u32, height: u32) -> Result<Vec<u8>, image::ImageError> {
    let mut bytes = Vec::new();
    image::write_buffer_with_format(
        &mut std::io::Cursor::new(&mut bytes),
        rgba8,
        width,
        height,
        image::ExtendedColorType::Rgba8,
        image::ImageFormat::Png,
    )?;
    Ok(bytes)
}

/// Writes an RGBA8 image as PNG atomically.
pub fn write_png(path: &Path, width: u32, height: u32, rgba8: &[u8]) -> Result<(), FramesError> {
    let write = |problem: String| FramesError::Write {
        path: path.to_path_buf(),
        problem,
    };
    let bytes = encode_png(rgba8, width, height).map_err(|e| write(format!("encoding: {e}")))?;
    trisort_format::container::write_bytes_atomic(path, &bytes).map_err(|e| write(e.to_string()))
}

/// Writes frame `v`'s player image, reference image, difference and unordered mask as
/// `NNNNN-player.png`, `-reference.png`, `-diff.png` and `-unordered.png` into `dir`.
pub fn write_diff(dir: &Path, v: &VerifiedFrame, size: (u32, u32)) -> Result<(), FramesError> {
    std::fs::create_dir_all(dir).map_err(|e| FramesError::Write {
        path: dir.to_path_buf(),
        problem: format!("creating: {e}"),
    })?;
    let f = v.report.frame;
    let (w, h) = size;
    let r = &v.reference;
    write_png(&dir.join(format!("{f:05}-player.png")), w, h, &v.player)?;
    write_png(&dir.join(format!("{f:05}-reference.png")), w, h, &r.rgba8)?;
    let diff = difference_image(&v.player, &r.rgba8, &r.unordered);
    write_png(&dir.join(format!("{f:05}-diff.png")), w, h, &diff)?;
    let mask = mask_image(&r.unordered);
    write_png(&dir.join(format!("{f:05}-unordered.png")), w, h, &mask)
}

/// What [`play_frames_to`] plays: frames of a baked file at `config`, the projection moved
/// by `offset` pixels, with material variant `variant` (`None`: the default materials),
/// written as `frame-NNNNN.png` into `out_dir` when given.
pub struct PlayFrames<'a> {
    /// The baked file.
    pub baked: &'a Baked,
    /// Size, samples, mode, shading.
    pub config: &'a HeadlessConfig,
    /// The frames.
    pub frames: Range<u32>,
    /// Where to write the PNGs (created if missing).
    pub out_dir: Option<&'a Path>,
    /// Sub-pixel shift of the projection, in pixels.
    pub offset: [f64; 2],
    /// Material variant.
    pub variant: Option<&'a str>,
    /// The file frame numbered 0 (a clip's first frame; 0 for the file's own numbering):
    /// frame `f` is written as `frame-NNNNN.png` and comes back as frame NNNNN = `f −
    /// numbered_from`, so a clip of a bundle plays to the names a bake of its path alone does.
    pub numbered_from: u32,
}

/// How [`play_frames_to`] played: the player's binding tier, draw path, texture bytes and
/// warnings.
#[derive(Clone, Debug)]
pub struct PlayedPath {
    /// `storage` or `textures` (`trisort_gpu::Bindings::name`).
    pub bindings: &'static str,
    /// `multi-draw-indirect` or `direct` (`trisort_player::DrawPath::name`).
    pub draw_path: &'static str,
    /// GPU bytes of the scene's textures and environment (`SceneGpu::texture_bytes`).
    pub texture_bytes: u64,
    /// Every buffer and texture the player created, by kind
    /// (`trisort_player::Player::gpu_bytes_allocated`).
    pub gpu_bytes_allocated: trisort_gpu::scene_gpu::GpuBytes,
    /// How the player uploaded its sRGB and linear texture arrays
    /// (`trisort_player::Player::texture_uploads`).
    pub texture_uploads: [trisort_gpu::scene_gpu::ArrayUpload; 2],
    /// Milliseconds the player took to load: creating it (every buffer, texture and the
    /// pipeline) and waiting until the GPU has its uploads.
    pub load_ms: f64,
    /// The player's warnings (e.g. a size other than the recorded one).
    pub warnings: Vec<String>,
}

/// Plays `what`'s frames with the player, writing each as PNG when asked, and calls `each`
/// after every frame. The frames come back without their pixels (which are in the PNGs),
/// with their timings. One untimed render comes first: the first draw compiles pipelines
/// (about 150 ms on lavapipe), which is not playback cost.
pub fn play_frames_to(
    gpu: &Gpu,
    what: PlayFrames<'_>,
    mut each: impl FnMut(u32),
) -> Result<(Vec<RenderedFrame>, PlayedPath), FramesError> {
    let started = std::time::Instant::now();
    let renderer = HeadlessRenderer::new(gpu, what.baked, what.config)?;
    gpu.queue.submit([]);
    let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
    let load_ms = started.elapsed().as_secs_f64() * 1e3;
    renderer.set_subpixel_offset(what.offset);
    renderer.set_variant(what.variant)?;
    let player = renderer.player();
    let path = PlayedPath {
        bindings: player.bindings().name(),
        draw_path: player.config().draw_path.name(),
        texture_bytes: player.texture_bytes(),
        gpu_bytes_allocated: player.gpu_bytes_allocated().clone(),
        texture_uploads: player.texture_uploads().clone(),
        load_ms,
        warnings: player.warnings().to_vec(),
    };
    if let Some(d) = what.out_dir {
        std::fs::create_dir_all(d).map_err(|e| FramesError::Write {
            path: d.to_path_buf(),
            problem: format!("creating: {e}"),
        })?;
    }
    if !what.frames.is_empty() {
        renderer.render(what.frames.start)?;
    }
    let (w, h) = what.config.size;
    let mut out = Vec::with_capacity(what.frames.len());
    for f in what.frames {
        let r = renderer.render(f)?;
        let local = f - what.numbered_from;
        if let Some(d) = what.out_dir {
            write_png(&d.join(format!("frame-{local:05}.png")), w, h, &r.rgba8)?;
        }
        each(f);
        out.push(RenderedFrame {
            frame: local,
            rgba8: Vec::new(),
            ..r
        });
    }
    Ok((out, path))
}

/// The player of `baked` on `gpu` set up as `check` plays: its size, samples, mode, shading,
/// tone map and sub-pixel shift (for frames played on another device and then checked as
/// captured ones).
pub fn checked_player<'g>(
    gpu: &'g Gpu,
    baked: &Baked,
    check: &ImageCheck,
) -> Result<HeadlessRenderer<'g>, FramesError> {
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
    Ok(player)
}
