#!/usr/bin/env bash
# Runs examples/k8s/bake.yaml's four Jobs in order, each after the previous one completed
# (`kubectl wait`), in the current kubectl context and namespace. Needs the PersistentVolumeClaim
# `trisort-work` (ReadWriteMany) and the image named in the manifest. Not run by the tests.
set -euo pipefail
manifest="$(dirname "$0")/bake.yaml"
timeout="${TRISORT_K8S_TIMEOUT:-24h}"
for step in phase1 union phase2 merge; do
  kubectl apply -f "$manifest" -l "step=$step"
  kubectl wait --for=condition=complete --timeout="$timeout" "job/trisort-$step"
done
echo "wrote demo.baked and demo.baked.rec on the volume trisort-work"
