#!/usr/bin/env bash
# Runs trisort's whole test suite (README's second command; .ci/run runs this too).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-lavapipe.sh
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
