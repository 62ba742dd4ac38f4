//! trisort's GPU code in one place: every WGSL shader, device setup (headless or for a
//! window's surface), scene upload ([`scene_gpu`]), the off-screen frame target
//! ([`FrameTarget`]), readback and the one quantisation to 8-bit sRGB ([`readback`]), GPU
//! timestamps ([`GpuTimer`]). The recorder, the player, the reference, the bench and the window
//! viewer build on it; the player keeps only what playing a baked file needs.
//!
//! Every pipeline's shader is [`COMMON`] followed by its own entry points, so all of them use
//! the one vertex transform (`transform_position`) and the one surface function
//! (`surface_base`, `shade`), and mark `@builtin(position)` `@invariant`: the recorder, the
//! player and the reference rasterize bit-identical positions. WGSL has no includes, so every
//! shader is assembled one way, by [`shader_source::assemble`]: `enable` directives, the
//! source files joined in order, `{{NAME}}` placeholders filled.
#![deny(missing_docs)]

mod data_textures;
pub mod device;
#[cfg(not(target_arch = "wasm32"))]
mod export_layout;
#[cfg(not(target_arch = "wasm32"))]
pub mod export_shaders;
pub mod pipeline;
pub mod present;
pub mod raster_probe;
pub mod readback;
pub mod shader_source;
pub mod target;
mod timer;

pub use device::{
    device_info, wanted_features, DeviceBackend, DeviceLimits, Gpu, GpuError, GpuOptions,
    UncapturedError,
};
#[cfg(not(target_arch = "wasm32"))]
pub use readback::map_read_all;
pub use readback::{f16_to_f32, halves, linear_to_srgb, poll_ready, quantize_rgba16f};
pub use target::{
    clear_colour, FrameTarget, StagingLayout, TargetConfig, BACKGROUND, COLOR_FORMAT, DEPTH_FORMAT,
};
pub use timer::GpuTimer;
pub mod scene_gpu;
pub use scene_gpu::{Bindings, Lighting, Shading, ToneMap};

/// The shared bindings, vertex layout, vertex transform and surface functions.
pub const COMMON: &str = include_str!("../../shaders/common/common.wgsl");

/// The GPU smoke test's fragment entry point (`fs_smoke`); compose with [`smoke_shader`].
pub const SMOKE: &str = include_str!("../../shaders/common/smoke.wgsl");

/// The complete smoke-test shader: [`COMMON`], the plain pass's vertex stage (`vs_plain`) and
/// [`SMOKE`]'s `fs_smoke`, which colours each triangle by its material.
pub fn smoke_shader() -> String {
    storage_shader("smoke", &[], &[PLAIN, SMOKE], &[])
}

/// Entry points of the player (`vs_player`, `fs_player_straight`, `fs_player_premultiplied`).
pub const PLAYER: &str = include_str!("../../shaders/play/player.wgsl");

/// The exact reference's compositing entry points (`fs_reference_straight`,
/// `fs_reference_premultiplied`); compose with [`reference_shader`].
pub const REFERENCE: &str = include_str!("../../shaders/reference/reference.wgsl");

/// The complete shader of the exact reference's compositing passes: [`COMMON`], the player's
/// [`PLAYER`] entry points and the reference's own (needs `Features::PRIMITIVE_INDEX`). The
/// reference draws with `vs_player` and shades with the player's `player_colour`.
pub fn reference_shader() -> String {
    storage_shader("reference", &["primitive_index"], &[PLAYER, REFERENCE], &[])
}

/// The recorder's vertex stage (`vs_record`, `RecordVarying`), shared by [`PEEL`] and
/// [`CAPTURE`] so both rasterize the same positions.
pub const RECORD_VERTEX: &str = include_str!("../../shaders/record/record_vertex.wgsl");

/// Depth peeling's fragment stage (`fs_peel`, after [`RECORD_VERTEX`]); compose with
/// [`peel_shader`].
pub const PEEL: &str = include_str!("../../shaders/record/peel.wgsl");

/// The recorder's fragment capture (`fs_capture`, after [`RECORD_VERTEX`]): every fragment of every
/// sample in one pass, pushed on per-sample lists; compose with [`capture_shader`].
pub const CAPTURE: &str = include_str!("../../shaders/record/capture.wgsl");

/// The complete fragment-capture shader (needs `Features::PRIMITIVE_INDEX` and writable
/// storage in fragment shaders); with `early_depth_test`, its fragment stage forces the depth
/// test before it runs (needs `Features::SHADER_EARLY_DEPTH_TEST`).
pub fn capture_shader(early_depth_test: bool) -> String {
    let early = if early_depth_test {
        "@early_depth_test(force)"
    } else {
        ""
    };
    storage_shader(
        "capture",
        &["primitive_index"],
        &[RECORD_VERTEX, CAPTURE],
        &[("EARLY_DEPTH_TEST", early)],
    )
}

