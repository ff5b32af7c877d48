#!/usr/bin/env bash
# The real-size CT benchmark (issue 74): benches/ct_phantom.py's 256x256x113 CT head phantom
# (uint16, spacing 1:1:2, dense bone), grey ramp 1200..2400, view 30,20,0, 512², one thread.
#
#   benches/real_size.sh [--reps N] [FOOTPRINT_BINARY]
#
# Per method, run alternately N times (default 3; these machines are noisy): `footprint bench
# --frames 4 --orbit 2 --threads 1 --json` (first_ms = a fresh volume, median_ms = re-render,
# with the phases' split from the text output), then once `footprint verify --reference continuous`
# (the default model: opacity reconstruction). Methods: the default plan; object slicing; slabs
# 1 and 2 spacings thick, each cut per pixel and through section stencils (--depth-phases 8,
# --phases 8). Writes docs/perf/real-size.csv (medians) for benches/peers_report.py, which puts it
# in docs/performance.md.
set -euo pipefail
# shellcheck source=benches/bench_common.sh
source "$(dirname "$0")/bench_common.sh"
work=$root/target/real-size
mkdir -p "$work" docs/perf
# numpy for the phantom: benches/peers.sh's venv if it is there, else one of its own.
py=$root/target/peers/venv/bin/python
if [ ! -x "$py" ]; then
  [ -x "$work/venv/bin/python" ] || python3 -m venv "$work/venv"
  "$work/venv/bin/pip" install -q numpy
  py=$work/venv/bin/python
fi
[ -s "$work/ct.nhdr" ] || "$py" benches/ct_phantom.py "$work/ct"
common=("$work/ct.nhdr" --window 1200,2400 --tf grey --view 30,20,0 --size 512x512 --threads 1)
fixed=(--lod 0 --supersample 1 --subsample 1)
methods=(
  "default|"
  "object|--slicing object ${fixed[*]}"
  "slabs 1|--slicing image --slab 1 ${fixed[*]}"
  "slabs 1 + section stencils|--slicing image --slab 1 --depth-phases 8 --phases 8 ${fixed[*]}"
  "slabs 2|--slicing image --slab 2 ${fixed[*]}"
  "slabs 2 + section stencils|--slicing image --slab 2 --depth-phases 8 --phases 8 ${fixed[*]}"
)
raw=$work/runs.csv
echo "method,rep,first_ms,median_ms,splat_ms,composite_ms" > "$raw"
for rep in $(seq "$reps"); do
  for m in "${methods[@]}"; do
    IFS='|' read -r name flags <<<"$m"
    # shellcheck disable=SC2086
    "$fp" bench "${common[@]}" $flags --frames 4 --orbit 2 --json "$work/b.json" > "$work/b.txt"
    # The last frame's splat and composite phases, ms.
    phases=$(grep '^frame' "$work/b.txt" | tail -1 | sed -E 's/.*splat ([0-9.]+), composite ([0-9.]+).*/\1,\2/')
    "$py" -c "import json; j=json.load(open('$work/b.json')); print(f'$name,$rep,{j[\"first_ms\"]:.1f},{j[\"median_ms\"]:.1f},$phases')" >> "$raw"
  done
done
csv=docs/perf/real-size.csv
echo "method,first_ms,median_ms,splat_ms,composite_ms,psnr_continuous_db,pixel_updates,date,cpu" > "$csv"
cpu=$(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -1)
cpu="$cpu, $(nproc) cores"
today=$(date +%F)
for m in "${methods[@]}"; do
  IFS='|' read -r name flags <<<"$m"
  # shellcheck disable=SC2086
  "$fp" verify "${common[@]}" $flags --reference continuous --json "$work/v.json" >/dev/null
  # shellcheck disable=SC2086
  "$fp" render "${common[@]}" $flags --out "$work/r.pfm" --json "$work/r.json" >/dev/null
  "$py" - "$raw" "$name" "$work/v.json" "$work/r.json" "$today" "$cpu" >> "$csv" <<'PY'
import csv, json, statistics, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["method"] == sys.argv[2]]
med = lambda k: statistics.median(float(r[k]) for r in rows)
v, r = json.load(open(sys.argv[3])), json.load(open(sys.argv[4]))
print(f'"{sys.argv[2]}",{med("first_ms"):.1f},{med("median_ms"):.1f},{med("splat_ms"):.1f},'
      f'{med("composite_ms"):.1f},{v["continuous"]["psnr_db"]:.2f},{int(r["pixel_updates"])},'
      f'{sys.argv[5]},"{sys.argv[6]}"')
PY
done
cat "$csv"
