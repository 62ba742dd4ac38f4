//! The run-time rivals that render the whole scene every frame: per-sample linked-list OIT
//! and GPU depth peeling (both in `trisort-reference`).

use trisort_format::{FrameState, Geometry};
use trisort_gpu::{Gpu, Lighting};
use trisort_player::Mode;
use trisort_reference::presorted::TestStage;
use trisort_reference::{
    OitConfig, OitRenderer, PeelingConfig, PeelingRenderer, PresortedRenderer,
};

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

/// Builds the `oit`, `peeling`, `presorted` (with `presorted_vertex`, its vertex-stage
/// variant) or `occlusion-query` methods of a group (none for the other kinds).
pub(crate) fn build<'g>(
    kind: crate::table::MethodKind,
    gpu: &'g Gpu,
    input: &crate::table::GroupInput<'_>,
    progress: &dyn Fn(&str),
) -> Result<Vec<Box<dyn Method + 'g>>, BenchError> {
    use crate::table::MethodKind;
    if kind == MethodKind::Presorted {
        progress(if input.presorted.is_some() {
            "building presorted (paper 000) from --presorted"
        } else {
            "presorting (paper 000, 6 partitions)"
        });
        let mut out: Vec<Box<dyn Method + 'g>> = Vec::new();
        for stage in [TestStage::Fragment, TestStage::Vertex] {
            out.push(Box::new(PresortedMethod::new(gpu, input, stage)?));
        }
        return Ok(out);
    }
    let method: Option<Box<dyn Method + 'g>> = match kind {
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
        MethodKind::OcclusionQuery => {
            progress("building occlusion-query (paper 004)");
            Some(Box::new(crate::vis_sort::OcclusionQueryMethod::new(
                gpu,
                input.geometry,
                input.frame_states,
                &input.baked.environment,
                input.view,
            )?))
        }
        _ => None,
    };
    Ok(method.into_iter().collect())
}

/// The `presorted` method (paper 000): the scene presorted for free viewpoints
/// ([`trisort_presort`], 6 partitions), drawn by [`PresortedRenderer`]: the opaque triangles
/// with the depth test, then the camera's partition's list in one draw with the fragment-stage
/// half-space test. It needs no bake, only cameras outside the scene's bounding polyhedron.
pub struct PresortedMethod<'g> {
    gpu: &'g Gpu,
    mode: Mode,
    stage: TestStage,
    file: trisort_format::Presorted,
    renderer: PresortedRenderer<'g>,
    target: trisort_gpu::FrameTarget,
}

impl<'g> PresortedMethod<'g> {
    /// Presorts the group's scene (6 partitions; or takes its `--presorted` file) and uploads
    /// it for its frames, testing in `stage`; errors where a camera is inside the polyhedron
    /// or the presort finds no order.
    pub fn new(
        gpu: &'g Gpu,
        input: &crate::table::GroupInput<'_>,
        stage: TestStage,
    ) -> Result<PresortedMethod<'g>, BenchError> {
        let (geometry, frames, view, mode) =
            (input.geometry, input.frame_states, input.view, input.mode);
        let environment = &input.baked.environment;
        // A path this method cannot draw (a camera inside the polyhedron, a moving node) or a
        // scene it cannot order leaves it out of the table, saying why.
        let unsupported = |why: String| {
            BenchError::Reference(trisort_reference::ReferenceError::Unsupported(why))
        };
        let file = match input.presorted {
            // The file's scene must be the bench's, triangle for triangle (the same scene
            // split at the same pose): the reference is rendered from the bench's.
            Some(f) => {
                if let Some(why) = crate::methods::presorted_mismatch(f, geometry) {
                    return Err(BenchError::Invalid(format!("--presorted: {why}")));
                }
                f.clone()
            }
            None => presorted_once(geometry, environment, view.glass_opacity)
                .map_err(|e| unsupported(format!("presorting: {e}")))?,
        };
        trisort_reference::presorted::partitions_of(&file, frames)
            .map_err(|e| unsupported(e.to_string()))?;
        let renderer = PresortedRenderer::with_stage(
            gpu,
            &file,
            frames,
            view.view(),
            Lighting::pbr(environment),
            mode,
            stage,
        )?;
        let target = trisort_gpu::FrameTarget::new(
            &gpu.adapter,
            &gpu.device,
            trisort_gpu::TargetConfig {
                depth: true,
                ..trisort_gpu::TargetConfig::readback(view.size, view.samples, mode)
            },
        )?;
        Ok(PresortedMethod {
            gpu,
            mode,
            stage,
            file,
            renderer,
            target,
        })
    }
}

