//! Does this device rasterize as a bake's raster profile assumes ([`trisort_format::RasterProfile`])?
//! The player asks at load (`play --json`'s `profile_check`, `play --strict-profile`).
//!
//! Two sources, both used where both exist:
//! - **The API.** On Vulkan, the adapter's `subPixelPrecisionBits` and
//!   `standardSampleLocations` (through wgpu-hal). GL and WebGL2 are not asked here: wgpu does
//!   not expose `GL_SUBPIXEL_BITS`.
//! - **A raster probe**, on every backend: a 2048×2 target at the bake's sample count, where
//!   column k of row 0 holds a quad whose left edge lies k/2048 px into the pixel, and column k
//!   of row 1 one whose top edge does. The resolved coverage of each pixel counts the samples
//!   right of (below) the edge, so as the edge sweeps across the pixel in steps of 1/2048 px
//!   the count drops once per sample: where it drops tells the samples' x (y) positions
//!   *moved by the snapping of the edge's corners*. The probe then tries every sub-pixel
//!   precision from 4 to 16 bits, rounding to nearest (halves up or to even) and either tie
//!   rule for a sample on the edge, on the standard positions, and keeps the precisions that
//!   reproduce every count: those the device is consistent with (all of 11 to 16 bits look
//!   alike on a 1/2048 px sweep).
//!
//! What the probe does not see: how x and y pair up into samples (it compares the sets of x
//! and y positions), and where the device takes a sample's depth (the profile's `depth_at` is
//! taken on trust; the self-check and `verify --frames-dir` measure its effect).
//!
//! The probe draws with the same shift the player applies (`--subpixel-offset`), so a shifted
//! pattern shows up as a device off the profile.

// The probe draws only where wgpu runs natively (the web player checks its device with the
// page's self-check instead); on wasm32 its drawing helpers go unused.
#![cfg_attr(target_arch = "wasm32", allow(dead_code, unused_imports))]

use trisort_format::{RasterProfile, RecordSettings};
use wgpu::util::DeviceExt;

use crate::{Gpu, GpuError};

/// Steps of the sweep across a pixel (the target's width).
const STEPS: u32 = 2048;

/// Vulkan's and D3D's standard 4× sample locations within a pixel (x right, y down), sample
/// k at `[k]`.
pub const STANDARD_4X: [[f64; 2]; 4] = [
    [0.375, 0.125],
    [0.875, 0.375],
    [0.125, 0.625],
    [0.625, 0.875],
];

/// Sample `k`'s standard location within its pixel (x right, y down) at `samples` samples per
/// pixel (1 or 4, what trisort records).
pub fn standard_location(samples: u32, k: u32) -> [f64; 2] {
    if samples == 4 {
        STANDARD_4X[k as usize % 4]
    } else {
        [0.5, 0.5]
    }
}

/// The standard sample positions' x and y (each as a set, sorted) for a sample count.
pub fn standard_positions(samples: u32) -> (Vec<f64>, Vec<f64>) {
    let n = if samples == 4 { 4 } else { 1 };
    let (mut xs, mut ys): (Vec<f64>, Vec<f64>) = (0..n)
        .map(|k| {
            let [x, y] = standard_location(samples, k);
            (x, y)
        })
        .unzip();
    xs.sort_by(f64::total_cmp);
    ys.sort_by(f64::total_cmp);
    (xs, ys)
}

/// What the raster probe measured.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeResult {
    /// Sample count probed.
    pub samples: u32,
    /// Covered samples per step of the left-edge sweep (x) and the top-edge sweep (y).
    pub counts: [Vec<u8>; 2],
    /// Where the count drops, in pixels from the pixel's left (top) side, one entry per
    /// sample dropped: the samples' x (y) positions as the device sees them, moved by its
    /// snapping (up to half a grid step) and the sweep's step.
    pub drops: [Vec<f64>; 2],
    /// The sub-pixel precisions (bits, 4 to 16) that reproduce every count on the standard
    /// positions; empty where none does (the positions are not the standard ones).
    pub consistent_bits: Vec<u32>,
}

