#!/usr/bin/env bash
# The continuous model and both slicings (issue 41): every shared volume, views 30,20,0 and
# 75,-40,20, emission and Phong, 256x256, default flags otherwise. Each slicing (object; image at
# the default slab of one spacing) renders each --absorption model and is measured by
# `verify --reference continuous` against that model; the figure against the other model is the
# JSON's `continuous.models`. Prints a Markdown table, PSNR over premultiplied RGB, dB.
#
#   benches/models.sh [DATA_DIR]   (default ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data}
cargo build --release -q -p footprint-harness
fp=target/release/footprint
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fig() { python3 -c "
import json,sys
c=json.load(open(sys.argv[1]))['continuous']
m=c['models']
print(f\"{m['opacity']:.1f} {m['extinction']:.1f}\")" "$1"; }
echo "| volume | view | shading | object → opacity | image → opacity | object → extinction | image → extinction | (image opacity render vs extinction model) |"
echo "|---|---|---|---|---|---|---|---|"
for vol in "$data"/*/*.nhdr; do
  for view in 30,20,0 75,-40,20; do
    for shading in emission phong; do
      cells=()
      for model in opacity extinction; do
        for slicing in object image; do
          "$fp" verify "$vol" --size 256x256 --view "$view" --shading "$shading" \
            --slicing "$slicing" --absorption "$model" --reference continuous \
            --json "$tmp/v.json" > /dev/null 2>&1
          read -r op ex < <(fig "$tmp/v.json")
          if [ "$model" = opacity ]; then cells+=("$op"); [ "$slicing" = image ] && cross=$ex; else cells+=("$ex"); fi
        done
      done
      echo "| $(basename "$vol" .nhdr) | $view | $shading | ${cells[0]} dB | ${cells[1]} dB | ${cells[2]} dB | ${cells[3]} dB | $cross dB |"
    done
  done
done