impl Method for PresortedMethod<'_> {
    fn name(&self) -> &str {
        match self.stage {
            TestStage::Fragment => "presorted",
            TestStage::Vertex => "presorted_vertex",
        }
    }
    fn mode(&self) -> Mode {
        self.mode
    }
    fn gpu(&self) -> &Gpu {
        self.gpu
    }
    fn variant(&self) -> String {
        let s = &self.file.stats;
        format!(
            "paper 000, {} partitions, {} copies for {} sorted triangles, {}-stage test",
            self.file.segments.len(),
            s.list_triangles,
            s.sorted_triangles,
            match self.stage {
                TestStage::Fragment => "fragment",
                TestStage::Vertex => "vertex",
            }
        )
    }
    fn triangles(&self, frame: u32) -> u64 {
        self.renderer.triangles(frame) as u64
    }
    fn draws(&self, _frame: u32) -> u32 {
        self.renderer.draws()
    }
    fn stat_slots(&self, _frame: u32) -> u32 {
        1
    }
    fn encode(&self, enc: &mut wgpu::CommandEncoder, frame: u32, stats: Option<&wgpu::QuerySet>) {
        let mut pass = self
            .target
            .begin_pass(enc, trisort_gpu::clear_colour(self.mode), None);
        crate::methods::stats_begin(&mut pass, stats, 0);
        self.renderer.draw(&mut pass, frame);
        crate::methods::stats_end(&mut pass, stats);
    }
    fn image(&self, frame: u32) -> Result<Vec<u8>, BenchError> {
        Ok(self
            .target
            .read_rgba8(self.gpu, self.mode, |enc| self.encode(enc, frame, None))?)
    }
    fn streams(&self, frame: u32) -> Vec<Stream> {
        let g = &self.file.geometry;
        let opaque: Vec<u32> = self
            .file
            .opaque
            .iter()
            .flat_map(|&t| g.triangles[t as usize])
            .collect();
        let list: Vec<u32> = self
            .renderer
            .partition(frame)
            .map(|k| {
                let s = self.file.segments[k];
                self.file.copies[s.first as usize..(s.first + s.count) as usize]
                    .iter()
                    .flat_map(|c| g.triangles[c.triangle as usize])
                    .collect()
            })
            .unwrap_or_default();
        vec![
            Stream {
                indices: opaque,
                depth: Some(true),
                repeat: 1,
                per_sample: false,
            },
            Stream {
                indices: list,
                depth: Some(false),
                repeat: 1,
                per_sample: false,
            },
        ]
    }
}

/// The presort of `geometry`, made once per process: a bench's groups (sample counts, modes)
/// share one scene, and presorting it takes seconds.
fn presorted_once(
    geometry: &Geometry,
    environment: &trisort_format::Environment,
    glass_opacity: f32,
) -> Result<trisort_format::Presorted, trisort_presort::PresortError> {
    use std::sync::{Mutex, OnceLock};
    type Memo = Mutex<Vec<(trisort_format::Hash, trisort_format::Presorted)>>;
    static MEMO: OnceLock<Memo> = OnceLock::new();
    let mut bytes: Vec<u8> = bytemuck::cast_slice(&geometry.vertices).to_vec();
    bytes.extend_from_slice(bytemuck::cast_slice(&geometry.triangles));
    bytes.extend_from_slice(&glass_opacity.to_le_bytes());
    let key = trisort_format::hash_bytes(&bytes);
    let memo = MEMO.get_or_init(|| Mutex::new(Vec::new()));
    if let Some((_, f)) = memo.lock().unwrap().iter().find(|(k, _)| *k == key) {
        return Ok(f.clone());
    }
    let lists = trisort_presort::presort(geometry, Default::default(), &|_, _| {})?;
    let file = lists.into_presorted(
        geometry.clone(),
        environment.clone(),
        glass_opacity,
        [0; 32],
    );
    memo.lock().unwrap().push((key, file.clone()));
    Ok(file)
}
