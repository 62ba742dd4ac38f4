//! [`GpuBudget`]: the GPU memory a [`Player`](crate::Player) allocates for a baked file, worked
//! out without a device (`inspect BAKED`) or for one (the player creates exactly this).

use trisort_format::{Baked, DrawIndexedIndirectArgs};
use trisort_gpu::scene_gpu::budget::buffer_size;
use trisort_gpu::scene_gpu::{
    scene_budget, ArrayUpload, Bindings, BudgetConfig, GpuBytes, GpuKind, SceneBudget,
};

use crate::commands::{command_count, index_format};

/// The GPU bytes a player of a baked file allocates, by kind: the scene's
/// ([`trisort_gpu::scene_gpu::scene_budget`]: vertices, per-frame uniforms and node matrices,
/// materials, lighting, the two texture arrays with their mips, the environment) and the
/// player's own index and indirect buffers. [`crate::Player`] sizes its buffers from it.
#[derive(Clone, Debug, PartialEq)]
pub struct GpuBudget {
    /// The device figures and tier it was worked out for.
    pub config: BudgetConfig,
    /// The index buffer's format (u16 where every vertex index fits).
    pub index_format: wgpu::IndexFormat,
    /// Layers of the sRGB and the linear texture array.
    pub layers: [u32; 2],
    /// Level 0 size and levels of the sRGB and the linear texture array.
    pub arrays: [(u32, u32, u32); 2],
    /// How the sRGB and the linear texture array are uploaded: RGBA8, or their members'
    /// blocks where the device has the compression feature ([`SceneBudget::uploads`]).
    pub texture_uploads: [ArrayUpload; 2],
    /// Bytes by kind.
    pub bytes: GpuBytes,
}

impl GpuBudget {
    /// The budget of `baked` on a device `config` describes, with 32-bit indices where
    /// `force_u32` ([`crate::Player::new_u32`]).
    pub fn new(baked: &Baked, config: BudgetConfig, force_u32: bool) -> GpuBudget {
        let scene = scene_budget(
            &baked.geometry,
            baked.frame_states.len(),
            &baked.environment,
            config,
        );
        GpuBudget::from_scene(&scene, baked, force_u32)
    }

    /// The budget of a player of `baked` whose scene has budget `scene` (the player's
    /// [`trisort_gpu::scene_gpu::SceneGpu::budget`]): its bytes, the index buffer in
    /// [`index_format`] and the indirect buffer.
    pub fn from_scene(scene: &SceneBudget, baked: &Baked, force_u32: bool) -> GpuBudget {
        let mut bytes = scene.bytes.clone();
        let index_format = index_format(baked, force_u32);
        let index_size = index_format.byte_size() as u64;
        bytes.add_buffer(
            GpuKind::Indices,
            buffer_size(baked.copies.len() as u64 * 3 * index_size),
        );
        let args = std::mem::size_of::<DrawIndexedIndirectArgs>() as u64;
        bytes.add_buffer(
            GpuKind::Indirect,
            buffer_size(command_count(baked).max(1) as u64 * args),
        );
        GpuBudget {
            config: scene.config,
            index_format,
            layers: scene.layers,
            arrays: [&scene.arrays.srgb, &scene.arrays.linear]
                .map(|a| (a.width, a.height, a.levels)),
            texture_uploads: scene.uploads.clone(),
            bytes,
        }
    }

    /// [`GpuBudget::new`] for a device with WebGPU's default limits on tier `bindings`
    /// ([`BudgetConfig::portable`]), which samples every block format: what `inspect` reports.
    pub fn portable(baked: &Baked, bindings: Bindings) -> GpuBudget {
        GpuBudget::new(baked, BudgetConfig::portable(bindings), false)
    }

    /// [`GpuBudget::portable`] on a device without texture compression (or played with
    /// [`crate::PlayerConfig::decode_textures`]): block-compressed textures uploaded decoded,
    /// as RGBA8 (`inspect`'s `textures_decoded`).
    pub fn portable_decoded(baked: &Baked, bindings: Bindings) -> GpuBudget {
        GpuBudget::new(baked, BudgetConfig::portable(bindings).decoded(), false)
    }
}
