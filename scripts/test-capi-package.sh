#!/usr/bin/env bash
# The C library as a dashboard team takes it (scripts/test.sh runs this after the cargo tests;
# README § C API): installs it to a temporary prefix with scripts/install-capi.sh, then
# - checks the SONAME (readelf -d), that the player-only library needs no libstdc++ (ldd) and
#   lacks trisort_export_order (with TRISORT_CAPI_EXPORT=1 also libtrisort_export's SONAME,
#   symbols, and the C reader on it);
# - builds the C host (examples/c-gles) with CMake (find_package(trisort)) and again with
#   `pkg-config --cflags --libs trisort`, runs both on a small bake and compares their frames;
# - builds the C++ wrapper's example (examples/cpp, both error modes) with CMake and runs it;
# - builds the C reader (examples/c-reader) against the installed library and runs it;
# - cross-builds trisort-capi for aarch64-unknown-linux-gnu (Debian's cross gcc), runs the C
#   reader under qemu-aarch64 and requires its output to equal the native run's.
# TRISORT_AARCH64=0 skips the last step on a developer machine; CI refuses to skip it.
# It installs the dev-profile build (TRISORT_CAPI_PROFILE=release for the release one): the
# same code, and the C dependencies the cargo tests compiled (zstd) are reused, which saves
# CI about a minute; the profile changes only the optimisation.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-c-host.sh
aarch64="${TRISORT_AARCH64:-1}"
if [ "$aarch64" != 1 ] && [ "${CI:-}" = true ]; then
  echo "test-capi-package: TRISORT_AARCH64=0 is not allowed in CI" >&2
  exit 1
fi
[ "$aarch64" = 1 ] && bash scripts/ensure-aarch64.sh
work="$(mktemp -d /tmp/trisort-capi-package.XXXXXX)"
cross=""
trap '[ -z "$cross" ] || kill "$cross" 2>/dev/null; rm -rf "$work"' EXIT
fail() { echo "test-capi-package: $*" >&2; exit 1; }
step() { echo "test-capi-package: $*" >&2; }
start=$(date +%s)

# A small bake from the CLI the cargo tests built (no rebuild when they ran before), before
# the install below builds libtrisort_capi.so over the tests' copy (which would make cargo
# compile trisort-capi and link the CLI again).
baked="$work/car.baked"
cargo run -q --bin trisort -- bake demo:3000 --path orbit:frames=3,degrees=90 --size 64x48 \
  -o "$baked" >/dev/null 2>&1 || fail "baking the test file failed"

prefix="$work/prefix"
profile="${TRISORT_CAPI_PROFILE:-dev}"
# libtrisort_export (--with-export-order) too with TRISORT_CAPI_EXPORT=1: its build needs the
# glTF importer's dependencies with other features than the cargo tests compiled them (about
# a minute more), so CI leaves it out; its SONAME comes from the same install function.
with_export="${TRISORT_CAPI_EXPORT:-0}"
export_args=()
[ "$with_export" = 1 ] && export_args=(--with-export-order)
bash scripts/install-capi.sh --prefix "$prefix" --profile "$profile" "${export_args[@]}"
# The aarch64 cross-build (cargo, both cores) runs in the background while the checks and the
# C and C++ examples below build and run (gcc, CMake, CTest: mostly one core, no cargo, so no
# wait on cargo's lock on target/); its library is checked at the end.
arm="$work/prefix-aarch64"
if [ "$aarch64" = 1 ]; then
  bash scripts/install-capi.sh --prefix "$arm" --target aarch64-unknown-linux-gnu \
    --profile "$profile" >"$work/install-aarch64.log" 2>&1 &
  cross=$!
fi
lib="$prefix/lib/libtrisort.so"
soname="$(readelf -d "$lib" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')"
[ "$soname" = libtrisort.so.0 ] || fail "$lib: SONAME is '$soname', not libtrisort.so.0"
[ "$(readlink "$lib")" = libtrisort.so.0 ] || fail "$lib does not link to libtrisort.so.0"
if ldd "$lib" | grep -q 'libstdc++'; then
  ldd "$lib" >&2
  fail "$lib (player only) depends on libstdc++"
fi
if [ "$with_export" = 1 ]; then
  export_lib="$prefix/lib/libtrisort_export.so"
  export_soname="$(readelf -d "$export_lib" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')"
  [ "$export_soname" = libtrisort_export.so.0 ] ||
    fail "$export_lib: SONAME is '$export_soname', not libtrisort_export.so.0"
  for symbol in trisort_export_order trisort_open_path trisort_last_error trisort_clip_find; do
    nm -D --defined-only "$export_lib" | grep -qw "$symbol" || fail "$export_lib lacks $symbol"
  done
fi
if nm -D --defined-only "$lib" | grep -qw trisort_export_order; then
  fail "$lib (player only) exports trisort_export_order"