/// The grown capture's fragment stage (`fs_capture_grown`, after [`GROW`]'s `vs_grown`); compose with
/// [`capture_grown_shader`].
pub const CAPTURE_GROWN: &str = include_str!("../../shaders/record/capture_grown.wgsl");

/// The complete grown-capture shader: [`COMMON`], the capture's bindings and functions
/// ([`CAPTURE`], group 1), [`GROW`] in group 2 and [`CAPTURE_GROWN`]: the one-pass form of
/// [`peel_grown_shader`] (needs writable storage in fragment shaders).
pub fn capture_grown_shader() -> String {
    storage_shader(
        "capture grown",
        &["primitive_index"],
        &[RECORD_VERTEX, CAPTURE, GROW, CAPTURE_GROWN],
        &[
            ("EARLY_DEPTH_TEST", ""),
            ("CONS_GROUP", "2"),
            ("ENVELOPE_ID_BITS", &ENVELOPE_ID_BITS.to_string()),
        ],
    )
}

/// Bits of an envelope capture node's id word that hold the triangle's id + 1; its flags sit
/// above them (`capture_grown.wgsl`, read back by the recorder's envelope bound).
pub const ENVELOPE_ID_BITS: u32 = 24;

/// The compute pass that gathers a peel layer per sample; compose with [`gather_shader`].
pub const GATHER: &str = include_str!("../../shaders/record/gather.wgsl");

/// The texture placeholders of the shaders that read a previous layer per sample, for a sample
/// count: `IDS_TYPE` and `DEPTH_TYPE` (multisampled textures for `samples > 1`, plain ones for a
/// single sample) and `AT_SAMPLE`, `AT_S`, `AT_K`, the sample argument of a `textureLoad` at the
/// sample held in WGSL variable `sample`, `s` or `k` (`i32(sample)`, or 0 for a single sample).
fn sample_values(samples: u32) -> [(&'static str, &'static str); 5] {
    if samples > 1 {
        [
            ("IDS_TYPE", "texture_multisampled_2d<u32>"),
            ("DEPTH_TYPE", "texture_depth_multisampled_2d"),
            ("AT_SAMPLE", "i32(sample)"),
            ("AT_S", "i32(s)"),
            ("AT_K", "i32(k)"),
        ]
    } else {
        [
            ("IDS_TYPE", "texture_2d<u32>"),
            ("DEPTH_TYPE", "texture_depth_2d"),
            ("AT_SAMPLE", "0"),
            ("AT_S", "0"),
            ("AT_K", "0"),
        ]
    }
}

/// The values of [`sample_values`] for a sample count that name one of `names`.
fn sample_values_of(samples: u32, names: &[&str]) -> Vec<(&'static str, &'static str)> {
    sample_values(samples)
        .into_iter()
        .filter(|(name, _)| names.contains(name))
        .collect()
}

/// The complete peel shader for a sample count (needs `Features::PRIMITIVE_INDEX`).
pub fn peel_shader(samples: u32) -> String {
    storage_shader(
        "peel",
        &["primitive_index"],
        &[RECORD_VERTEX, PEEL],
        &sample_values_of(samples, &["IDS_TYPE", "DEPTH_TYPE", "AT_SAMPLE"]),
    )
}

/// The complete gather shader for a sample count (stand-alone: no shared bindings).
pub fn gather_shader(samples: u32) -> String {
    shader_source::assemble(
        "gather",
        &[],
        &[GATHER],
        &sample_values_of(samples, &["IDS_TYPE", "DEPTH_TYPE", "AT_S"]),
    )
}

/// The plain benchmark pass (`vs_plain`, `fs_plain`); compose with [`plain_shader`].
pub const PLAIN: &str = include_str!("../../shaders/reference/plain.wgsl");

/// The complete plain benchmark shader.
pub fn plain_shader() -> String {
    storage_shader("plain", &[], &[PLAIN], &[])
}

/// The depth-presorted renderer's fragment entry points (`fs_presorted_straight`,
/// `fs_presorted_premultiplied`); compose with [`presorted_shader`].
pub const PRESORTED: &str = include_str!("../../shaders/reference/presorted.wgsl");

/// The complete presorted shader: [`COMMON`], the player's [`PLAYER`] entry points and
/// [`PRESORTED`] (needs `Features::PRIMITIVE_INDEX`).
pub fn presorted_shader() -> String {
    storage_shader("presorted", &["primitive_index"], &[PLAYER, PRESORTED], &[])
}

/// The per-sample linked-list OIT renderer's entry points (`fs_oit_list`,
/// `vs_oit_fullscreen`, `fs_oit_resolve`); compose with [`oit_shader`].
pub const OIT: &str = include_str!("../../shaders/reference/oit.wgsl");

