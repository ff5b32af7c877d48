#!/usr/bin/env bash
# Object against image slicing, both against the continuous integral (issue 12): every shared
# volume, views 0,0,0 and 30,20,0, emission and Phong, 256x256, slabs of 0.5, 1 and 2 voxel
# spacings. Prints a Markdown table: PSNR (RGB) against `verify --reference continuous` and the
# core's frame seconds (two threads), object and image slicing rendered alternately.
#
#   benches/slicing.sh [DATA_DIR]   (default ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data}
cargo build --release -q -p footprint-harness
fp=target/release/footprint
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
field() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(f\"{d['continuous']['psnr_db']:.1f} {d['core_seconds']:.3f}\")" "$1"; }
echo "| volume | view | shading | object dB | image 2 dB | image 1 dB | image 0.5 dB | object s | image 2 s | image 1 s | image 0.5 s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for vol in "$data"/*/*.nhdr; do
  for view in 0,0,0 30,20,0; do
    for shading in emission phong; do
      row=()
      times=()
      for cfg in "object 1" "image 2" "image 1" "image 0.5"; do
        set -- $cfg
        "$fp" verify "$vol" --size 256x256 --view "$view" --shading "$shading" --threads 2 \
          --slicing "$1" --slab "$2" --reference continuous --json "$tmp/v.json" > /dev/null 2>&1
        read -r db s < <(field "$tmp/v.json")
        row+=("$db")
        times+=("$s")
      done
      echo "| $(basename "$vol" .nhdr) | $view | $shading | ${row[0]} | ${row[1]} | ${row[2]} | ${row[3]} | ${times[0]} | ${times[1]} | ${times[2]} | ${times[3]} |"
    done
  done
done
