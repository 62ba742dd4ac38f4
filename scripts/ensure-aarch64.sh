#!/usr/bin/env bash
# Makes sure trisort-capi can be cross-built for aarch64-unknown-linux-gnu (the usual
# automotive SoC CPU) and its C reader run under emulation: Rust's aarch64 standard library
# (rustup), Debian's cross gcc and C library, and qemu-user. Installs what is missing.
set -euo pipefail
if ! rustup target list --installed | grep -qx aarch64-unknown-linux-gnu; then
  echo "trisort: adding Rust's aarch64-unknown-linux-gnu target" >&2
  rustup target add aarch64-unknown-linux-gnu >&2
fi
missing=()
command -v aarch64-linux-gnu-gcc >/dev/null || missing+=(gcc-aarch64-linux-gnu)
[ -f /usr/aarch64-linux-gnu/include/stdio.h ] || missing+=(libc6-dev-arm64-cross)
command -v qemu-aarch64 >/dev/null || missing+=(qemu-user)
if [ ${#missing[@]} -gt 0 ]; then
  echo "trisort: installing ${missing[*]} (aarch64 cross-build)" >&2
  bash "$(dirname "$0")/apt-install.sh" --no-install-recommends "${missing[@]}"
fi
