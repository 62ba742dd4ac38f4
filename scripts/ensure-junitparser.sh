#!/usr/bin/env bash
# Makes sure python3 can import junitparser (PyPI), the JUnit parser that reads
# `trisort verify --junit` reports in tests/verify_forged.rs. Installs it when missing.
set -euo pipefail
if ! python3 -c 'import junitparser' 2>/dev/null; then
  echo "trisort: installing junitparser (PyPI) for the JUnit report test" >&2
  python3 -m pip install --quiet --disable-pip-version-check junitparser >&2
fi
