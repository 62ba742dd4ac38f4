#!/usr/bin/env bash
# Builds the web player into web/dist/: the wasm module (release), its wasm-bindgen glue
# (pkg/), the page, and the demo car's bake (demo.baked, as `trisort demo` bakes it) when it
# is missing or stale. Serve the folder and open it: python3 -m http.server -d web/dist 8080
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-web.sh
target="${CARGO_TARGET_DIR:-target}"
out=web/dist
cargo build --quiet -p trisort-web --target wasm32-unknown-unknown --release
mkdir -p "$out/pkg"
wasm-bindgen --target web --no-typescript --out-dir "$out/pkg" \
  "$target/wasm32-unknown-unknown/release/trisort_web.wasm"
cp web/www/index.html web/www/main.js "$out/"
cargo build --quiet --bin trisort
# Bake again when missing or unreadable by this trisort (an older format version).
if ! "$target/debug/trisort" inspect "$out/demo.baked" >/dev/null 2>&1; then
  bash scripts/ensure-lavapipe.sh
  rm -f "$out/demo.baked" "$out/demo.baked.rec"
  "$target/debug/trisort" bake demo --path demo --size 256x256 --samples 4 -o "$out/demo.baked"
fi
echo "web player in $out/ ($(du -h "$out/pkg/trisort_web_bg.wasm" | cut -f1) of wasm)"