/// The complete OIT shader: [`COMMON`], the player's [`PLAYER`] entry points (`vs_player`,
/// `player_colour`) and [`OIT`] with a per-sample sort array of `max_sorted` entries (needs
/// `Features::PRIMITIVE_INDEX`).
pub fn oit_shader(max_sorted: u32) -> String {
    storage_shader(
        "oit",
        &["primitive_index"],
        &[PLAYER, OIT],
        &[("OIT_MAX_SORTED", &max_sorted.max(1).to_string())],
    )
}

/// The GPU-only depth peeling renderer's entry points (`fs_peeling`, which finds the next
/// layer by the recorder's (depth, id) key, and `fs_peeling_composite`, which shades a layer's
/// samples through the player's `player_colour`); compose with [`peeling_shader`].
pub const PEELING: &str = include_str!("../../shaders/reference/peeling.wgsl");

/// The complete depth peeling shader for a sample count: [`COMMON`], the player's [`PLAYER`]
/// entry points (`vs_player`, `player_colour`) and [`PEELING`] with its texture types and
/// per-sample loads filled in (needs `Features::PRIMITIVE_INDEX`).
pub fn peeling_shader(samples: u32) -> String {
    let samples = samples.max(1);
    let count = samples.to_string();
    let mut values = sample_values_of(samples, &["IDS_TYPE", "DEPTH_TYPE", "AT_SAMPLE", "AT_S"]);
    values.push(("SAMPLE_COUNT", &count));
    storage_shader("peeling", &["primitive_index"], &[PLAYER, PEELING], &values)
}

/// Triangles grown or shrunk by a tolerance box, pulled from storage (bindings in group
/// `{{CONS_GROUP}}`); the base of [`conservative_shader`] and [`peel_grown_shader`].
pub const GROW: &str = include_str!("../../shaders/record/grow.wgsl");

/// The recorder's conservative visibility passes (`vs_erode`/`fs_erode`,
/// `vs_dilate`/`fs_mark`); compose with [`conservative_shader`].
pub const CONSERVATIVE: &str = include_str!("../../shaders/record/conservative.wgsl");

/// The complete conservative visibility shader for a sample count: [`COMMON`], [`GROW`] in
/// group 1 and [`CONSERVATIVE`] with its texture types, per-sample loads and sample count
/// filled in.
pub fn conservative_shader(samples: u32) -> String {
    let samples = samples.max(1);
    let count = samples.to_string();
    let occluder = if samples > 1 {
        "texture_multisampled_2d<f32>"
    } else {
        "texture_2d<f32>"
    };
    let mut values = sample_values_of(samples, &["DEPTH_TYPE", "AT_SAMPLE", "AT_K"]);
    values.extend([
        ("CONS_GROUP", "1"),
        ("OCCLUDER_TYPE", occluder),
        ("SAMPLE_COUNT", &count),
    ]);
    storage_shader("conservative", &[], &[GROW, CONSERVATIVE], &values)
}

/// The grown peel's fragment stage (`fs_peel_grown`, after [`GROW`]'s `vs_grown`); compose with
/// [`peel_grown_shader`].
pub const PEEL_GROWN: &str = include_str!("../../shaders/record/peel_grown.wgsl");

/// The complete grown-peel shader for a sample count: [`COMMON`], the peel's bindings and
/// entry points ([`PEEL`], group 1), [`GROW`] in group 2 and [`PEEL_GROWN`] (needs
/// `Features::PRIMITIVE_INDEX`, as [`PEEL`] does).
pub fn peel_grown_shader(samples: u32) -> String {
    let mut values = sample_values_of(samples, &["IDS_TYPE", "DEPTH_TYPE", "AT_SAMPLE"]);
    values.push(("CONS_GROUP", "2"));
    storage_shader(
        "peel grown",
        &["primitive_index"],
        &[RECORD_VERTEX, PEEL, GROW, PEEL_GROWN],
        &values,
    )
}

/// The coverage test's entry point (`fs_coverage`); compose with [`coverage_shader`].
pub const COVERAGE: &str = include_str!("../../shaders/common/coverage.wgsl");

/// The complete shader of the recorder's coverage test: [`COMMON`], the player's [`PLAYER`]
/// entry points (`vs_player`) and [`COVERAGE`] (needs `Features::PRIMITIVE_INDEX`).
pub fn coverage_shader() -> String {
    storage_shader("coverage", &["primitive_index"], &[PLAYER, COVERAGE], &[])
}

/// The window viewer's copy of a frame to its surface (`vs_blit`, `fs_blit`); stand-alone (no
/// shared bindings): see [`blit_shader`].
pub const BLIT: &str = include_str!("../../shaders/play/blit.wgsl");