/// What the API says, where it can.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ApiRaster {
    /// Vulkan's `subPixelPrecisionBits`.
    pub subpixel_bits: Option<u32>,
    /// Vulkan's `standardSampleLocations`.
    pub standard_sample_locations: Option<bool>,
}

/// The device against a bake's profile: whether it satisfies it, and what differs.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileCheck {
    /// No difference found.
    pub ok: bool,
    /// Each difference in words, naming what the profile asks and what the device has.
    pub differences: Vec<String>,
    /// What the API reported.
    pub api: ApiRaster,
    /// What the probe measured.
    pub probe: ProbeResult,
}

/// Asks the API what it can say about rasterization (Vulkan only; `Default` elsewhere).
pub fn api_raster(gpu: &Gpu) -> ApiRaster {
    #[cfg(not(target_arch = "wasm32"))]
    {
        // SAFETY: the adapter is only read (its properties), never destroyed through the raw
        // handles, and the guard is dropped before returning.
        let hal = unsafe { gpu.adapter.as_hal::<wgpu::hal::api::Vulkan>() };
        if let Some(adapter) = hal {
            let instance = adapter.shared_instance().raw_instance();
            // SAFETY: a physical device of this instance, as wgpu-hal enumerated it.
            let props =
                unsafe { instance.get_physical_device_properties(adapter.raw_physical_device()) };
            return ApiRaster {
                subpixel_bits: Some(props.limits.sub_pixel_precision_bits),
                standard_sample_locations: Some(props.limits.standard_sample_locations != 0),
            };
        }
    }
    let _ = gpu;
    ApiRaster::default()
}

/// `t` snapped to a grid of 2^−bits px, rounding to nearest, halves up (`even`: to even).
fn snap(t: f64, bits: u32, even: bool) -> f64 {
    let scale = (1u64 << bits) as f64;
    let v = t * scale;
    let r = if even { v.round_ties_even() } else { v.round() };
    r / scale
}

/// The counts a device with samples at `positions`, snapping to `bits` bits, would give on the
/// sweep: samples at or after the snapped edge (`inclusive`), or strictly after it.
fn predicted(positions: &[f64], bits: u32, even: bool, inclusive: bool) -> Vec<u8> {
    (0..STEPS)
        .map(|k| {
            let edge = snap(k as f64 / STEPS as f64, bits, even);
            positions
                .iter()
                .filter(|&&s| if inclusive { s >= edge } else { s > edge })
                .count() as u8
        })
        .collect()
}

/// Where `counts` drops, one entry per sample dropped (pixels from the side).
fn drops(counts: &[u8]) -> Vec<f64> {
    let mut out = vec![];
    for k in 1..counts.len() {
        for _ in counts[k]..counts[k - 1] {
            out.push(k as f64 / STEPS as f64);
        }
    }
    out
}

/// The precisions from 4 to 16 bits whose predictions reproduce both sweeps on the standard
/// positions, under some rounding and tie rule.
fn consistent_bits(samples: u32, counts: &[Vec<u8>; 2]) -> Vec<u32> {
    let (xs, ys) = standard_positions(samples);
    (4..=16)
        .filter(|&bits| {
            [(&xs, &counts[0]), (&ys, &counts[1])]
                .iter()
                .all(|(pos, measured)| {
                    [false, true].iter().any(|&even| {
                        [true, false]
                            .iter()
                            .any(|&inc| predicted(pos, bits, even, inc) == **measured)
                    })
                })
        })
        .collect()
}

/// The probe's quads: per column k, row 0's from x = k + k/2048 (its left edge) to k + 1, and
/// row 1's from y = 1 + k/2048 (its top edge) to 2, in pixels moved by `offset`, as NDC.
fn probe_vertices(offset: [f64; 2]) -> Vec<[f32; 2]> {
    let (w, h) = (STEPS as f64, 2.0);
    let ndc = |x: f64, y: f64| {
        let (x, y) = (x + offset[0], y + offset[1]);
        [(2.0 * x / w - 1.0) as f32, (1.0 - 2.0 * y / h) as f32]
    };
    let mut v = Vec::with_capacity(STEPS as usize * 12);
    let mut quad = |x0: f64, y0: f64, x1: f64, y1: f64| {
        let (a, b, c, d) = (ndc(x0, y0), ndc(x1, y0), ndc(x1, y1), ndc(x0, y1));
        v.extend_from_slice(&[a, b, c, a, c, d]);
    };
    for k in 0..STEPS {
        let (x, t) = (k as f64, k as f64 / STEPS as f64);
        quad(x + t, 0.0, x + 1.0, 1.0);
        quad(x, 1.0 + t, x + 1.0, 2.0);
    }
    v
}

