//! WGSL and GPU setup shared by trisort's recorder, player and reference.
//!
//! Every pipeline's shader is [`COMMON`] followed by its own entry points, so all of them use
//! the one vertex transform (`transform_position`) and the one surface function
//! (`surface_base`, `shade`), and mark `@builtin(position)` `@invariant`: the recorder, the
//! player and the reference rasterize bit-identical positions. WGSL has no includes, so
//! [`compose`] concatenates.
#![deny(missing_docs)]

pub mod device;
pub use device::{device_info, wanted_features, Gpu, GpuError, REQUIRE_GPU_ENV};
pub mod scene_gpu;

/// The shared bindings, vertex layout, vertex transform and surface functions.
pub const COMMON: &str = include_str!("wgsl/common.wgsl");

/// Entry points of the GPU smoke test (one triangle through the shared transform).
pub const SMOKE: &str = include_str!("wgsl/smoke.wgsl");

/// Entry points of the player (`vs_player`, `fs_player_straight`, `fs_player_premultiplied`).
pub const PLAYER: &str = include_str!("wgsl/player.wgsl");

/// The exact reference's compositing entry points (`fs_reference_straight`,
/// `fs_reference_premultiplied`); compose with [`reference_shader`].
pub const REFERENCE: &str = include_str!("wgsl/reference.wgsl");

/// The complete shader of the exact reference's compositing passes: [`COMMON`], the player's
/// [`PLAYER`] entry points and the reference's own (needs `Features::PRIMITIVE_INDEX`). The
/// reference draws with `vs_player` and shades with the player's `player_colour`.
pub fn reference_shader() -> String {
    compose(&["primitive_index"], &format!("{PLAYER}\n{REFERENCE}"))
}

/// Depth peeling entry points (`vs_peel`, `fs_peel`); compose with [`peel_shader`].
pub const PEEL: &str = include_str!("wgsl/peel.wgsl");

/// The compute pass that gathers a peel layer per sample; compose with [`gather_shader`].
pub const GATHER: &str = include_str!("wgsl/gather.wgsl");

/// The id texture type, the depth texture type and the sample argument of a `textureLoad` at
/// sample `sample`, for a sample count: multisampled textures for `samples > 1`, plain ones
/// (and sample 0) for a single sample.
fn sample_types(samples: u32) -> (&'static str, &'static str, &'static str) {
    if samples > 1 {
        (
            "texture_multisampled_2d<u32>",
            "texture_depth_multisampled_2d",
            "i32(sample)",
        )
    } else {
        ("texture_2d<u32>", "texture_depth_2d", "0")
    }
}

/// Fills the texture-type placeholders of the peel and gather shaders for a sample count
/// ([`sample_types`]).
fn peel_types(body: &str, samples: u32) -> String {
    let (ids, depth, sample) = sample_types(samples);
    body.replace("PREV_IDS_TYPE", ids)
        .replace("PREV_DEPTH_TYPE", depth)
        .replace(
            "LOAD_PREV_DEPTH",
            &format!("textureLoad(prev_depth, coord, {sample})"),
        )
        .replace(
            "LOAD_PREV_IDS",
            &format!("textureLoad(prev_ids, coord, {sample})"),
        )
        .replace(
            "LOAD_LAYER_IDS",
            &format!(
                "textureLoad(layer_ids, coord, {})",
                sample.replace("sample", "s")
            ),
        )
        .replace(
            "LOAD_LAYER_DEPTH",
            &format!(
                "textureLoad(layer_depth, coord, {})",
                sample.replace("sample", "s")
            ),
        )
}

/// The complete peel shader for a sample count (needs `Features::PRIMITIVE_INDEX`).
pub fn peel_shader(samples: u32) -> String {
    compose(&["primitive_index"], &peel_types(PEEL, samples))
}

/// The complete gather shader for a sample count (stand-alone: no shared bindings).
pub fn gather_shader(samples: u32) -> String {
    peel_types(GATHER, samples)
}

/// The plain benchmark pass (`vs_plain`, `fs_plain`); compose with [`plain_shader`].
pub const PLAIN: &str = include_str!("wgsl/plain.wgsl");

/// The complete plain benchmark shader.
pub fn plain_shader() -> String {
    compose(&[], PLAIN)
}

/// The per-sample linked-list OIT renderer's entry points (`fs_oit_list`,
/// `vs_oit_fullscreen`, `fs_oit_resolve`); compose with [`oit_shader`].
pub const OIT: &str = include_str!("wgsl/oit.wgsl");

/// The complete OIT shader: [`COMMON`], the player's [`PLAYER`] entry points (`vs_player`,
/// `player_colour`) and [`OIT`] with a per-sample sort array of `max_sorted` entries (needs
/// `Features::PRIMITIVE_INDEX`).
pub fn oit_shader(max_sorted: u32) -> String {
    compose(
        &["primitive_index"],
        &format!(
            "{PLAYER}\n{}",
            OIT.replace("OIT_MAX_SORTED", &max_sorted.max(1).to_string())
        ),
    )
}

/// The GPU-only depth peeling renderer's entry points (`fs_peeling`, which finds the next
/// layer by the recorder's (depth, id) key, and `fs_peeling_composite`, which shades a layer's
/// samples through the player's `player_colour`); compose with [`peeling_shader`].
pub const PEELING: &str = include_str!("wgsl/peeling.wgsl");

/// The complete depth peeling shader for a sample count: [`COMMON`], the player's [`PLAYER`]
/// entry points (`vs_player`, `player_colour`) and [`PEELING`] with its texture types and
/// per-sample loads filled in (needs `Features::PRIMITIVE_INDEX`).
pub fn peeling_shader(samples: u32) -> String {
    let samples = samples.max(1);
    let (ids, depth, at) = sample_types(samples);
    let at_s = at.replace("sample", "s");
    let body = PEELING
        .replace("PREV_DEPTH_TYPE", depth)
        .replace("IDS_TYPE", ids)
        .replace(
            "LOAD_PREV_DEPTH",
            &format!("textureLoad(prev_depth, coord, {at})"),
        )
        .replace(
            "LOAD_PREV_ID",
            &format!("textureLoad(prev_ids, coord, {at}).x"),
        )
        .replace(
            "LOAD_LAYER_ID",
            &format!("textureLoad(layer_ids, coord, {at_s}).x"),
        )
        .replace("SAMPLE_COUNT", &samples.to_string());
    compose(&["primitive_index"], &format!("{PLAYER}\n{body}"))
}

/// Every shader of the crate by name, composed and ready to compile (used by the naga test).
pub fn all() -> Vec<(&'static str, String)> {
    vec![
        ("smoke", compose(&[], SMOKE)),
        ("player", compose(&[], PLAYER)),
        ("reference", reference_shader()),
        ("peel 1x", peel_shader(1)),
        ("peel 4x", peel_shader(4)),
        ("gather 1x", gather_shader(1)),
        ("gather 4x", gather_shader(4)),
        ("plain", plain_shader()),
        ("peeling 1x", peeling_shader(1)),
        ("peeling 4x", peeling_shader(4)),
        ("oit", oit_shader(32)),
    ]
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
