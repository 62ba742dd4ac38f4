#!/usr/bin/env bash
# Schema check of the Kubernetes manifest (bake.yaml) against Kubernetes 1.29 (the first
# with backoffLimitPerIndex on by default) and 1.37, strict (unknown fields fail), with
# PyPI's kubernetes-validate in a virtual environment under target/. Nothing is run on a
# cluster. .ci/run calls it when TRISORT_SLURM_TEST=1.
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/k8s-validate-venv
if [ ! -x "$venv/bin/kubernetes-validate" ]; then
  if ! python3 -m venv --help >/dev/null 2>&1 || ! python3 -c 'import ensurepip' 2>/dev/null; then
    sudo=""; if [ "$(id -u)" != 0 ]; then sudo="sudo"; fi
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update -qq
    $sudo apt-get install -y -qq python3-venv >/dev/null
  fi
  rm -rf "$venv"
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q kubernetes-validate==1.37.0
fi
for k in 1.29.0 1.37.0; do
  "$venv/bin/kubernetes-validate" --strict --quiet -k "$k" examples/k8s/bake.yaml
done
echo "k8s: examples/k8s/bake.yaml valid (Kubernetes 1.29, 1.37, strict)"