const PROBE_WGSL: &str = r#"
@vertex
fn vs(@location(0) p: vec2<f32>) -> @builtin(position) vec4<f32> {
    return vec4<f32>(p, 0.5, 1.0);
}

@fragment
fn fs() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0, 1.0, 1.0, 1.0);
}
"#;

#[cfg(not(target_arch = "wasm32"))]
/// Runs the raster probe at `samples` (1 or 4) with the projection moved by `offset` pixels
/// (x right, y down), as the player moves it.
pub fn probe(gpu: &Gpu, samples: u32, offset: [f64; 2]) -> Result<ProbeResult, GpuError> {
    let device = &gpu.device;
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let size = wgpu::Extent3d {
        width: STEPS,
        height: 2,
        depth_or_array_layers: 1,
    };
    let texture = |label, samples: u32, usage| {
        crate::pipeline::texture_2d(device, label, (STEPS, 2), samples, format, usage)
    };
    let resolved = texture(
        "raster probe resolved",
        1,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let msaa = (samples > 1).then(|| {
        texture(
            "raster probe",
            samples,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
    });
    let pipeline = probe_pipeline(device, samples, format);
    let vertices = probe_vertices(offset);
    let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("raster probe quads"),
        contents: bytemuck::cast_slice(&vertices),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let row = STEPS * 4;
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("raster probe readback"),
        size: (row * 2) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let resolved_view = resolved.create_view(&Default::default());
    let msaa_view = msaa.as_ref().map(|t| t.create_view(&Default::default()));
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let (view, resolve_target) = match &msaa_view {
            Some(v) => (v, Some(&resolved_view)),
            None => (&resolved_view, None),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("raster probe"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.set_vertex_buffer(0, buffer.slice(..));
        pass.draw(0..vertices.len() as u32, 0..1);
    }
    encoder.copy_texture_to_buffer(
        resolved.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(2),
            },
        },
        size,
    );
    gpu.queue.submit([encoder.finish()]);
    let bytes = crate::map_read_all(device, &[&staging])?.remove(0);
    // The resolve averages the samples: coverage c of n gives 255·c/n, rounded.
    let count = |r: u32| -> Vec<u8> {
        (0..STEPS)
            .map(|k| {
                let v = bytes[(r * row + 4 * k) as usize] as f64;
                (v * samples as f64 / 255.0).round() as u8
            })
            .collect()
    };
    let counts = [count(0), count(1)];
    Ok(ProbeResult {
        samples,
        drops: [drops(&counts[0]), drops(&counts[1])],
        consistent_bits: consistent_bits(samples, &counts),
        counts,
    })
}

#[cfg(not(target_arch = "wasm32"))]
/// The probe's pipeline: [`PROBE_WGSL`]'s white quads, position-only vertices, no depth, at
/// `samples` into `format`.
fn probe_pipeline(
    device: &wgpu::Device,
    samples: u32,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("raster probe"),
        source: wgpu::ShaderSource::Wgsl(PROBE_WGSL.into()),
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("raster probe"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 8,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x2],
            })],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState {
            count: samples,
            ..Default::default()
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The differences between what `profile` asks (with the recorded sample count) and what the
/// API and the probe found.
pub fn differences(
    profile: &RasterProfile,
    settings: &RecordSettings,
    api: &ApiRaster,
    probe: &ProbeResult,
) -> Vec<String> {
    let (lo, hi) = (profile.subpixel_bits_min, profile.subpixel_bits_max);
    let asked = profile.bits_text();
    let mut out = profile.device_differences(
        settings,
        api.subpixel_bits,
        api.standard_sample_locations,
        probe.samples,
    );
    let (xs, ys) = standard_positions(probe.samples);
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.4}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if probe.consistent_bits.is_empty() {
        out.push(format!(
            "sample positions: the probe's coverage steps at x = [{}], y = [{}] px fit the standard {}x positions (x [{}], y [{}]) at no sub-pixel precision from 4 to 16 bits",
            list(&probe.drops[0]),
            list(&probe.drops[1]),
            probe.samples,
            list(&xs),
            list(&ys)
        ));
    } else if !probe.consistent_bits.iter().any(|b| (lo..=hi).contains(b)) {
        let (a, b) = (
            probe.consistent_bits[0],
            *probe.consistent_bits.last().unwrap(),
        );
        let measured = if b >= 11 && a >= 11 {
            "at least 11".to_string()
        } else if a == b {
            format!("{a}")
        } else {
            format!("{a} to {b}")
        };
        out.push(format!(
            "sub-pixel precision: the probe measures {measured} bits, the profile `{}` asks {asked}",
            profile.name
        ));
    }
    out
}

