#!/usr/bin/env bash
# Runs trisort's whole test suite (README's second command; .ci/run runs this too).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-lavapipe.sh
# GL through EGL (Mesa llvmpipe): the player's `--backend gl` tests.
bash scripts/ensure-gl.sh
# The C host example and FORMAT.md's Python reader (tests/c_host.rs, tests/format_reader.rs):
# gcc, EGL/GLES headers, python3-zstandard (seconds when present).
bash scripts/ensure-c-host.sh
# gltfpack and gltf-pipeline (npm) make meshopt-, Draco-compressed and quantized copies of
# CarConcept at test time (scene's import_compressed, tests/compressed_gltf.rs).
bash scripts/ensure-gltf-tools.sh
# Python's junitparser reads `verify --junit` reports (tests/verify_forged.rs).
bash scripts/ensure-junitparser.sh
# Chromium and playwright-core read `verify --report` pages back (tests/verify_report.rs; the
# browser test below installs the rest of what it needs).
if [ "${TRISORT_SKIP_BROWSER:-}" != 1 ]; then
  bash scripts/ensure-web.sh --browser-only
fi
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/xdg-runtime-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
export TRISORT_SCENES="${TRISORT_SCENES:-$(pwd)/../shared/scenes}"
cargo test --workspace --all-targets "$@"
# The web player in headless Chromium (installs Chromium, Node's playwright-core and the
# wasm-bindgen CLI when missing). TRISORT_SKIP_BROWSER=1 skips it on a developer machine;
# CI refuses to skip it.
if [ "${TRISORT_SKIP_BROWSER:-}" = 1 ]; then
  if [ "${CI:-}" = true ]; then
    echo "test: TRISORT_SKIP_BROWSER=1 is not allowed in CI" >&2
    exit 1
  fi
  echo "test: browser test skipped (TRISORT_SKIP_BROWSER=1)" >&2
else
  bash web/test/run.sh
fi
# The C library installed as a C/C++ build takes it: SONAME, pkg-config, CMake, the C++
# example, and the aarch64 cross-build run under qemu-aarch64 (README § Installing the C
# library). Last: its install builds libtrisort_capi.so with the library's own dependency
# features over the tests' copy in target/debug/deps (a cdylib's file name carries no hash),
# so a `cargo build --bin trisort` after it (web/build.sh's) would compile trisort-capi,
# trisort-capi-export and link the CLI again.
bash scripts/test-capi-package.sh