fi
step "SONAME $soname, no libstdc++ ($(ldd "$lib" | wc -l) libraries: $(ldd "$lib" | awk '{print $1}' | tr '\n' ' '))"

# The C host: CMake and pkg-config builds, each run on the bake; their frames are equal.
cmake -S examples/c-gles -B "$work/c-cmake" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null || fail "cmake could not configure examples/c-gles"
cmake --build "$work/c-cmake" >/dev/null || fail "cmake could not build examples/c-gles"
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
# shellcheck disable=SC2046 # pkg-config's words are separate arguments
gcc -std=c99 -Wall -Wextra -Werror -O2 examples/c-gles/host.c -o "$work/host-pc" \
  $(pkg-config --cflags --libs trisort egl glesv2) -lm || fail "the pkg-config build failed"
ldd "$work/c-cmake/host" | grep -q "libtrisort.so.0 => $prefix/lib/" ||
  fail "the CMake-built host does not load $prefix/lib/libtrisort.so.0"
mkdir -p "$work/frames-cmake" "$work/frames-pc"
"$work/c-cmake/host" "$baked" "$work/frames-cmake" blend >/dev/null ||
  fail "the CMake-built host failed"
LD_LIBRARY_PATH="$prefix/lib" "$work/host-pc" "$baked" "$work/frames-pc" blend >/dev/null ||
  fail "the pkg-config-built host failed"
frames=$(find "$work/frames-cmake" -name '*.png' | wc -l)
[ "$frames" = 3 ] || fail "the host wrote $frames frames, not 3"
diff -r "$work/frames-cmake" "$work/frames-pc" >/dev/null ||
  fail "the CMake and pkg-config builds of the host drew different frames"
step "C host built with CMake and with pkg-config: 3 equal frames"

# The C++ wrapper's example, both error modes, through CMake and CTest.
cmake -S examples/cpp -B "$work/cpp" -DCMAKE_PREFIX_PATH="$prefix" \
  -DTRISORT_EXAMPLE_BAKED="$baked" >/dev/null || fail "cmake could not configure examples/cpp"
cmake --build "$work/cpp" >/dev/null || fail "cmake could not build examples/cpp"
(cd "$work/cpp" && ctest --output-on-failure >"$work/ctest.log" 2>&1) || {
  cat "$work/ctest.log" >&2
  fail "the C++ example failed"
}
step "C++ example (exceptions and expected) built with CMake and run"

# The C reader, natively and (below) under qemu-aarch64.
gcc -std=c99 -Wall -Wextra -Werror -O2 examples/c-reader/reader.c -o "$work/reader" \
  $(pkg-config --cflags --libs trisort) || fail "the C reader did not build"
LD_LIBRARY_PATH="$prefix/lib" "$work/reader" "$baked" >"$work/reader-x86_64.txt" ||
  fail "the C reader failed natively"
grep -q '^refusals ok$' "$work/reader-x86_64.txt" || fail "the C reader did not finish"
if [ "$with_export" = 1 ]; then
  # libtrisort_export is a drop-in superset: the same reader linked to it prints the same.
  gcc -std=c99 -Wall -Wextra -Werror -O2 examples/c-reader/reader.c -o "$work/reader-export" \
    $(pkg-config --cflags --libs trisort-export) ||
    fail "the C reader did not build on trisort-export"
  LD_LIBRARY_PATH="$prefix/lib" "$work/reader-export" "$baked" |
    diff "$work/reader-x86_64.txt" - >&2 ||
    fail "the C reader on libtrisort_export printed other data than on libtrisort"
  step "libtrisort_export: SONAME libtrisort_export.so.0, the C reader prints the same on it"
fi

if [ "$aarch64" = 1 ]; then
  crossed=0
  wait "$cross" || crossed=$?
  cross=""
  cat "$work/install-aarch64.log" >&2
  [ "$crossed" = 0 ] || fail "installing the aarch64 library failed"
  readelf -h "$arm/lib/libtrisort.so" | grep -q 'Machine:.*AArch64' ||
    fail "$arm/lib/libtrisort.so is not an AArch64 library"
  aarch64-linux-gnu-gcc -std=c99 -Wall -Wextra -Werror -O2 -I "$arm/include" \
    examples/c-reader/reader.c -L "$arm/lib" -ltrisort -o "$work/reader-aarch64" ||
    fail "the C reader did not cross-build"
  QEMU_LD_PREFIX=/usr/aarch64-linux-gnu LD_LIBRARY_PATH="$arm/lib" \
    qemu-aarch64 "$work/reader-aarch64" "$baked" >"$work/reader-aarch64.txt" ||
    fail "the C reader failed under qemu-aarch64"
  diff "$work/reader-x86_64.txt" "$work/reader-aarch64.txt" >&2 ||
    fail "the aarch64 library copies out other data than the x86_64 one"
  step "aarch64: cross-built, the C reader under qemu-aarch64 equals the native run"
fi
step "passed in $(($(date +%s) - start)) s"
