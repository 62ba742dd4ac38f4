#!/usr/bin/env bash
# Builds the web player: the npm package in web/pkg (@trisort/player: the wasm module, its
# wasm-bindgen glue and types, the tarball `npm pack` makes) and web/dist/: the glue and wasm
# (pkg/), the page, and the demo car's bake (demo.baked, as `trisort demo` bakes it but with
# the `browser` raster profile: SwiftShader snaps corners to 4 bits and takes a sample's depth
# elsewhere in its pixel) when it is missing or stale. Serve the folder and open it: python3 -m http.server -d web/dist 8080
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-web.sh
target="${CARGO_TARGET_DIR:-target}"
out=web/dist
# The wasm-release profile (the root Cargo.toml: fat LTO, one codegen unit, opt-level "s"),
# chosen by size and frame time (BENCHMARKS § Web player); TRISORT_WASM_PROFILE=release builds
# without LTO (faster while working on the player). `cargo rustc --crate-type cdylib`: cargo
# skips LTO for a crate that is also an rlib (web/Cargo.toml's crate-type, for the native
# tests), so the wasm build asks for the cdylib alone.
wasm_profile="${TRISORT_WASM_PROFILE:-wasm-release}"
cargo rustc --quiet -p trisort-web --lib --crate-type cdylib --target wasm32-unknown-unknown \
  --profile "$wasm_profile"
# The npm package (web/pkg, @trisort/player): index.js and index.d.ts are written by hand;
# wasm/ is wasm-bindgen's module and its types, generated here. Same inputs, same bytes: the
# tarball holds no time stamp of ours (npm pack sets every file's time to its fixed date).
pkg=web/pkg
version=$(sed -n '/^\[workspace.package\]/,/^\[/s/^version = "\(.*\)"/\1/p' Cargo.toml)
pkg_version=$(node -p 'require("./web/pkg/package.json").version')
if [ "$pkg_version" != "$version" ]; then
  echo "web/pkg/package.json has version $pkg_version, the workspace $version" >&2
  exit 1
fi
rm -rf "$pkg/wasm" && mkdir -p "$pkg/wasm" "$out/pkg"
wasm_dir=$wasm_profile
[ "$wasm_profile" = dev ] && wasm_dir=debug
wasm-bindgen --target web --out-dir "$pkg/wasm" \
  "$target/wasm32-unknown-unknown/$wasm_dir/trisort_web.wasm"
rm -f "$pkg/wasm/trisort_web_bg.wasm.d.ts"
# TRISORT_WASM_OPT=-Oz (or other wasm-opt flags) runs binaryen's wasm-opt (web/test's pinned
# npm binaryen) over the module: BENCHMARKS § Web player has what it saves and costs.
if [ -n "${TRISORT_WASM_OPT:-}" ]; then
  [ -x web/test/node_modules/.bin/wasm-opt ] || bash scripts/ensure-web.sh --browser-only
  # shellcheck disable=SC2086 # the flags are words
  web/test/node_modules/.bin/wasm-opt $TRISORT_WASM_OPT "$pkg/wasm/trisort_web_bg.wasm" \
    -o "$pkg/wasm/trisort_web_bg.wasm"
fi
cp LICENSE-MIT LICENSE-APACHE THIRD-PARTY-NOTICES.md "$pkg/"
rm -f "$pkg"/trisort-player-*.tgz
(cd "$pkg" && npm pack --silent >/dev/null)
# The demo page imports the wasm-bindgen module directly (web/www/main.js).
cp "$pkg/wasm/trisort_web.js" "$pkg/wasm/trisort_web_bg.wasm" "$out/pkg/"
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
wasm_bytes=$(stat -c %s "$out/pkg/trisort_web_bg.wasm")
echo "web player in $out/ and $pkg/$(cd "$pkg" && ls trisort-player-*.tgz) ($wasm_bytes bytes of wasm, $wasm_profile${TRISORT_WASM_OPT:+, wasm-opt $TRISORT_WASM_OPT})"
