#!/usr/bin/env bash
# Makes sure headless OpenGL ES through EGL works (wgpu's GL backend: `--backend gl`, the
# player's GLES 3.0 / WebGL2 path): Mesa's EGL and its software (llvmpipe) driver. Installs
# them when libEGL's Mesa vendor or the DRI drivers are missing.
set -euo pipefail
have_gl() {
  case "$(ldconfig -p)" in
    *libEGL.so.1*libEGL_mesa.so.0* | *libEGL_mesa.so.0*libEGL.so.1*) ;;
    *) return 1 ;;
  esac
  compgen -G '/usr/lib/*/dri/swrast_dri.so' >/dev/null || compgen -G '/usr/lib/dri/swrast_dri.so' >/dev/null
}
if ! have_gl; then
  echo "trisort: no Mesa EGL found; installing libegl1 libegl-mesa0 libgles2 libgl1-mesa-dri" >&2
  bash "$(dirname "$0")/apt-install.sh" libegl1 libegl-mesa0 libgles2 libgl1-mesa-dri
fi
