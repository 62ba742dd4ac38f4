#!/usr/bin/env bash
# Shared by the job scripts of scripts/slurm/ (sourced, not run): the trisort command and
# the work folder's file names. Every variable comes from bake.sh through the job's
# environment (sbatch --export=ALL).
set -euo pipefail
: "${TRISORT_WORK:?TRISORT_WORK (the shared work folder) is not set; submit with bake.sh}"
: "${TRISORT_SCENE:?TRISORT_SCENE is not set; submit with bake.sh}"
: "${TRISORT_PATH:?TRISORT_PATH is not set; submit with bake.sh}"
TRISORT_BIN="${TRISORT_BIN:-trisort}"
# Options every `record` step repeats (size, samples, ...): word-split on purpose.
read -r -a RECORD_OPTS <<<"${TRISORT_RECORD_OPTS:-}"
# Runs a step unless its output already exists: a resubmitted bake skips finished steps, and
# an interrupted `record` resumes from OUT.partial/ (trisort writes every output by rename,
# so an existing output is a finished one).
step() {
  local out="$1"
  shift
  if [ -e "$out" ]; then
    echo "trisort-slurm: $out exists, skipping: $*"
    return 0
  fi
  echo "trisort-slurm: $(hostname -s): $*"
  "$@"
}
