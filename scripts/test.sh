#!/usr/bin/env bash
# Runs trisort's whole test suite (README's second command; .ci/run runs this too).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-lavapipe.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/xdg-runtime-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
export TRISORT_SCENES="${TRISORT_SCENES:-$(pwd)/../shared/scenes}"
cargo test --workspace --all-targets "$@"
