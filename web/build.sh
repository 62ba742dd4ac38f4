#!/usr/bin/env bash
# Builds the web player into web/dist/: the wasm module (release), its wasm-bindgen glue
# (pkg/), the page, and the demo car's bake (demo.baked, as `trisort demo` bakes it but with
# the `browser` raster profile: SwiftShader snaps corners to 4 bits and takes a sample's depth
# elsewhere in its pixel) when it is missing or stale. Serve the folder and open it: python3 -m http.server -d web/dist 8080
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
# Bake again when missing, unreadable by this trisort (an older format version) or baked for
# another raster profile.
profile=$("$target/debug/trisort" inspect "$out/demo.baked" --json 2>/dev/null |
  node -e 'let s="";process.stdin.on("data",d=>s+=d).on("end",()=>{try{console.log(JSON.parse(s).raster_profile.name)}catch(e){}})' || true)
if [ "$profile" != browser ]; then
  bash scripts/ensure-lavapipe.sh
  rm -f "$out/demo.baked" "$out/demo.baked.rec"
  "$target/debug/trisort" bake demo --path demo --size 256x256 --samples 4 \
    --raster-profile browser -o "$out/demo.baked"
fi
echo "web player in $out/ ($(du -h "$out/pkg/trisort_web_bg.wasm" | cut -f1) of wasm)"
