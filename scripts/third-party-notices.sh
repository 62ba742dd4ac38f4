#!/usr/bin/env bash
# Regenerates THIRD-PARTY-NOTICES.md: every third-party crate the shipped artefacts (the
# `trisort` CLI, the C libraries, the web player's wasm) link, with its licence and the licence
# texts. cargo-about finds the texts in the crates (about.toml: allow-list, clarifications);
# scripts/licences.py computes which crates ship and writes the file, then checks it as CI does.
# Run it after changing dependencies or Cargo.lock, and commit the result.
# Installs cargo-about (about 4.5 min on 2 cores) when the pinned version is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
about_version=0.9.3
if [ "$(cargo about --version 2>/dev/null)" != "cargo-about $about_version" ]; then
  cargo install --locked cargo-about --version "$about_version" --features cli
fi
json="$(mktemp /tmp/trisort-about.XXXXXX.json)"
trap 'rm -f "$json"' EXIT
# --fail: a crate whose licence cargo-about cannot read or the allow-list does not satisfy
# fails the run. (A clarification whose checksum no longer matches, after a crate update, only
# warns; `licences.py render` checks those checksums itself and fails.)
cargo about generate --locked --fail --workspace --format json -o "$json"
python3 scripts/licences.py render --about-json "$json" -o THIRD-PARTY-NOTICES.md
python3 scripts/licences.py check
