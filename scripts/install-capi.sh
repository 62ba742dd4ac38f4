#!/usr/bin/env bash
# Builds trisort's C library and installs it under a prefix, as a C/C++ build expects it:
#
#   PREFIX/lib/libtrisort.so.0.1.0, libtrisort.so.0 (the SONAME), libtrisort.so, libtrisort.a
#   PREFIX/include/trisort.h, trisort.hpp
#   PREFIX/lib/pkgconfig/trisort.pc                  pkg-config --cflags --libs trisort
#   PREFIX/lib/cmake/trisort/trisortConfig.cmake     find_package(trisort): trisort::trisort
#                                                    (shared), trisort::trisort_static
#   PREFIX/share/doc/trisort/                        the licences and third-party notices
#
# The library is the player only: no glTF importer and no C++ runtime. --with-export-order
# also installs libtrisort_export (the player library plus trisort_export_order, which needs
# the importer, whose meshoptimizer is C++: its static archive links libstdc++),
# trisort_export.h, trisort-export.pc and trisort::trisort_export.
#
# Usage: scripts/install-capi.sh --prefix DIR [--target TRIPLE] [--profile release|dev]
#                                [--libdir lib] [--with-export-order]
# --target cross-builds (e.g. aarch64-unknown-linux-gnu: see scripts/ensure-aarch64.sh).
set -euo pipefail
cd "$(dirname "$0")/.."

prefix="" target="" profile=release libdir=lib export_order=0
while [ $# -gt 0 ]; do
  case "$1" in
    --prefix) prefix="${2:?--prefix needs a directory}"; shift 2 ;;
    --target) target="${2:?--target needs a target triple}"; shift 2 ;;
    --profile) profile="${2:?--profile needs release or dev}"; shift 2 ;;
    --libdir) libdir="${2:?--libdir needs a path relative to the prefix}"; shift 2 ;;
    --with-export-order) export_order=1; shift ;;
    -h|--help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "install-capi: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
if [ -z "$prefix" ]; then
  echo "install-capi: --prefix DIR is required (see --help)" >&2
  exit 2
fi
case "$profile" in
  release) out_profile=release ;;
  dev) out_profile=debug ;;
  *) echo "install-capi: --profile is release or dev, not '$profile'" >&2; exit 2 ;;
