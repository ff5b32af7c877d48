#!/usr/bin/env bash
# Perspective (issue 13), measured: writes docs/perspective.md and the pictures it shows.
#
#   benches/perspective.sh [--reps N]
#
# 1. `footprint verify --perspective 30|60` on every volume in ../shared/data at 512x512, views
#    30,20,0 and 120,-35,0, against the exact-ray f64 reference (each kernel integrated along each
#    pixel's own diverging ray): PSNR and max |error|.
# 2. How that error grows: with the field of view (10...120 degrees, headsq and heart, 512x512,
#    view 30,20,0) and with the footprint size (image 128...1024 at 60 degrees; footprints grow
#    with the image).
# 3. What per-voxel footprints cost: `footprint bench` on walnut, 512x512, view 30,20,0, one
#    thread, alternately (these machines are noisy; only ratios in one run mean much): orthographic
#    with its default view table and stencils, orthographic with the direct method (the generic
#    table sampled through one footprint), perspective 60 (the generic table sampled through each
#    voxel's own footprint); medians over the repetitions of first_ms and median_ms (--frames 5,
#    --orbit 2).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
reps=5
while [ $# -gt 0 ]; do
  case "$1" in
    --reps) reps=$2; shift 2 ;;
    *) echo "usage: $0 [--reps N]"; exit 2 ;;
  esac
done
data=$root/../shared/data
cargo build --release -q -p footprint-harness
fp=$root/target/release/footprint
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
out=docs/perspective.md
psnr() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print('%.2f %.2e' % (d['overall']['psnr_db'], d['overall']['max_abs']))" "$1"; }
volumes=(
  "headsq/headsq_64x64x93_int16_le.nhdr"
  "heart/heart_32x32x12_float32_le.nhdr"
  "hydrogen/hydrogen_orbital_64x64x64_float32_le.nhdr"
  "neghip/neghip_64x64x64_uint8.nhdr"
  "walnut/walnut_128x96x114_uint16_le.nhdr"
)
{
  echo "# Perspective, measured"
  echo
  echo "Regenerate with \`benches/perspective.sh\` ($(date -u +%Y-%m-%d), $(nproc) cores, $(uname -m))."
  echo "Emission, each volume's default window and the grey ramp, table 129 bilinear (the generic"
  echo "table sampled directly through each voxel's own footprint), against the exact-ray f64"
  echo "reference (\`footprint verify\`: PSNR over RGB, premultiplied linear values)."
  echo
  echo "## Every shared volume, 512x512"
  echo
  echo "| volume | view | FOV 30: PSNR dB | max abs | FOV 60: PSNR dB | max abs |"
  echo "|---|---|---|---|---|---|"
} > "$out"
for v in "${volumes[@]}"; do
  for view in 30,20,0 120,-35,0; do
    row="| $(basename "$(dirname "$v")") | $view"
    for fov in 30 60; do
      "$fp" verify "$data/$v" --size 512x512 --view "$view" --perspective "$fov" --json "$work/v.json" > /dev/null 2>&1
      read -r db mx < <(psnr "$work/v.json")
      row="$row | $db | $mx"
    done
    echo "$row |" >> "$out"
  done
done
{
  echo
  echo "## How the error grows"
  echo
  echo "With the field of view (512x512, view 30,20,0; the eye at VTK's ResetCamera distance, so a"
  echo "wider field brings it nearer and the volume's depth spans more of the eye's distance):"
  echo
  echo "| FOV, degrees | headsq PSNR dB | heart PSNR dB |"
  echo "|---|---|---|"
} >> "$out"
for fov in 10 30 60 90 120; do
  row="| $fov"
  for v in "${volumes[0]}" "${volumes[1]}"; do
    if "$fp" verify "$data/$v" --size 512x512 --view 30,20,0 --perspective "$fov" --json "$work/v.json" > "$work/log" 2>&1; then
      read -r db _ < <(psnr "$work/v.json")
      row="$row | $db"
    else
      row="$row | refused: $(sed -n 's/^footprint: //p' "$work/log" | head -1 | cut -c1-60)..."
    fi
  done
  echo "$row |" >> "$out"
done
{
  echo
  echo "With the footprint size (FOV 60, view 30,20,0; footprints grow with the image; the half-extent"
  echo "is the volume centre's footprint, from the JSON):"
  echo
  echo "| image | headsq: centre footprint half-extent px | PSNR dB | heart: half-extent px | PSNR dB |"
  echo "|---|---|---|---|---|"
} >> "$out"
for size in 128 256 512 1024; do
  row="| ${size}x$size"
  for v in "${volumes[0]}" "${volumes[1]}"; do
    "$fp" verify "$data/$v" --size ${size}x$size --view 30,20,0 --perspective 60 --json "$work/v.json" > /dev/null 2>&1
    read -r db _ < <(psnr "$work/v.json")
    ext=$(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print('%.1f' % max(d['footprint_half_extent_px']))" "$work/v.json")
    row="$row | $ext | $db"
  done
  echo "$row |" >> "$out"
done
# 3. Cost, alternately.
walnut=$data/walnut/walnut_128x96x114_uint16_le.nhdr
declare -A first median
configs=("ortho-view" "ortho-direct" "persp-60")
for c in "${configs[@]}"; do first[$c]=""; median[$c]=""; done
for rep in $(seq "$reps"); do
  for c in "${configs[@]}"; do
    case $c in
      ortho-view) extra=() ;;
      ortho-direct) extra=(--method direct) ;;
      persp-60) extra=(--perspective 60) ;;
    esac
    "$fp" bench "$walnut" --size 512x512 --view 30,20,0 --frames 5 --orbit 2 --threads 1 "${extra[@]}" --json "$work/b.json" > /dev/null 2>&1
    read -r a b < <(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['first_ms'], d['median_ms'])" "$work/b.json")
    first[$c]="${first[$c]} $a"; median[$c]="${median[$c]} $b"
  done
done
med() { python3 -c "import statistics,sys; print('%.1f' % statistics.median(map(float, sys.argv[1:])))" $1; }
{
  echo
  echo "## What per-voxel footprints cost"
  echo
  echo "\`footprint bench\` walnut, 512x512, view 30,20,0, one thread, --frames 5 --orbit 2, the three"
  echo "configurations run alternately, $reps repetitions; medians of first_ms (fresh volume) and"
  echo "median_ms (re-render), and each over the orthographic default's:"
  echo
  echo "| configuration | first ms | re-render ms | re-render / orthographic default |"
  echo "|---|---|---|---|"
} >> "$out"
base=$(med "${median[ortho-view]}")
for c in "${configs[@]}"; do
  f=$(med "${first[$c]}"); m=$(med "${median[$c]}")
  r=$(python3 -c "print('%.2f' % ($m / $base))")
  echo "| $c | $f | $m | ${r}x |" >> "$out"
done
cat "$out"
