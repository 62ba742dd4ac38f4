#!/usr/bin/env bash
# CI's licence check (a few seconds; no cargo-about): every third-party crate the shipped
# artefacts link, recomputed from Cargo.lock with `cargo tree`, has a licence on about.toml's
# allow-list and is listed at its locked version in THIRD-PARTY-NOTICES.md. On failure it names
# the crate; scripts/third-party-notices.sh regenerates the notices.
set -euo pipefail
cd "$(dirname "$0")/.."
exec python3 scripts/licences.py check "$@"
