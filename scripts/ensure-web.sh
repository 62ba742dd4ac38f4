#!/usr/bin/env bash
# Makes sure the web player can be built and tested: the wasm32 target, the wasm-bindgen CLI
# of the version web/Cargo.toml pins (from crates.io), and, with --browser, Debian's Chromium
# and Node.js/npm (for playwright-core). Installs what is missing. `--browser-only` installs
# just the browser side (no compiling: .ci/run runs it beside the lint).
set -euo pipefail
cd "$(dirname "$0")/.."
want=$(sed -n 's/^wasm-bindgen = "=\([0-9.]*\)".*/\1/p' web/Cargo.toml)
browser_only=0
if [ "${1:-}" = "--browser-only" ]; then
  browser_only=1
  set -- --browser
elif ! rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
  echo "trisort: installing the wasm32-unknown-unknown target" >&2
  rustup target add wasm32-unknown-unknown
fi
if [ "$browser_only" = 0 ] && [ "$(wasm-bindgen --version 2>/dev/null | awk '{print $2}')" != "$want" ]; then
  echo "trisort: installing wasm-bindgen-cli $want from crates.io (a few minutes, once)" >&2
  cargo install --quiet wasm-bindgen-cli --version "=$want"
fi
if [ "${1:-}" = "--browser" ]; then
  missing=()
  command -v chromium >/dev/null || missing+=(chromium)
  command -v node >/dev/null || missing+=(nodejs)
  command -v npm >/dev/null || missing+=(npm)
  if [ ${#missing[@]} -gt 0 ]; then
    echo "trisort: installing ${missing[*]}" >&2
    bash scripts/apt-install.sh --no-install-recommends "${missing[@]}"
  fi
  # web/test/package.json pins them: playwright-core drives Chromium, typescript checks the
  # npm package's types, binaryen's wasm-opt is measured in BENCHMARKS § Web player.
  if [ ! -d web/test/node_modules/playwright-core ] || [ ! -d web/test/node_modules/typescript ] ||
    [ ! -d web/test/node_modules/binaryen ]; then
    echo "trisort: installing playwright-core, typescript, binaryen (npm) into web/test/node_modules" >&2
    (cd web/test && npm install --no-audit --no-fund --silent)
  fi
fi
