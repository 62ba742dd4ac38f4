//! WGSL and GPU setup shared by trisort's recorder, player and reference.
//!
//! Every pipeline's shader is [`COMMON`] followed by its own entry points, so all of them use
//! the one vertex transform (`transform_position`) and the one surface function
//! (`surface_base`, `shade`), and mark `@builtin(position)` `@invariant`: the recorder, the
//! player and the reference rasterize bit-identical positions. WGSL has no includes, so
//! [`compose`] concatenates.
#![deny(missing_docs)]

pub mod gpu;
pub mod scene_gpu;

/// The shared bindings, vertex layout, vertex transform and surface functions.
pub const COMMON: &str = include_str!("wgsl/common.wgsl");

/// Entry points of the GPU smoke test (one triangle through the shared transform).
pub const SMOKE: &str = include_str!("wgsl/smoke.wgsl");

/// Every shader of the crate by name, composed and ready to compile (used by the naga test).
pub fn all() -> Vec<(&'static str, String)> {
    vec![("smoke", compose(&[], SMOKE))]
}

/// Composes a module: `enable` directives first (WGSL requires them before any declaration),
/// then [`COMMON`], then `body`.
pub fn compose(enables: &[&str], body: &str) -> String {
    let mut s = String::new();
    for e in enables {
        s.push_str(&format!("enable {e};\n"));
    }
    s.push_str(COMMON);
    s.push('\n');
    s.push_str(body);
    s
}

/// Size in bytes of the `Frame` uniform of [`COMMON`].
pub const FRAME_UNIFORM_SIZE: u64 = 64 + 16 + 16;
/// Size in bytes of one `MaterialGpu` of [`COMMON`].
pub const MATERIAL_SIZE: u64 = 64;
