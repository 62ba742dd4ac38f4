#!/usr/bin/env bash
# The Slurm test (issue 18): stands up a single-node Slurm on this machine (munged,
# slurmctld, slurmd on localhost; installed from Debian's packages when missing), bakes the
# demo car's default path at 128x128 4x as 4 array tasks per phase through bake.sh, bakes it
# again with one local `trisort bake`, and compares the two baked files and the two
# recordings byte for byte. Stops the daemons it started, whatever happens. Needs root.
#
#   bash scripts/slurm/test-local-slurm.sh      (.ci/run runs it when TRISORT_SLURM_TEST=1)
#
# TRISORT_BIN: the trisort binary (default: builds target/debug/trisort).
set -euo pipefail
cd "$(dirname "$0")/../.."
root="$PWD"
source scripts/slurm/local-cluster.sh
start=$(date +%s)
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/xdg-runtime-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
tmp="$(mktemp -d /tmp/trisort-slurm-test.XXXXXX)"
build=""
cleanup() {
  if [ -n "$build" ]; then kill "$build" 2>/dev/null || true; fi
  local_slurm_stop "$tmp/cluster"
  if [ "${TRISORT_SLURM_KEEP:-0}" = 1 ]; then echo "slurm test: kept $tmp"; else rm -rf "$tmp"; fi
}
trap cleanup EXIT
# The CLI builds (the CPU) while the daemons start and the node comes up (mostly waiting).
if [ -z "${TRISORT_BIN:-}" ]; then
  cargo build --quiet --bin trisort &
  build=$!
  TRISORT_BIN="$root/target/debug/trisort"
fi
local_slurm_start "$tmp/cluster"
echo "slurm test: cluster up in $(( $(date +%s) - start )) s"
if [ -n "$build" ]; then
  built=0
  wait "$build" || built=$?
  build=""
  if [ "$built" != 0 ]; then echo "slurm test: building trisort failed" >&2; exit 1; fi
  echo "slurm test: trisort built, $(( $(date +%s) - start )) s in"
fi

opts=(--size 128x128 --samples 4)
mkdir -p "$tmp/local" "$tmp/shared"
t0=$(date +%s)
"$TRISORT_BIN" bake demo --path demo "${opts[@]}" -o "$tmp/local/demo.baked" >/dev/null
echo "slurm test: local bake in $(( $(date +%s) - t0 )) s"
t0=$(date +%s)
bash scripts/slurm/bake.sh --scene demo --path demo --out "$tmp/shared/demo.baked" --shards 4 \
  --trisort "$TRISORT_BIN" --wait -- "${opts[@]}"
echo "slurm test: cluster bake (4 array tasks per phase) in $(( $(date +%s) - t0 )) s"

failed=0
for f in demo.baked demo.baked.rec; do
  if cmp "$tmp/local/$f" "$tmp/shared/$f"; then
    echo "slurm test: $f identical ($(stat -c %s "$tmp/local/$f") bytes)"
  else
    echo "slurm test: $f DIFFERS between the local and the Slurm bake" >&2
    failed=1
  fi
done
# Each phase really ran as 4 array tasks, each its own shard of the 48 frames.
for i in 0 1 2 3; do
  for p in phase1 phase2; do
    log="$(ls "$tmp/shared/demo.baked.work/logs/trisort-$p-"*"_$i.out")"
    grep -q "shard auto" "$log" || { echo "slurm test: $log ran no shard" >&2; failed=1; }
  done
done
grep -h "recorded frames" "$tmp/shared/demo.baked.work/logs/"trisort-phase2-*.out

# Resubmitting after losing shard 2's phase 2 and the result reruns only those two steps
# (every other step finds its output and skips) and bakes the same bytes again.
work="$tmp/shared/demo.baked.work"
rm "$work/graphs-2.rec" "$tmp/shared/demo.baked" "$tmp/shared/demo.baked.rec"
rm -f "$work"/logs/*.out
t0=$(date +%s)
bash scripts/slurm/bake.sh --scene demo --path demo --out "$tmp/shared/demo.baked" --shards 4 \
  --trisort "$TRISORT_BIN" --wait -- "${opts[@]}"
echo "slurm test: resubmitted bake in $(( $(date +%s) - t0 )) s"
reran="$(grep -L "exists, skipping" "$work"/logs/*.out | xargs -n1 basename \
  | sed -E 's/-[0-9]+(_[0-9]+)?\.out$/\1/' | sort | tr '\n' ' ')"
if [ "$reran" != "trisort-merge trisort-phase2_2 " ]; then
  echo "slurm test: the resubmission reran [$reran], not just phase 2 of shard 2 and the merge" >&2
  failed=1
fi
for f in demo.baked demo.baked.rec; do
  cmp "$tmp/local/$f" "$tmp/shared/$f" || { echo "slurm test: resubmitted $f DIFFERS" >&2; failed=1; }
done

# A failing step (a sample count trisort refuses) fails the chain: bake.sh --wait exits 1
# and cancels the steps waiting on it.
if bash scripts/slurm/bake.sh --scene demo --path demo --out "$tmp/bad/demo.baked" --shards 4 \
  --trisort "$TRISORT_BIN" --wait -- --size 64x64 --samples 7 >"$tmp/bad.log" 2>&1; then
  echo "slurm test: a chain whose phase 1 fails succeeded" >&2
  failed=1
elif ! grep -q "only 1 and 4 are supported" "$tmp/bad.log"; then
  echo "slurm test: the failed chain did not show the step's error:" >&2
  cat "$tmp/bad.log" >&2
  failed=1
fi
if [ -n "$(squeue -h)" ]; then
  echo "slurm test: jobs left in the queue after the failed chain:" >&2
  squeue >&2
  failed=1
fi
echo "slurm test: finished in $(( $(date +%s) - start )) s"
if [ "$failed" = 0 ]; then
  echo "slurm: 1 passed, 0 failed"
else
  echo "slurm: 0 passed, 1 failed"
  exit 1
fi
