#!/usr/bin/env bash
# Makes README's pictures from the real binary: docs/demo-frames.png (four frames of
# `trisort demo`) and docs/carconcept.png (CarConcept baked once at 480x270 4x with glass at
# 0.35, played in its default paint and in two KHR_materials_variants paints).
# Needs the scenes (TRISORT_SCENES, default ../shared/scenes) and python3-pil (installed
# when missing). Run: bash scripts/readme-pictures.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-lavapipe.sh
python3 -c 'import PIL' 2>/dev/null || bash scripts/apt-install.sh python3-pil
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/xdg-runtime-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
scenes="${TRISORT_SCENES:-$(pwd)/../shared/scenes}"
cargo build --quiet --bin trisort
trisort="${CARGO_TARGET_DIR:-target}/debug/trisort"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$trisort" demo --out-dir "$work/demo" >/dev/null
"$trisort" bake "$scenes/CarConcept/CarConcept.glb" \
  --path orbit:frames=3,degrees=100,elevation=12,distance=1.45,start=30 \
  --size 480x270 --samples 4 --glass-opacity 0.35 -o "$work/car.baked" 2>/dev/null
"$trisort" play "$work/car.baked" --out-dir "$work/car" >/dev/null
"$trisort" play "$work/car.baked" --frames 1..2 --variant "Pearly Swirly" --out-dir "$work/pearl" >/dev/null
"$trisort" play "$work/car.baked" --frames 1..2 --variant "Torched Graphite" --out-dir "$work/graphite" >/dev/null

python3 - "$work" <<'PY'
import sys
from PIL import Image
w = sys.argv[1]
def grid(paths, cols, out):
    ims = [Image.open(p).convert("RGB") for p in paths]
    iw, ih = ims[0].size
    rows = (len(ims) + cols - 1) // cols
    g = Image.new("RGB", (iw * cols, ih * rows))
    for k, im in enumerate(ims):
        g.paste(im, ((k % cols) * iw, (k // cols) * ih))
    g.save(out, optimize=True)
    print(f"wrote {out} ({g.size[0]}x{g.size[1]})")
grid([f"{w}/demo/frames/frame-{f:05d}.png" for f in (0, 14, 24, 36)], 4, "docs/demo-frames.png")
grid([f"{w}/car/frame-{f:05d}.png" for f in (0, 2)]
     + [f"{w}/pearl/frame-00001.png", f"{w}/graphite/frame-00001.png"], 2, "docs/carconcept.png")
PY
