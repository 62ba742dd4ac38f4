#!/usr/bin/env bash
# Bakes a path on a Slurm cluster: four jobs chained with --dependency=afterok.
#
#   1. phase1.sbatch  array of N tasks: `record --phase visibility --shard auto`
#   2. union.sbatch   one task:         `record --phase union` (G, written once)
#   3. phase2.sbatch  array of N tasks: `record --phase graphs --shard auto`
#   4. merge.sbatch   one task:         `merge --join OUT.rec -o OUT`
#
# OUT and OUT.rec are byte for byte what `trisort bake SCENE --path P -o OUT` writes on one
# machine with the same device, driver and options.
#
# Usage:
#   scripts/slurm/bake.sh --scene S --path P --out OUT --shards N [--work DIR]
#                         [--trisort BIN] [--merge-opts "..."] [--wait]
#                         [--sbatch "extra sbatch options"] [-- RECORD_OPTIONS...]
#
# --work (default OUT.work/) must be on a file system every node sees; it keeps each step's
# output and the jobs' logs (logs/). Resubmitting the same bake skips the steps whose output
# exists, and an interrupted `record` resumes from its OUT.partial/; a work folder of another
# bake is refused. --wait returns when the merge has finished (exit 1 if any job failed).
# Prints the four job ids.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
scene="" path="" out="" shards="" work="" bin="${TRISORT_BIN:-}" wait=0 merge_opts="" extra=""
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --scene) scene="$2"; shift 2 ;;
    --path) path="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --shards) shards="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --trisort) bin="$2"; shift 2 ;;
    --merge-opts) merge_opts="$2"; shift 2 ;;
    --sbatch) extra="$2"; shift 2 ;;
    --wait) wait=1; shift ;;
    --) shift; break ;;
    -h|--help) usage ;;
    *) echo "bake.sh: unknown argument $1" >&2; usage ;;
  esac
done
if [ -z "$scene" ] || [ -z "$path" ] || [ -z "$out" ] || [ -z "$shards" ]; then
  echo "bake.sh: --scene, --path, --out and --shards are required" >&2
  usage
fi
case "$shards" in ''|*[!0-9]*|0) echo "bake.sh: --shards must be a positive number" >&2; exit 2 ;; esac
if [ -z "$bin" ]; then
  bin="$(command -v trisort || true)"
  [ -n "$bin" ] || { echo "bake.sh: no trisort on PATH; give --trisort BIN" >&2; exit 2; }
fi
abs() { case "$1" in /*) echo "$1" ;; *) echo "$PWD/$1" ;; esac; }
out="$(abs "$out")"
work="$(abs "${work:-$out.work}")"
bin="$(abs "$bin")"
# A scene file is given to the jobs by absolute path (`demo…` is built in).
if [ -e "$scene" ]; then scene="$(abs "$scene")"; fi
if [ -e "$path" ]; then path="$(abs "$path")"; fi
record_opts="$*"
mkdir -p "$work/logs"
key="$(printf '%s\n' "$scene" "$path" "$out" "$shards" "$record_opts" "$merge_opts" "$bin")"
if [ -e "$work/bake.key" ] && [ "$(cat "$work/bake.key")" != "$key" ]; then
  echo "bake.sh: $work holds the steps of another bake (see $work/bake.key); remove it or give --work" >&2
  exit 1
fi
printf '%s\n' "$key" >"$work/bake.key"

export TRISORT_SLURM_DIR="$here" TRISORT_BIN="$bin" TRISORT_SCENE="$scene" TRISORT_PATH="$path" \
  TRISORT_WORK="$work" TRISORT_OUT="$out" TRISORT_RECORD_OPTS="$record_opts" \
  TRISORT_MERGE_OPTS="$merge_opts"
read -r -a extra_opts <<<"$extra"
# submit LOG-PATTERN SBATCH-OPTIONS... SCRIPT: the job id.
submit() {
  local log="$1"
  shift
  sbatch --parsable --export=ALL --chdir="$work" --output="$work/logs/$log" \
    "${extra_opts[@]}" "$@" | cut -d';' -f1
}
last=$((shards - 1))
p1="$(submit '%x-%A_%a.out' --array="0-$last" "$here/phase1.sbatch")"
un="$(submit '%x-%j.out' --dependency="afterok:$p1" "$here/union.sbatch")"
p2="$(submit '%x-%A_%a.out' --array="0-$last" --dependency="afterok:$un" "$here/phase2.sbatch")"
mg="$(submit '%x-%j.out' --dependency="afterok:$p2" "$here/merge.sbatch")"
echo "trisort-slurm: jobs phase1=$p1 union=$un phase2=$p2 merge=$mg (logs in $work/logs)"
[ "$wait" = 1 ] || exit 0

# Waits for the chain. A failed task leaves its dependants pending forever (unless the
# cluster sets kill_invalid_depend), so a job pending on DependencyNeverSatisfied ends the
# wait: the rest are cancelled.
jobs="$p1,$un,$p2,$mg"
while :; do
  queued="$(squeue -h -j "$jobs" -o '%i %T %r' 2>/dev/null || true)"
  if grep -q 'DependencyNeverSatisfied' <<<"$queued"; then
    echo "trisort-slurm: a step failed; cancelling the rest:" >&2
    echo "$queued" >&2
    scancel "$p1" "$un" "$p2" "$mg" 2>/dev/null || true
    tail -n 5 "$work"/logs/*.out >&2 || true
    exit 1
  fi
  [ -n "$queued" ] || break
  sleep 2
done
if [ ! -e "$out" ]; then
  echo "trisort-slurm: the chain ended without $out; logs:" >&2
  tail -n 5 "$work"/logs/*.out >&2 || true
  exit 1
fi
echo "trisort-slurm: wrote $out and $out.rec"
