//! trisort's GPU code in one place: every WGSL shader, device setup (headless or for a
//! window's surface), scene upload ([`scene_gpu`]), the off-screen frame target
//! ([`FrameTarget`]), readback and the one quantisation to 8-bit sRGB ([`readback`]), GPU
//! timestamps ([`GpuTimer`]). The recorder, the player, the reference, the bench and the window
//! viewer build on it; the player keeps only what playing a baked file needs.
//!
//! Every pipeline's shader is [`COMMON`] followed by its own entry points, so all of them use
//! the one vertex transform (`transform_position`) and the one surface function
//! (`surface_base`, `shade`), and mark `@builtin(position)` `@invariant`: the recorder, the
//! player and the reference rasterize bit-identical positions. WGSL has no includes, so
//! [`compose`] concatenates.
#![deny(missing_docs)]

mod data_textures;
pub mod device;
pub mod pipeline;
pub mod present;
pub mod raster_probe;
pub mod readback;
pub mod target;
mod timer;

pub use device::{
    device_info, wanted_features, DeviceBackend, DeviceLimits, Gpu, GpuError, GpuOptions,
    UncapturedError,
};
#[cfg(not(target_arch = "wasm32"))]
pub use readback::map_read_all;
pub use readback::{f16_to_f32, halves, linear_to_srgb, poll_ready, quantize_rgba16f};
pub use target::{clear_colour, FrameTarget, TargetConfig, BACKGROUND, COLOR_FORMAT, DEPTH_FORMAT};
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
    compose(&[], &format!("{PLAIN}\n{SMOKE}"))
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
    compose(&["primitive_index"], &format!("{PLAYER}\n{REFERENCE}"))
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
    compose(
        &["primitive_index"],
        &format!("{RECORD_VERTEX}\n{CAPTURE}").replace(
            "EARLY_DEPTH_TEST",
            if early_depth_test {
                "@early_depth_test(force)"
            } else {
                ""
            },
        ),
    )
}

/// The grown capture's fragment stage (`fs_capture_grown`, after [`GROW`]'s `vs_grown`); compose with
/// [`capture_grown_shader`].
pub const CAPTURE_GROWN: &str = include_str!("../../shaders/record/capture_grown.wgsl");

/// The complete grown-capture shader: [`COMMON`], the capture's bindings and functions
/// ([`CAPTURE`], group 1), [`GROW`] in group 2 and [`CAPTURE_GROWN`]: the one-pass form of
/// [`peel_grown_shader`] (needs writable storage in fragment shaders).
pub fn capture_grown_shader() -> String {
    compose(
        &["primitive_index"],
        &format!(
            "{}\n{}\n{}",
            format!("{RECORD_VERTEX}\n{CAPTURE}").replace("EARLY_DEPTH_TEST", ""),
            GROW.replace("CONS_GROUP", "2"),
            CAPTURE_GROWN.replace("ENVELOPE_ID_BITS_VALUE", &ENVELOPE_ID_BITS.to_string())
        ),
    )
}

/// Bits of an envelope capture node's id word that hold the triangle's id + 1; its flags sit
/// above them (`capture_grown.wgsl`, read back by the recorder's envelope bound).
pub const ENVELOPE_ID_BITS: u32 = 24;

/// The compute pass that gathers a peel layer per sample; compose with [`gather_shader`].
pub const GATHER: &str = include_str!("../../shaders/record/gather.wgsl");

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
    compose(
        &["primitive_index"],
        &peel_types(&format!("{RECORD_VERTEX}\n{PEEL}"), samples),
    )
}

/// The complete gather shader for a sample count (stand-alone: no shared bindings).
pub fn gather_shader(samples: u32) -> String {
    peel_types(GATHER, samples)
}

/// The plain benchmark pass (`vs_plain`, `fs_plain`); compose with [`plain_shader`].
pub const PLAIN: &str = include_str!("../../shaders/reference/plain.wgsl");

/// The complete plain benchmark shader.
pub fn plain_shader() -> String {
    compose(&[], PLAIN)
}

/// The per-sample linked-list OIT renderer's entry points (`fs_oit_list`,
/// `vs_oit_fullscreen`, `fs_oit_resolve`); compose with [`oit_shader`].
pub const OIT: &str = include_str!("../../shaders/reference/oit.wgsl");

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
pub const PEELING: &str = include_str!("../../shaders/reference/peeling.wgsl");

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

/// Triangles grown or shrunk by a tolerance box, pulled from storage (bindings in group
/// `CONS_GROUP`); the base of [`conservative_shader`] and [`peel_grown_shader`].
pub const GROW: &str = include_str!("../../shaders/record/grow.wgsl");

/// The recorder's conservative visibility passes (`vs_erode`/`fs_erode`,
/// `vs_dilate`/`fs_mark`); compose with [`conservative_shader`].
pub const CONSERVATIVE: &str = include_str!("../../shaders/record/conservative.wgsl");

