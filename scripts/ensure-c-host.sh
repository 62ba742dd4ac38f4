#!/usr/bin/env bash
# Makes sure the C host example (examples/c-gles, tests/c_host.rs) can be built and run, and
# that FORMAT.md's independent reader (docs/format_reader.py, tests/format_reader.rs) can run:
# gcc, the EGL and GLES 3 headers and libraries with Mesa's EGL vendor, and Python's
# zstandard module (Debian's python3-zstandard, for /usr/bin/python3); for the installed
# library's builds (scripts/test-capi-package.sh) g++, CMake and pkg-config. Installs what is
# missing.
set -euo pipefail
missing=()
command -v gcc >/dev/null || missing+=(gcc)
command -v g++ >/dev/null || missing+=(g++)
command -v cmake >/dev/null || missing+=(cmake)
command -v pkg-config >/dev/null || missing+=(pkgconf)
# spirv-val checks `trisort export-shaders --lang spirv` (tests/c_host.rs).
command -v spirv-val >/dev/null || missing+=(spirv-tools)
[ -f /usr/include/EGL/egl.h ] || missing+=(libegl-dev)
[ -f /usr/include/GLES3/gl3.h ] || missing+=(libgles-dev)
case "$(ldconfig -p)" in
  *libEGL_mesa.so.0*) ;;
  *) missing+=(libegl-mesa0) ;;
esac
have_zstandard() {
  for py in python3 /usr/bin/python3; do
    if command -v "$py" >/dev/null && "$py" -c 'import zstandard' 2>/dev/null; then return 0; fi
  done
  return 1
}
have_zstandard || missing+=(python3 python3-zstandard)
if [ ${#missing[@]} -gt 0 ]; then
  echo "trisort: installing ${missing[*]} (C host example, format reader)" >&2
  bash "$(dirname "$0")/apt-install.sh" --no-install-recommends "${missing[@]}"
fi