esac
case "$libdir" in
  /*|*..*) echo "install-capi: --libdir is a path inside the prefix, like lib or lib64" >&2; exit 2 ;;
esac
mkdir -p "$prefix"
prefix="$(cd "$prefix" && pwd)"

version="$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
major="${version%%.*}"
target_args=()
target_dir="${CARGO_TARGET_DIR:-target}"
out_dir="$target_dir/$out_profile"
if [ -n "$target" ]; then
  target_args=(--target "$target")
  out_dir="$target_dir/$target/$out_profile"
  # Debian's cross gcc links (and, through the cc crate, compiles zstd's C) for aarch64.
  if [ "$target" = aarch64-unknown-linux-gnu ]; then
    export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER="${CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER:-aarch64-linux-gnu-gcc}"
  fi
fi

# One build gives the shared and the static library and the system libraries a static link
# needs (rustc's native-static-libs note, replayed by cargo when the build is fresh).
# The SONAME goes to this crate's link alone (a build script's cdylib-link-arg would reach
# every dependent cdylib too: libtrisort_export would be named libtrisort.so.0).
build() { # package, installed name → prints the native-static-libs
  local log
  log="$(mktemp)"
  if ! cargo rustc --profile "$profile" "${target_args[@]}" -p "$1" --lib \
      --crate-type cdylib,staticlib -- --print native-static-libs \
      -C "link-arg=-Wl,-soname,lib$2.so.$major" >"$log" 2>&1; then
    cat "$log" >&2
    rm -f "$log"
    echo "install-capi: building $1 failed" >&2
    return 1
  fi
  sed -n 's/.*note: native-static-libs: //p' "$log" | tail -1
  rm -f "$log"
}

echo "install-capi: building trisort-capi ($profile${target:+, $target})" >&2
static_libs="$(build trisort-capi trisort)"
if [ "$export_order" = 1 ]; then
  echo "install-capi: building trisort-capi-export ($profile${target:+, $target})" >&2
  export_static_libs="$(build trisort-capi-export trisort_export)"
fi

# Into a staging directory beside the prefix, then moved in: an interrupted install leaves
# no half-written library or config behind.
stage="$(mktemp -d "$prefix/.install-capi.XXXXXX")"
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/$libdir/pkgconfig" "$stage/$libdir/cmake/trisort" "$stage/include" \
  "$stage/share/doc/trisort"

install_lib() { # cargo's name, installed name
  install -m 755 "$out_dir/lib$1.so" "$stage/$libdir/lib$2.so.$version"
  ln -sf "lib$2.so.$version" "$stage/$libdir/lib$2.so.$major"
  ln -sf "lib$2.so.$major" "$stage/$libdir/lib$2.so"
  install -m 644 "$out_dir/lib$1.a" "$stage/$libdir/lib$2.a"
}
install_lib trisort_capi trisort
install -m 644 capi/include/trisort.h capi/include/trisort.hpp "$stage/include/"
for f in LICENSE-MIT LICENSE-APACHE THIRD-PARTY-NOTICES.md; do
  if [ -f "$f" ]; then install -m 644 "$f" "$stage/share/doc/trisort/"; fi
done

# pkg-config: `--libs` links the shared library, `--static --libs` the archive and the system
# libraries it needs.
pc() { # name, library, description, static libs
  cat >"$stage/$libdir/pkgconfig/$1.pc" <<EOF
prefix=$prefix
exec_prefix=\${prefix}
libdir=\${prefix}/$libdir
includedir=\${prefix}/include

Name: $1
Description: $3
Version: $version
Cflags: -I\${includedir}
Libs: -L\${libdir} -l$2
Libs.private: $4
EOF
}
pc trisort trisort "trisort's player library: baked, depth-sorted frames for C and C++ hosts" \
  "$static_libs"

# CMake: the package finds its prefix from where the config file lies, so the prefix can move.
up="$(echo "$libdir/cmake/trisort" | sed 's#[^/][^/]*#..#g')"
cmake_target() { # target, library, static libs
  local libs
  libs="$(echo "$3" | sed 's/-l\([^ ]*\)/\1/g; s/ /;/g')"
  cat <<EOF
if(NOT TARGET trisort::$1)
  add_library(trisort::$1 SHARED IMPORTED)
  set_target_properties(trisort::$1 PROPERTIES
    IMPORTED_LOCATION "\${_trisort_prefix}/$libdir/lib$2.so.$version"
    IMPORTED_SONAME "lib$2.so.$major"
    INTERFACE_INCLUDE_DIRECTORIES "\${_trisort_prefix}/include")
  add_library(trisort::$1_static STATIC IMPORTED)
  set_target_properties(trisort::$1_static PROPERTIES
    IMPORTED_LOCATION "\${_trisort_prefix}/$libdir/lib$2.a"
    INTERFACE_INCLUDE_DIRECTORIES "\${_trisort_prefix}/include"
    INTERFACE_LINK_LIBRARIES "$libs")
endif()
EOF
}
{
  echo "# trisort's CMake package (scripts/install-capi.sh): find_package(trisort) defines"
  echo "# trisort::trisort (the shared player library) and trisort::trisort_static."
  echo "get_filename_component(_trisort_prefix \"\${CMAKE_CURRENT_LIST_DIR}/$up\" ABSOLUTE)"
  cmake_target trisort trisort "$static_libs"
  if [ "$export_order" = 1 ]; then
    cmake_target trisort_export trisort_export "$export_static_libs"
  fi
  echo "unset(_trisort_prefix)"
} >"$stage/$libdir/cmake/trisort/trisortConfig.cmake"
cat >"$stage/$libdir/cmake/trisort/trisortConfigVersion.cmake" <<EOF
# find_package(trisort X.Y) accepts this $version when the major versions match (for 0.x,
# the minor too: before 1.0 a minor release may change the ABI) and X.Y is not newer.
set(PACKAGE_VERSION "$version")
set(PACKAGE_VERSION_COMPATIBLE FALSE)
if(PACKAGE_FIND_VERSION_MAJOR EQUAL $major AND NOT PACKAGE_FIND_VERSION VERSION_GREATER PACKAGE_VERSION)
  if(NOT $major EQUAL 0 OR PACKAGE_FIND_VERSION_MINOR EQUAL "$(echo "$version" | cut -d. -f2)")
    set(PACKAGE_VERSION_COMPATIBLE TRUE)
  endif()
endif()
if(PACKAGE_FIND_VERSION STREQUAL PACKAGE_VERSION)
  set(PACKAGE_VERSION_EXACT TRUE)
endif()
EOF

if [ "$export_order" = 1 ]; then
  install_lib trisort_export trisort_export
  install -m 644 capi/include/trisort_export.h "$stage/include/"
  pc trisort-export trisort_export \
    "trisort's player library plus trisort_export_order (the glTF importer; needs libstdc++)" \
    "$export_static_libs"
fi

# Move the staged tree in, file by file (the prefix may hold other packages).
(cd "$stage" && find . \( -type f -o -type l \) -print) | while read -r f; do
  mkdir -p "$prefix/$(dirname "$f")"
  mv -f "$stage/$f" "$prefix/$f"
done
echo "install-capi: installed trisort $version into $prefix" >&2
