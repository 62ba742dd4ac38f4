#!/usr/bin/env bash
# Makes sure gltfpack (meshoptimizer's glTF packer, npm package `gltfpack`, a WebAssembly
# build run by Node.js) is installed where the tests look for it
# (target/tools/gltfpack/node_modules/.bin/gltfpack, see testkit's `gltfpack()`): the
# compressed-glTF import tests make meshopt-compressed, quantized copies of CarConcept with
# it at test time. Installs Node.js/npm (Debian) and the pinned package when missing.
set -euo pipefail
cd "$(dirname "$0")/.."
version=1.3.0
dir=target/tools/gltfpack
exe=$dir/node_modules/.bin/gltfpack
if [ -x "$exe" ] && [ "$("$exe" -v 2>&1 | head -1)" = "gltfpack ${version%.0}" ]; then
  exit 0
fi
if ! command -v npm >/dev/null || ! command -v node >/dev/null; then
  echo "trisort: installing nodejs npm (for gltfpack)" >&2
  SUDO=""; if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends nodejs npm >/dev/null
fi
echo "trisort: installing gltfpack $version (npm) into $dir" >&2
mkdir -p "$dir"
npm install --prefix "$dir" --no-audit --no-fund --silent "gltfpack@$version"
"$exe" -v
