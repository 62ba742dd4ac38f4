//! The per-frame `Frame` uniform (projection, light, view size, view-to-world rotation), the
//! `Lighting` uniform of a scene's light, and every frame's uniforms and camera-relative node
//! matrices laid out at the device's dynamic-offset strides.

use bytemuck::{Pod, Zeroable};
use trisort_format::{Environment, FrameState, Geometry, Shading, ToneMap};

use super::View;

/// The `Frame` uniform of the shared WGSL.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniform {
    /// Projection matrix.
    pub proj: [[f32; 4]; 4],
    /// View-space light direction (xyz) and ambient (w) of [`Shading::Basic`].
    pub light: [f32; 4],
    /// Glass opacity, width, height, sample count.
    pub params: [f32; 4],
    /// Columns (xyz) of the view-to-world rotation: environment lookups are in world space.
    pub view_to_world: [[f32; 4]; 3],
}

/// The `Lighting` uniform of the shared WGSL (binding 7).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightingUniform {
    /// Irradiance / π, spherical harmonics (rgb).
    pub sh: [[f32; 4]; 9],
    /// World direction towards the sun (xyz), 1 with a sun (w).
    pub sun_direction: [f32; 4],
    /// Sun radiance.
    pub sun_color: [f32; 4],
    /// Exposure, shading (0 basic, 1 pbr), tone map (0 neutral, 1 ACES), last mip level.
    pub params: [f32; 4],
}

/// The pipeline-overridable constants that specialise a pipeline's surface function to
/// `shading` (`SHADING_MODEL` in `shaders/common/common.wgsl`), so it compiles only this model's code; for
/// the fragment stage of pipelines whose module includes the common WGSL. Without them the
/// model is chosen at run time from the lighting uniform.
pub fn shading_constants(shading: Shading) -> &'static [(&'static str, f64)] {
    match shading {
        Shading::Basic => &[("SHADING_MODEL", 0.0)],
        Shading::Pbr => &[("SHADING_MODEL", 1.0)],
    }
}

/// How a scene is lit: the surface model, the tone map and the environment (a baked file's
/// [`trisort_format::Baked::environment`], so every player of it lights alike).
#[derive(Clone, Copy, Debug)]
pub struct Lighting<'a> {
    /// Surface model.
    pub shading: Shading,
    /// Tone map (for [`Shading::Pbr`]).
    pub tone_map: ToneMap,
    /// Environment and sun.
    pub environment: &'a Environment,
}

impl Default for Lighting<'static> {
    /// [`Shading::Pbr`], [`ToneMap::Neutral`], under a uniform environment of radiance 1 and no
    /// sun (`Environment::uniform(1.0)`, what a bake without another environment stores).
    fn default() -> Lighting<'static> {
        static UNIFORM: std::sync::LazyLock<Environment> =
            std::sync::LazyLock::new(|| Environment::uniform(1.0));
        Lighting {
            shading: Shading::Pbr,
            tone_map: ToneMap::Neutral,
            environment: &UNIFORM,
        }
    }
}