/// The complete blit shader: `under` puts `background` (linear RGB) under the frame's
/// premultiplied colour (`saturate` mode), `encode_srgb` applies the sRGB transfer function in
/// the shader (for a non-sRGB view of an 8-bit surface).
pub fn blit_shader(under: bool, encode_srgb: bool, background: [f32; 3]) -> String {
    let [r, g, b] = background;
    shader_source::assemble(
        "blit",
        &[],
        &[BLIT],
        &[
            ("UNDER", &under.to_string()),
            ("ENCODE_SRGB", &encode_srgb.to_string()),
            ("BACKGROUND", &format!("{r:?}, {g:?}, {b:?}")),
        ],
    )
}

/// Every shader of the crate by name, composed and ready to compile (used by the naga test).
pub fn all() -> Vec<(&'static str, String)> {
    vec![
        ("smoke", smoke_shader()),
        ("player", compose(&[], PLAYER)),
        (
            "player textures",
            compose_with(Bindings::Textures, &[], PLAYER),
        ),
        (
            "smoke textures",
            tier_shader(
                Bindings::Textures,
                "smoke textures",
                &[],
                &[PLAIN, SMOKE],
                &[],
            ),
        ),
        ("reference", reference_shader()),
        ("peel 1x", peel_shader(1)),
        ("peel 4x", peel_shader(4)),
        ("gather 1x", gather_shader(1)),
        ("gather 4x", gather_shader(4)),
        ("plain", plain_shader()),
        ("peeling 1x", peeling_shader(1)),
        ("peeling 4x", peeling_shader(4)),
        ("oit", oit_shader(32)),
        ("presorted", presorted_shader()),
        ("coverage", coverage_shader()),
        ("conservative 1x", conservative_shader(1)),
        ("conservative 4x", conservative_shader(4)),
        ("peel grown 1x", peel_grown_shader(1)),
        ("peel grown 4x", peel_grown_shader(4)),
        ("capture", capture_shader(false)),
        ("capture, early depth test", capture_shader(true)),
        ("capture grown", capture_grown_shader()),
        ("blit", blit_shader(false, true, BACKGROUND)),
        ("blit saturate linear", blit_shader(true, false, BACKGROUND)),
    ]
}

/// Composes a module on the storage tier ([`Bindings::Storage`]): `enable` directives first
/// (WGSL requires them before any declaration), then [`COMMON`], its binding prelude, then
/// `body`, a complete source (it must hold no `{{NAME}}` placeholder: [`shader_source`]).
pub fn compose(enables: &[&str], body: &str) -> String {
    compose_with(Bindings::Storage, enables, body)
}

/// [`compose`] with the binding prelude of `bindings` ([`STORAGE_BINDINGS`] or
/// [`TEXTURE_BINDINGS`]): the same [`COMMON`] maths over either.
pub fn compose_with(bindings: Bindings, enables: &[&str], body: &str) -> String {
    tier_shader(bindings, "composed", enables, &[body], &[])
}

/// Shader `name` on the storage tier ([`tier_shader`] with [`Bindings::Storage`]).
fn storage_shader(
    name: &str,
    enables: &[&str],
    sources: &[&str],
    values: &[(&str, &str)],
) -> String {
    tier_shader(Bindings::Storage, name, enables, sources, values)
}

/// Shader `name` on a binding tier: [`COMMON`], the tier's binding prelude ([`STORAGE_BINDINGS`]
/// or [`TEXTURE_BINDINGS`]), then `sources`, assembled with `enables` and placeholder `values`
/// by [`shader_source::assemble`].
fn tier_shader(
    bindings: Bindings,
    name: &str,
    enables: &[&str],
    sources: &[&str],
    values: &[(&str, &str)],
) -> String {
    let prelude = match bindings {
        Bindings::Storage => STORAGE_BINDINGS,
        Bindings::Textures => TEXTURE_BINDINGS,
    };
    let sources: Vec<&str> = [COMMON, prelude].iter().chain(sources).copied().collect();
    shader_source::assemble(name, enables, &sources, values)
}

/// Binding prelude of [`Bindings::Storage`]: node matrices and materials in storage buffers.
pub const STORAGE_BINDINGS: &str = include_str!("../../shaders/common/storage.wgsl");
/// Binding prelude of [`Bindings::Textures`]: node matrices and materials in data textures.
pub const TEXTURE_BINDINGS: &str = include_str!("../../shaders/common/textures.wgsl");

/// Size in bytes of the `Frame` uniform of [`COMMON`].
pub const FRAME_UNIFORM_SIZE: u64 = 64 + 16 + 16 + 48;
/// Size in bytes of one `MaterialGpu` of [`COMMON`].
pub const MATERIAL_SIZE: u64 = 20 * 16;
