#!/usr/bin/env bash
# Makes sure a Vulkan driver is present: on a machine without a GPU that is Mesa's lavapipe
# (a CPU Vulkan implementation). Installs mesa-vulkan-drivers when no Vulkan ICD is found.
set -euo pipefail
have_icd() {
  ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json 2>/dev/null | grep -q . &&
    ldconfig -p | grep -q 'libvulkan.so.1'
}
if ! have_icd; then
  echo "trisort: no Vulkan driver found; installing Mesa's lavapipe (mesa-vulkan-drivers)" >&2
  SUDO=""
  if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq mesa-vulkan-drivers libvulkan1 >/dev/null
fi
