#!/usr/bin/env bash
# Installs Debian packages for the ensure-* scripts: `bash scripts/apt-install.sh
# [--no-install-recommends] PACKAGE...` (through sudo when not root, non-interactive, quiet).
set -euo pipefail
SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq "$@" >/dev/null
