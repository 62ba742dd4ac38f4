//! The on-device self-check (`play --self-check`): does this device, at this size and sample
//! pattern, show a surface the baked frame leaves out?
//!
//! A bake is exact only at the sample pattern it was recorded at. On another rasterizer
//! (other sub-pixel precision or snapping), at another size, or with the projection shifted
//! ([`crate::Player::set_subpixel_offset`]), a triangle of the file that won no sample when
//! recorded can win one here; where the frame's window does not draw it, whatever lies behind
//! it shows through: a *hole* (the background or the car's interior where a body panel
//! should be).
//!
//! The check needs no scene and no reference renderer, only the baked file and the device the
//! host plays on. It plays each frame twice in `depth` mode (front to back, depth test `Less`):
//! 1. the frame as baked;
//! 2. a z-buffer of *every* triangle of the file: the frame's own window first, in its sorted
//!    order, then all of the file's triangles in id order ([`zbuffer_baked`]).
//!
//! In the second render every extra triangle passes the depth test only at samples where it is
//! strictly nearer than everything the frame's window drew there (a triangle the window already
//! drew lies at exactly the same depth, as every pipeline rasterizes invariant positions, and
//! fails `Less`). So the two frames agree bit for bit, whatever the materials' opacity, unless
//! a triangle the frame leaves out is the nearest surface at some sample: each differing pixel
//! is a hole. The check is blind to triangles that are not in the file at all (never visible
//! when recording); `verify --scene` against the exact reference measures those too.

#[cfg(not(target_arch = "wasm32"))]
use trisort_format::Mode;
use trisort_format::{Baked, DrawIndexedIndirectArgs, FrameWindow, Geometry};
#[cfg(not(target_arch = "wasm32"))]
use trisort_gpu::Gpu;

#[cfg(not(target_arch = "wasm32"))]
use crate::error::PlayerError;
#[cfg(not(target_arch = "wasm32"))]
use crate::headless::{HeadlessConfig, HeadlessRenderer};

/// The self-check of one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SelfCheckFrame {
    /// Frame index.
    pub frame: u32,
    /// Pixels where a triangle of the file that the frame does not draw is the nearest surface
    /// at some sample (they differ from the z-buffer of the file's triangles).
    pub holes: u64,
    /// Largest colour-channel difference at those pixels (1/255 units).
    pub max_channel_diff: u8,
}

/// A frame of the self-check as pictures ([`SelfCheck::images`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HoleImages {
    /// Per pixel (rows top to bottom): whether it is a hole.
    pub mask: Vec<bool>,
    /// The frame as baked, depth mode, 8-bit sRGB RGBA.
    pub played: Vec<u8>,
    /// The z-buffer of the file's triangles, depth mode, 8-bit sRGB RGBA.
    pub zbuffer: Vec<u8>,
}

/// `baked` with every frame's window followed by one more draw of every triangle of the file
/// in ascending id order: played front to back in `depth` mode, the z-buffer of all of the
/// file's triangles, agreeing with the frame as baked wherever no left-out triangle is nearer.
pub fn zbuffer_baked(baked: &Baked) -> Baked {
    with_zbuffer_draw(baked.clone(), None)
}

/// [`zbuffer_baked`] over every triangle of `scene`, the full scene the file was baked from
/// (materials, textures and nodes as the file's, which keeps all of them): the twin then
/// also shows triangles that never reached the file, so the differing pixels are every hole,
/// not only those of the file's own triangles. For measurements with the scene at hand
/// (`trisort bench`); a host on the target has only the file.
pub fn zbuffer_baked_with_scene(baked: &Baked, scene: &Geometry) -> Baked {
    with_zbuffer_draw(baked.clone(), Some(scene))
}

fn with_zbuffer_draw(mut b: Baked, scene: Option<&Geometry>) -> Baked {
    let first_index = 3 * b.copies.len() as u32;
    let first_new = b.geometry.triangles.len() as u32;
    let (appended, first_copy) = match scene {
        None => (first_new, 0),
        Some(scene) => {
            let base = b.geometry.vertices.len() as u32;
            b.geometry.vertices.extend_from_slice(&scene.vertices);
            b.geometry
                .triangles
                .extend(scene.triangles.iter().map(|t| t.map(|v| v + base)));
            // Ids past the file's own keep scene_ids strictly ascending; nothing reads them.
            let next = b.scene_ids.last().map_or(0, |&x| x + 1);
            b.scene_ids
                .extend((0..scene.triangles.len() as u32).map(|k| next + k));
            (scene.triangles.len() as u32, first_new)
        }
    };
    b.copies.extend(first_copy..first_copy + appended);
    let mut draws = Vec::with_capacity(b.draws.len() + b.frames.len());
    let mut frames = Vec::with_capacity(b.frames.len());
    for f in 0..b.frames.len() {
        let first = draws.len() as u32;
        draws.extend_from_slice(b.frame_draws(f));
        draws.push(DrawIndexedIndirectArgs {
            index_count: 3 * appended,
            instance_count: 1,
            first_index,
            base_vertex: 0,
            first_instance: 0,
        });
        frames.push(FrameWindow {
            first,
            count: draws.len() as u32 - first,
        });
    }
    b.draws = draws;
    b.frames = frames;
    b
}