#[cfg(not(target_arch = "wasm32"))]
/// Checks `gpu` against the raster profile of a bake recorded with `settings`, played at
/// `samples` with the projection moved by `offset` pixels: the API where it can say, and the
/// raster probe.
pub fn check_profile(
    gpu: &Gpu,
    settings: &RecordSettings,
    samples: u32,
    offset: [f64; 2],
) -> Result<ProfileCheck, GpuError> {
    let api = api_raster(gpu);
    let probe = probe(gpu, samples, offset)?;
    let differences = differences(&settings.robust.profile, settings, &api, &probe);
    Ok(ProfileCheck {
        ok: differences.is_empty(),
        differences,
        api,
        probe,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn predictions_tell_coarse_grids_apart_and_fine_ones_alike() {
        let (xs, _) = standard_positions(4);
        let p4 = predicted(&xs, 4, false, true);
        let p8 = predicted(&xs, 8, false, true);
        let p12 = predicted(&xs, 12, false, true);
        assert_ne!(p4, p8);
        assert_ne!(p8, p12);
        assert_eq!(p12, predicted(&xs, 16, false, true));
        // 8 bits: the sample at 0.125 drops once the edge snaps past it, half a 1/256 step on.
        let d = drops(&p8);
        assert_eq!(d.len(), 4);
        assert!(
            (d[0] - (0.125 + 1.0 / 512.0)).abs() <= 1.0 / 2048.0,
            "{d:?}"
        );
        assert_eq!(
            consistent_bits(4, &[p8.clone(), p8.clone()]),
            vec![8],
            "a device snapping to 8 bits"
        );
        // Moved by 1/64 px: no precision fits the standard positions.
        let shifted: Vec<f64> = xs.iter().map(|x| x + 1.0 / 64.0).collect();
        let s = predicted(&shifted, 8, false, true);
        assert!(consistent_bits(4, &[s, p8]).is_empty());
    }

    #[test]
    fn differences_name_what_the_profile_asks() {
        let settings = RecordSettings::default();
        let profile = settings.robust.profile;
        let (xs, ys) = standard_positions(4);
        let counts = [
            predicted(&xs, 4, false, true),
            predicted(&ys, 4, false, true),
        ];
        let probe = ProbeResult {
            samples: 4,
            drops: [drops(&counts[0]), drops(&counts[1])],
            consistent_bits: consistent_bits(4, &counts),
            counts,
        };
        assert_eq!(probe.consistent_bits, vec![4]);
        let d = differences(&profile, &settings, &ApiRaster::default(), &probe);
        assert_eq!(d.len(), 1, "{d:?}");
        assert!(
            d[0].contains("measures 4 bits") && d[0].contains("asks 8"),
            "{d:?}"
        );
        let api = ApiRaster {
            subpixel_bits: Some(4),
            standard_sample_locations: Some(false),
        };
        assert_eq!(differences(&profile, &settings, &api, &probe).len(), 3);
    }
}
