//! The run-time rivals that render the whole scene every frame: per-sample linked-list OIT
//! and GPU depth peeling (both in `trisort-reference`).

use trisort_format::{FrameState, Geometry};
use trisort_gpu::{Gpu, Lighting};
use trisort_player::Mode;
use trisort_reference::{OitConfig, OitRenderer, PeelingConfig, PeelingRenderer};

use crate::methods::{BenchView, Method, Stream};
use crate::BenchError;

/// The `oit` method: [`OitRenderer`], per-sample linked lists.
pub struct OitMethod<'g> {
    gpu: &'g Gpu,
    renderer: OitRenderer<'g>,
    all: Vec<u32>,
}

impl<'g> OitMethod<'g> {
    /// Uploads the whole scene with the default fragment budget, lit by `environment`.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        environment: &trisort_format::Environment,
        view: BenchView,
    ) -> Result<OitMethod<'g>, BenchError> {
        let config = OitConfig {
            glass_opacity: view.glass_opacity,
            ..OitConfig::new(view.size, view.samples)
        };
        let renderer = OitRenderer::new(gpu, geometry, frames, Lighting::pbr(environment), config)?;
        Ok(OitMethod {
            gpu,
            renderer,
            all: geometry.triangles.iter().flatten().copied().collect(),
        })
    }
}

impl Method for OitMethod<'_> {
    fn name(&self) -> &str {
        "oit"
    }
    fn mode(&self) -> Mode {
        Mode::Blend
    }
    fn gpu(&self) -> &Gpu {
        self.gpu
    }
    fn variant(&self) -> String {
        self.renderer.config().describe()
    }
    fn triangles(&self, _frame: u32) -> u64 {
        self.renderer.triangles()
    }
    fn draws(&self, _frame: u32) -> u32 {
        1
    }
    fn stat_slots(&self, _frame: u32) -> u32 {
        self.renderer.passes()
    }
    fn encode(&self, enc: &mut wgpu::CommandEncoder, frame: u32, stats: Option<&wgpu::QuerySet>) {
        self.renderer.encode(enc, frame, stats);
    }
    fn image(&self, frame: u32) -> Result<Vec<u8>, BenchError> {
        Ok(self.renderer.render(frame)?.rgba8)
    }
    fn streams(&self, _frame: u32) -> Vec<Stream> {
        vec![Stream {
            indices: self.all.clone(),
            depth: None,
            repeat: 1,
            per_sample: true,
        }]
    }
}

/// The `peeling` method: [`PeelingRenderer`], exact depth peeling on the GPU with as many
/// passes as the frame needs (found before timing).
pub struct PeelingMethod<'g> {
    gpu: &'g Gpu,
    renderer: PeelingRenderer<'g>,
    mode: Mode,
    all: Vec<u32>,
}

impl<'g> PeelingMethod<'g> {
    /// Uploads the whole scene; `mode` is `blend` or `depth`.
    pub fn new(
        gpu: &'g Gpu,
        geometry: &Geometry,
        frames: &[FrameState],
        environment: &trisort_format::Environment,
        view: BenchView,
        mode: Mode,
        max_layers: u32,
    ) -> Result<PeelingMethod<'g>, BenchError> {
        let config = PeelingConfig {
            glass_opacity: view.glass_opacity,
            ..PeelingConfig::new(view.size, view.samples, mode, max_layers)
        };
        let renderer =
            PeelingRenderer::new(gpu, geometry, frames, Lighting::pbr(environment), config)?;
        Ok(PeelingMethod {
            gpu,
            renderer,
            mode,
            all: geometry.triangles.iter().flatten().copied().collect(),
        })
    }

    fn layers(&self, frame: u32) -> u32 {
        self.renderer.layers(frame).unwrap_or(1)
    }
}

impl Method for PeelingMethod<'_> {
    fn name(&self) -> &str {
        "peeling"
    }
    fn mode(&self) -> Mode {
        self.mode
    }
    fn gpu(&self) -> &Gpu {
        self.gpu
    }
    fn variant(&self) -> String {
        "back-to-front per-sample (depth, id) peel + per-pixel composite per layer; layer count found before timing".into()
    }
    fn prepare(&self, frame: u32) -> Result<(), BenchError> {
        self.renderer.layers(frame)?;
        Ok(())
    }
    // Each layer is two geometry passes over every triangle: the per-sample peel pass (ids
    // and depths) and the per-pixel compositing pass.
    fn triangles(&self, frame: u32) -> u64 {
        2 * self.renderer.triangles() * self.layers(frame) as u64
    }
    fn draws(&self, frame: u32) -> u32 {
        2 * self.layers(frame)
    }
    fn stat_slots(&self, frame: u32) -> u32 {
        self.layers(frame)
    }
    fn encode(&self, enc: &mut wgpu::CommandEncoder, frame: u32, stats: Option<&wgpu::QuerySet>) {
        self.renderer.encode(enc, frame, self.layers(frame), stats);
    }
    fn image(&self, frame: u32) -> Result<Vec<u8>, BenchError> {
        Ok(self.renderer.render(frame)?.rgba8)
    }
    fn streams(&self, frame: u32) -> Vec<Stream> {
        let layers = self.layers(frame);
        vec![
            Stream {
                indices: self.all.clone(),
                depth: None,
                repeat: layers,
                per_sample: true,
            },
            Stream {
                indices: self.all.clone(),
                depth: None,
                repeat: layers,
                per_sample: false,
            },
        ]
    }
}

/// Builds the `oit` or `peeling` method of a group (`None` for the other kinds).
pub(crate) fn build<'g>(
    kind: crate::table::MethodKind,
    gpu: &'g Gpu,
    input: &crate::table::GroupInput<'_>,
    progress: &dyn Fn(&str),
) -> Result<Option<Box<dyn Method + 'g>>, BenchError> {
    use crate::table::MethodKind;
    Ok(match kind {
        MethodKind::Oit => {
            progress("building oit (per-sample linked lists)");
            Some(Box::new(OitMethod::new(
                gpu,
                input.geometry,
                input.frame_states,
                &input.baked.environment,
                input.view,
            )?))
        }
        MethodKind::Peeling => {
            progress("building peeling");
            Some(Box::new(PeelingMethod::new(
                gpu,
                input.geometry,
                input.frame_states,
                &input.baked.environment,
                input.view,
                input.mode,
                input.baked.settings.max_layers.max(1),
            )?))
        }
        _ => None,
    })
}
