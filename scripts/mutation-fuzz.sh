#!/usr/bin/env bash
# The mutation fuzz of issue 28: N_REC mutants of a recording through `inspect` and `merge`,
# and N_BAKED mutants of a baked file through `inspect`, `play`, `verify --recording` and
# `verify --scene`, each command under a 60 s limit. Counts exit codes; any exit 101 (a
# panic) or any run killed at 60 s is a failure, and the script exits 1 naming the seeds.
#
#   scripts/mutation-fuzz.sh [N_REC [N_BAKED [OUT_DIR]]]      (defaults: 500 500 target/mutation-fuzz)
#
# The mutants come from testkit/examples/mutate.rs (fields changed and re-encoded, payload
# bytes in a correct container, container bytes), one per seed, so a failure replays with
# `cargo run --release -p trisort-testkit --example mutate -- KIND IN OUT SEED`; what each
# fields mutant changed is listed in OUT_DIR/mutants.txt.
# Needs a Vulkan (or GL) adapter for play and verify --scene: lavapipe on a machine without a GPU.
set -euo pipefail
cd "$(dirname "$0")/.."
n_rec=${1:-500}
n_baked=${2:-500}
out=${3:-target/mutation-fuzz}
limit=60
cargo build --release --quiet --bin trisort
cargo build --release --quiet -p trisort-testkit --example mutate
t=$PWD/target/release/trisort
mutate=$PWD/target/release/examples/mutate
# The output folder is emptied first: refuse anything but a folder of its own.
case "$(realpath -m "$out")" in
  / | "$PWD" | "$PWD"/.. | "$HOME" | "$PWD"/src | "$PWD"/tests)
    echo "mutation-fuzz: refusing to empty $out; give a folder of its own" >&2
    exit 2 ;;
esac
rm -rf "$out"
mkdir -p "$out"
cd "$out"
scene=demo:2000
"$t" bake $scene --path orbit:frames=3,degrees=30 --size 32x32 --samples 4 -o seed.baked >/dev/null
log=runs.tsv
: >"$log"
# run LABEL SEED CMD...: runs CMD under the limit and appends "label seed exit seconds".
run() {
  local label=$1 seed=$2
  shift 2
  local start end code
  start=$(date +%s.%N)
  code=0
  timeout --signal=KILL $limit "$@" >/dev/null 2>"err-$label-$seed.txt" || code=$?
  end=$(date +%s.%N)
  printf '%s\t%s\t%s\t%s\n' "$label" "$seed" "$code" "$(awk "BEGIN { print $end - $start }")" >>"$log"
  case $code in
    101 | 137) ;; # kept: the report names them
    *) rm -f "err-$label-$seed.txt" ;;
  esac
}
start=$(date +%s)
for seed in $(seq 1 "$n_rec"); do
  "$mutate" recording seed.baked.rec m.rec "$seed" 2>>mutants.txt
  run rec-inspect "$seed" "$t" inspect m.rec
  run rec-merge "$seed" "$t" merge m.rec -o m-merged.baked
  rm -f m-merged.baked
  if ((seed % 100 == 0)); then echo "recordings: $seed of $n_rec" >&2; fi
done
for seed in $(seq 1 "$n_baked"); do
  "$mutate" baked seed.baked m.baked "$seed" 2>>mutants.txt
  run baked-inspect "$seed" "$t" inspect m.baked
  run baked-play "$seed" "$t" play m.baked --out-dir frames
  run baked-verify-recording "$seed" "$t" verify m.baked --recording seed.baked.rec
  run baked-verify-scene "$seed" "$t" verify m.baked --scene $scene
  rm -rf frames
  if ((seed % 100 == 0)); then echo "baked files: $seed of $n_baked" >&2; fi
done
seconds=$(($(date +%s) - start))
python3 - "$log" "$n_rec" "$n_baked" "$seconds" <<'PY'
import collections, sys
log, n_rec, n_baked, seconds = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
runs = [l.rstrip("\n").split("\t") for l in open(log)]
by = collections.defaultdict(collections.Counter)
slowest = collections.defaultdict(float)
for label, seed, code, secs in runs:
    by[label][int(code)] += 1
    slowest[label] = max(slowest[label], float(secs))
print(f"mutation fuzz: {n_rec} recordings, {n_baked} baked files, {len(runs)} runs in {seconds} s")
print("| command | runs | exit 0 | exit 1 | exit 3 | exit 4 | exit 101 | killed at 60 s | slowest (s) |")
print("|---|---|---|---|---|---|---|---|---|")
bad = []
for label in sorted(by):
    c = by[label]
    other = sum(v for k, v in c.items() if k not in (0, 1, 3, 4, 101, 137))
    print(f"| {label} | {sum(c.values())} | {c[0]} | {c[1]} | {c[3]} | {c[4]} | {c[101]} | {c[137]} | {slowest[label]:.1f} |"
          + (f" ({other} other)" if other else ""))
    bad += [f"{label} seed {s}" for l, s, code, _ in runs if l == label and code in ("101", "137")]
if bad:
    print("FAILED: " + ", ".join(bad[:20]) + " (stderr in err-LABEL-SEED.txt)")
    sys.exit(1)
print("0 exit-101 results, 0 runs killed at 60 s")
PY