impl<'a> Lighting<'a> {
    /// [`Shading::Pbr`] with [`ToneMap::Neutral`] under `environment`.
    pub fn pbr(environment: &'a Environment) -> Lighting<'a> {
        Lighting {
            shading: Shading::Pbr,
            tone_map: ToneMap::Neutral,
            environment,
        }
    }
}

impl LightingUniform {
    /// The uniform for `lighting`, whose prefiltered radiance was uploaded with `levels` mip
    /// levels.
    pub fn new(lighting: &Lighting<'_>, levels: u32) -> LightingUniform {
        let env = lighting.environment;
        let mut sh = [[0.0; 4]; 9];
        for (d, s) in sh.iter_mut().zip(&env.sh) {
            *d = [s[0], s[1], s[2], 0.0];
        }
        let (sun_direction, sun_color) = match &env.sun {
            Some(sun) => {
                let d = glam::Vec3::from(sun.direction).normalize_or_zero();
                (
                    [d.x, d.y, d.z, if d == glam::Vec3::ZERO { 0.0 } else { 1.0 }],
                    [sun.color[0], sun.color[1], sun.color[2], 0.0],
                )
            }
            None => ([0.0; 4], [0.0; 4]),
        };
        LightingUniform {
            sh,
            sun_direction,
            sun_color,
            params: [
                env.exposure,
                match lighting.shading {
                    Shading::Basic => 0.0,
                    Shading::Pbr => 1.0,
                },
                match lighting.tone_map {
                    ToneMap::Neutral => 0.0,
                    ToneMap::Aces => 1.0,
                },
                levels.saturating_sub(1) as f32,
            ],
        }
    }
}

/// The view-space light of [`Shading::Basic`]: towards upper left behind the viewer; ambient
/// 0.35.
pub const LIGHT: [f32; 4] = [-0.3, 0.6, 0.75, 0.35];

fn align(x: u64, a: u64) -> u64 {
    x.div_ceil(a) * a
}

/// A frame's projection in f64 at a view's aspect ratio.
pub(super) fn projection(state: &FrameState, view: View) -> glam::DMat4 {
    let aspect = view.width as f64 / view.height as f64;
    state.camera.projection(aspect)
}

/// The clip-space translation that moves the image by `offset` pixels (x right, y down) at
/// `view`'s size: x_clip += 2·dx/width · w_clip, y_clip −= 2·dy/height · w_clip (NDC y points
/// up, pixel rows down).
pub fn subpixel_shift(offset: [f64; 2], view: View) -> glam::DMat4 {
    glam::DMat4::from_translation(glam::DVec3::new(
        2.0 * offset[0] / view.width.max(1) as f64,
        -2.0 * offset[1] / view.height.max(1) as f64,
        0.0,
    ))
}

/// The `Frame` uniform for one frame at a view.
pub fn frame_uniform(state: &FrameState, view: View) -> FrameUniform {
    let proj = projection(state, view).as_mat4();
    let rotation = glam::DMat3::from_mat4(state.camera.view_matrix());
    let to_world = if rotation.determinant().abs() > 1e-300 {
        rotation.inverse()
    } else {
        glam::DMat3::IDENTITY
    }
    .as_mat3();
    let column = |c: glam::Vec3| [c.x, c.y, c.z, 0.0];
    FrameUniform {
        proj: proj.to_cols_array_2d(),
        light: LIGHT,
        params: [
            view.glass_opacity,
            view.width as f32,
            view.height as f32,
            view.samples as f32,
        ],
        view_to_world: [
            column(to_world.x_axis),
            column(to_world.y_axis),
            column(to_world.z_axis),
        ],
    }
}

/// Every frame's uniform and node matrices, each frame at its stride (the device's dynamic
/// offset alignments).
pub(crate) struct FrameData {
    pub(crate) frame_bytes: Vec<u8>,
    pub(crate) node_bytes: Vec<u8>,
    pub(crate) frame_stride: u64,
    pub(crate) node_stride: u64,
    pub(crate) node_count: u64,
}

/// Computes [`FrameData`]: camera-relative node matrices in f64, cast once.
pub(super) fn frame_data(
    limits: &wgpu::Limits,
    geometry: &Geometry,
    frames: &[FrameState],
    view: View,
    node_align: u64,
) -> FrameData {
    let frame_stride = align(
        std::mem::size_of::<FrameUniform>() as u64,
        limits.min_uniform_buffer_offset_alignment as u64,
    );
    let node_count = geometry.nodes.len().max(1) as u64;
    let node_stride = align(node_count * 64, node_align);
    let nframes = frames.len().max(1) as u64;
    let mut frame_bytes = vec![0u8; (frame_stride * nframes) as usize];
    let mut node_bytes = vec![0u8; (node_stride * nframes) as usize];
    for (f, state) in frames.iter().enumerate() {
        let u = frame_uniform(state, view);
        frame_bytes[f * frame_stride as usize..][..std::mem::size_of::<FrameUniform>()]
            .copy_from_slice(bytemuck::bytes_of(&u));
        let mats = trisort_format::camera::node_view_matrices(&geometry.nodes, state);
        let m: Vec<[f32; 16]> = mats.iter().map(|m| m.to_cols_array()).collect();
        let b: &[u8] = bytemuck::cast_slice(&m);
        node_bytes[f * node_stride as usize..][..b.len()].copy_from_slice(b);
    }
    FrameData {
        frame_bytes,
        node_bytes,
        frame_stride,
        node_stride,
        node_count,
    }
}
