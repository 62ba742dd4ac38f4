#!/usr/bin/env bash
# BENCHMARKS § Shading: what the physically based model (issue 17) costs and whether frames
# stay exact. Bakes the demo car, CarConcept and GlassVaseFlowers (4-frame quarter orbit,
# 256², 4×), verifies each against the exact reference in blend/depth/saturate with PBR and
# in blend with the basic model (max channel difference, and the 8-bit sRGB player's; the
# recording excuses pixels at unordered samples: the `ordered` columns), then
# times `play --shading pbr|basic` on the same bakes, alternating, 6 rounds at 256² and 3 at
# 1024² (mean over rounds of each round's fastest frame). Prints tables; writes JSON to OUT.
# Run: bash scripts/bench-shading.sh [OUT]   (default bench-shading-out)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-bench-shading-out}"
mkdir -p "$out"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/xdg-runtime-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
scenes="${TRISORT_SCENES:-$(pwd)/../shared/scenes}"
cargo build --quiet --bin trisort
t="${CARGO_TARGET_DIR:-target}/debug/trisort"
path=orbit:frames=4,degrees=90
declare -A scene=([demo]=demo [car]="$scenes/CarConcept/CarConcept.glb"
  [vase]="$scenes/GlassVaseFlowers/GlassVaseFlowers.glb")
for b in demo car vase; do
  "$t" bake "${scene[$b]}" --path $path --size 256x256 --samples 4 --glass-opacity 0.35 \
    -o "$out/$b.baked" 2>/dev/null
  for m in blend depth saturate; do
    "$t" verify "$out/$b.baked" --scene "${scene[$b]}" --recording "$out/$b.baked.rec" \
      --mode $m --json > "$out/verify-$b-$m-pbr.json" || [ $? -eq 3 ]
  done
  "$t" verify "$out/$b.baked" --scene "${scene[$b]}" --recording "$out/$b.baked.rec" \
    --mode blend --shading basic --json > "$out/verify-$b-blend-basic.json" || [ $? -eq 3 ]
done
for size in 256x256 1024x1024; do
  rounds=6; [ $size = 256x256 ] || rounds=3
  for r in $(seq $rounds); do
    for b in demo car; do
      for s in pbr basic; do
        "$t" play "$out/$b.baked" --size $size --shading $s --json > "$out/play-$b-$size-$s-$r.json"
      done
    done
  done
done
"$t" play "$out/car.baked" --frames 0..1 --json > "$out/texture-bytes-car.json"
python3 - "$out" <<'PY'
import json, sys, glob, statistics
out = sys.argv[1]
print("scene  mode      shading  ok    unordered px  max diff  max diff ordered  8-bit sRGB max (ordered)")
for b in ("demo", "car", "vase"):
    for m, s in (("blend", "pbr"), ("depth", "pbr"), ("saturate", "pbr"), ("blend", "basic")):
        j = json.load(open(f"{out}/verify-{b}-{m}-{s}.json"))
        fr = j["frames"]
        mx = lambda k: max(f[k] for f in fr)
        s8 = max(f["srgb8"]["max_channel_diff"] for f in fr)
        s8o = max(f["srgb8"].get("max_channel_diff_ordered", 0) for f in fr)
        up = sum(f["unordered_pixels"] for f in fr)
        print(f"{b:6} {m:9} {s:8} {str(j['ok']):5} {up:12}  {mx('max_channel_diff'):8}  "
              f"{mx('max_channel_diff_ordered'):16}  {s8} ({s8o})")
print()
print("scene  size       pbr ms  basic ms  pbr/basic")
for b in ("demo", "car"):
    for size in ("256x256", "1024x1024"):
        ms = {}
        for s in ("pbr", "basic"):
            runs = [json.load(open(p)) for p in sorted(glob.glob(f"{out}/play-{b}-{size}-{s}-*.json"))]
            ms[s] = statistics.mean(min(f["gpu_ms"] for f in r["frames"]) for r in runs)
        print(f"{b:6} {size:10} {ms['pbr']:6.1f}  {ms['basic']:8.1f}  {ms['pbr'] / ms['basic']:.2f}")
j = json.load(open(f"{out}/texture-bytes-car.json"))
print(f"\nCarConcept texture bytes on the GPU: {j.get('texture_bytes')}")
PY