/// Plays frames of a baked file and of its [`zbuffer_baked`] twin on one device and counts
/// the pixels where they differ: the holes (see the module documentation). Native only: a
/// browser plays the twin itself (the web player's `zbuffer` option) and compares the canvas.
#[cfg(not(target_arch = "wasm32"))]
pub struct SelfCheck<'g> {
    baked: HeadlessRenderer<'g>,
    zbuffer: HeadlessRenderer<'g>,
}

#[cfg(not(target_arch = "wasm32"))]
impl<'g> SelfCheck<'g> {
    /// Sets up the check of `baked` at `size` with `samples` MSAA samples (the recorded
    /// pattern: `(baked.settings.width, baked.settings.height)` and `baked.settings.samples`)
    /// on `gpu`, the device the host plays on. Errors as [`HeadlessRenderer::new`].
    pub fn new(
        gpu: &'g Gpu,
        baked: &Baked,
        size: (u32, u32),
        samples: u32,
    ) -> Result<SelfCheck<'g>, PlayerError> {
        Self::with_twin(gpu, baked, &zbuffer_baked(baked), size, samples)
    }

    /// [`SelfCheck::new`] against the z-buffer of every triangle of `scene`, the full scene
    /// the file was baked from ([`zbuffer_baked_with_scene`]): counts every hole, including
    /// triangles that never reached the file. For measurements (`trisort bench`).
    pub fn against_scene(
        gpu: &'g Gpu,
        baked: &Baked,
        scene: &Geometry,
        size: (u32, u32),
        samples: u32,
    ) -> Result<SelfCheck<'g>, PlayerError> {
        let twin = zbuffer_baked_with_scene(baked, scene);
        Self::with_twin(gpu, baked, &twin, size, samples)
    }

    /// The depth renders of `baked` and of its z-buffer `twin`, with one configuration.
    fn with_twin(
        gpu: &'g Gpu,
        baked: &Baked,
        twin: &Baked,
        size: (u32, u32),
        samples: u32,
    ) -> Result<SelfCheck<'g>, PlayerError> {
        let config = HeadlessConfig {
            size,
            samples,
            mode: Mode::Depth,
            ..HeadlessConfig::recorded(baked)
        };
        Ok(SelfCheck {
            baked: HeadlessRenderer::new(gpu, baked, &config)?,
            zbuffer: HeadlessRenderer::new(gpu, twin, &config)?,
        })
    }

    /// Shifts both renders' projection by `offset` pixels
    /// ([`crate::Player::set_subpixel_offset`]).
    pub fn set_subpixel_offset(&self, offset: [f64; 2]) {
        self.baked.set_subpixel_offset(offset);
        self.zbuffer.set_subpixel_offset(offset);
    }

    /// Checks frame `frame`. Errors where a frame is out of range or the device fails.
    pub fn check(&self, frame: u32) -> Result<SelfCheckFrame, PlayerError> {
        let played = self.baked.render(frame)?.rgba8;
        let zbuffer = self.zbuffer.render(frame)?.rgba8;
        let mut out = SelfCheckFrame {
            frame,
            holes: 0,
            max_channel_diff: 0,
        };
        for (a, b) in played.chunks_exact(4).zip(zbuffer.chunks_exact(4)) {
            let d = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
            if d > 0 {
                out.holes += 1;
                out.max_channel_diff = out.max_channel_diff.max(d);
            }
        }
        Ok(out)
    }

    /// The hole mask of frame `frame` with both renders, for pictures of the holes.
    pub fn images(&self, frame: u32) -> Result<HoleImages, PlayerError> {
        let played = self.baked.render(frame)?.rgba8;
        let zbuffer = self.zbuffer.render(frame)?.rgba8;
        let mask = played
            .chunks_exact(4)
            .zip(zbuffer.chunks_exact(4))
            .map(|(a, b)| a[..3] != b[..3])
            .collect();
        Ok(HoleImages {
            mask,
            played,
            zbuffer,
        })
    }
}
