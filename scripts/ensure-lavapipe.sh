#!/usr/bin/env bash
# Makes sure a Vulkan driver is present: on a machine without a GPU that is Mesa's lavapipe
# (a CPU Vulkan implementation). Installs mesa-vulkan-drivers when no Vulkan ICD is found.
set -euo pipefail
# No pipelines here: under `pipefail`, `grep -q` closing its input early fails the pipeline.
have_icd() {
  compgen -G '/usr/share/vulkan/icd.d/*.json' >/dev/null || compgen -G '/etc/vulkan/icd.d/*.json' >/dev/null || return 1
  case "$(ldconfig -p)" in
    *libvulkan.so.1*) return 0 ;;
    *) return 1 ;;
  esac
}
if ! have_icd; then
  echo "trisort: no Vulkan driver found; installing Mesa's lavapipe (mesa-vulkan-drivers)" >&2
  bash "$(dirname "$0")/apt-install.sh" mesa-vulkan-drivers libvulkan1
fi
