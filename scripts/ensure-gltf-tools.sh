#!/usr/bin/env bash
# Makes sure the glTF tools the compressed-glTF import tests run at test time are installed
# where the tests look for them (testkit's `gltfpack()` and `gltf_pipeline()`):
# - gltfpack (meshoptimizer's packer, npm `gltfpack`, WebAssembly): quantized and
#   meshopt-compressed copies of CarConcept, in target/tools/gltfpack;
# - gltf-pipeline (Cesium's, npm `gltf-pipeline`, Draco through draco3d): a Draco-compressed
#   copy, in target/tools/gltf-pipeline.
# Installs Node.js/npm (Debian) and the pinned packages when missing.
set -euo pipefail
cd "$(dirname "$0")/.."
need_npm() {
  if ! command -v npm >/dev/null || ! command -v node >/dev/null; then
    echo "trisort: installing nodejs npm (for the glTF tools)" >&2
    bash scripts/apt-install.sh --no-install-recommends nodejs npm
  fi
}
# install PACKAGE VERSION: npm install into target/tools/PACKAGE unless that version is there.
install() {
  local dir=target/tools/$1
  if [ "$(node -p "require('./$dir/node_modules/$1/package.json').version" 2>/dev/null)" = "$2" ]; then
    return 0
  fi
  need_npm
  echo "trisort: installing $1 $2 (npm) into $dir" >&2
  mkdir -p "$dir"
  npm install --prefix "$dir" --no-audit --no-fund --silent "$1@$2"
}
command -v node >/dev/null || need_npm
install gltfpack 1.3.0
install gltf-pipeline 4.3.1