/// The complete conservative visibility shader for a sample count: [`COMMON`], [`GROW`] in
/// group 1 and [`CONSERVATIVE`] with its texture types, per-sample loads and sample count
/// filled in.
pub fn conservative_shader(samples: u32) -> String {
    let samples = samples.max(1);
    let (_, depth, at) = sample_types(samples);
    let float = if samples > 1 {
        "texture_multisampled_2d<f32>"
    } else {
        "texture_2d<f32>"
    };
    let at_k = if samples > 1 { "i32(k)" } else { "0" };
    compose(
        &[],
        &format!("{}\n{CONSERVATIVE}", GROW.replace("CONS_GROUP", "1"))
            .replace("OCCLUDER_TYPE", float)
            .replace("SURFACE_TYPE", depth)
            .replace(
                "LOAD_OCCLUDER",
                &format!("textureLoad(occluder, coord, {at}).x"),
            )
            .replace("LOAD_SURFACE", &format!("textureLoad(surface, c, {at_k})"))
            .replace("SAMPLE_COUNT", &format!("{samples}u")),
    )
}

/// The grown peel's fragment stage (`fs_peel_grown`, after [`GROW`]'s `vs_grown`); compose with
/// [`peel_grown_shader`].
pub const PEEL_GROWN: &str = include_str!("../../shaders/record/peel_grown.wgsl");

/// The complete grown-peel shader for a sample count: [`COMMON`], the peel's bindings and
/// entry points ([`PEEL`], group 1), [`GROW`] in group 2 and [`PEEL_GROWN`] (needs
/// `Features::PRIMITIVE_INDEX`, as [`PEEL`] does).
pub fn peel_grown_shader(samples: u32) -> String {
    compose(
        &["primitive_index"],
        &peel_types(
            &format!(
                "{RECORD_VERTEX}\n{PEEL}\n{}\n{PEEL_GROWN}",
                GROW.replace("CONS_GROUP", "2")
            ),
            samples,
        ),
    )
}

/// The coverage test's entry point (`fs_coverage`); compose with [`coverage_shader`].
pub const COVERAGE: &str = include_str!("../../shaders/common/coverage.wgsl");

/// The complete shader of the recorder's coverage test: [`COMMON`], the player's [`PLAYER`]
/// entry points (`vs_player`) and [`COVERAGE`] (needs `Features::PRIMITIVE_INDEX`).
pub fn coverage_shader() -> String {
    compose(&["primitive_index"], &format!("{PLAYER}\n{COVERAGE}"))
}

/// The window viewer's copy of a frame to its surface (`vs_blit`, `fs_blit`); stand-alone (no
/// shared bindings): see [`blit_shader`].
pub const BLIT: &str = include_str!("../../shaders/play/blit.wgsl");

/// The complete blit shader: `under` puts `background` (linear RGB) under the frame's
/// premultiplied colour (`saturate` mode), `encode_srgb` applies the sRGB transfer function in
/// the shader (for a non-sRGB view of an 8-bit surface).
pub fn blit_shader(under: bool, encode_srgb: bool, background: [f32; 3]) -> String {
    format!(
        "const UNDER: bool = {under};\nconst ENCODE_SRGB: bool = {encode_srgb};\n\
         const BACKGROUND: vec3<f32> = vec3<f32>({:?}, {:?}, {:?});\n{BLIT}",
        background[0], background[1], background[2],
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
            compose_with(Bindings::Textures, &[], &format!("{PLAIN}\n{SMOKE}")),
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
/// `body`.
pub fn compose(enables: &[&str], body: &str) -> String {
    compose_with(Bindings::Storage, enables, body)
}

/// [`compose`] with the binding prelude of `bindings` ([`STORAGE_BINDINGS`] or
/// [`TEXTURE_BINDINGS`]): the same [`COMMON`] maths over either.
pub fn compose_with(bindings: Bindings, enables: &[&str], body: &str) -> String {
    let mut s = String::new();
    for e in enables {
        s.push_str(&format!("enable {e};\n"));
    }
    s.push_str(COMMON);
    s.push('\n');
    s.push_str(match bindings {
        Bindings::Storage => STORAGE_BINDINGS,
        Bindings::Textures => TEXTURE_BINDINGS,
    });
    s.push('\n');
    s.push_str(body);
    s
}

/// Binding prelude of [`Bindings::Storage`]: node matrices and materials in storage buffers.
pub const STORAGE_BINDINGS: &str = include_str!("../../shaders/common/storage.wgsl");
/// Binding prelude of [`Bindings::Textures`]: node matrices and materials in data textures.
pub const TEXTURE_BINDINGS: &str = include_str!("../../shaders/common/textures.wgsl");

/// Size in bytes of the `Frame` uniform of [`COMMON`].
pub const FRAME_UNIFORM_SIZE: u64 = 64 + 16 + 16 + 48;
/// Size in bytes of one `MaterialGpu` of [`COMMON`].
pub const MATERIAL_SIZE: u64 = 20 * 16;
