#!/usr/bin/env bash
# Runs `trisort demo` on the built-in procedural car (README's first command).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-lavapipe.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/xdg-runtime-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
cargo run --release --quiet -- demo --out-dir demo-out "$@"
