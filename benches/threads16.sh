#!/usr/bin/env bash
# Thread scaling on a many-core machine (issue 42: 16 threads ≥ 10× one at 512² and 1024²).
#
#   benches/threads16.sh FOOTPRINT VOLDIR OUTDIR [MACHINE] [COMMIT] [SIZES] [THREADS]
#
# FOOTPRINT is a release build of `footprint`; VOLDIR holds the u8 volumes benches/peers.sh makes
# (walnut_u8.raw, headsq_u8.raw, blobs256_u8.raw); OUTDIR receives
#   - threads_long.csv: one row per run (volume, size, method, threads, first/median/min frame in ms,
#     the plan the default chose, the re-render's phases), appended as each run ends, so a run cut
#     short keeps what it measured;
#   - bench.jsonl: every run's `footprint bench --json`, one per line.
# benches/threads16_report.py turns threads_long.csv into docs/perf/threads16.csv.
#
# Each volume is rendered at azimuth 30 / elevation 20 (`--view 30,20,0`), grey ramp over the
# peers' u8 windows, `--frames 5 --orbit 2` (first = fresh frame with tables, classification and
# the default's pilot; median = re-render). Methods: the default (`--slicing auto`, its pilot free to
# subsample), object slicing and image-aligned slabs at full size (`--subsample 1`). Thread counts
# run alternately within a (volume, size, method) so their ratios share the same minutes.
set -euo pipefail
fp=$1; vols=$2; out=$3
machine=${4:-$(nproc)-core $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')}
commit=${5:-unknown}
read -r -a sizes <<<"${6:-512 1024}"
read -r -a threads <<<"${7:-1 16 2 8 4}"
mkdir -p "$out"
long=$out/threads_long.csv
jsonl=$out/bench.jsonl
[ -s "$long" ] || echo "machine,commit,date,volume,size,method,threads,first_ms,median_ms,min_ms,plan,classify_ms,tables_ms,splat_ms,composite_ms,resample_ms" > "$long"
date=$(date -u +%F)
# name | dims | spacing | window (u8 units)
volumes=(
  "walnut|128,96,114|1,1,1|40,255|walnut_u8.raw"
  "headsq|64,64,93|3.2,3.2,1.5|60,255|headsq_u8.raw"
  "blobs|256,256,256|1,1,1|80,255|blobs256_u8.raw"
)
methods=("default|--slicing auto" "object|--slicing object --subsample 1" "slabs|--slicing image --subsample 1")
for size in "${sizes[@]}"; do
  for spec in "${volumes[@]}"; do
    IFS='|' read -r name dims spacing window file <<<"$spec"
    for m in "${methods[@]}"; do
      IFS='|' read -r label flags <<<"$m"
      for t in "${threads[@]}"; do
        # shellcheck disable=SC2086 # the method's flags
        "$fp" bench "$vols/$file" --dims "$dims" --type u8 --spacing "$spacing" --window "$window" --tf grey \
          --size "${size}x$size" --view 30,20,0 --frames 5 --orbit 2 --threads "$t" $flags \
          --json "$out/b.json" >/dev/null
        tr -d '\n' < "$out/b.json" >> "$jsonl"; echo >> "$jsonl"
        python3 - "$out/b.json" "$machine,$commit,$date,$name,$size,$label,$t" >> "$long" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
p = j["plan"]
plan = f"{p['end']}/{p['precision']}/s={p['subsample']}"
ph = j.get("rerender_phases_ms") or {}
cols = [f"{j['first_ms']:.3f}", f"{j['median_ms']:.3f}", f"{j['min_ms']:.3f}", plan]
cols += [f"{ph.get(k, 0.0):.3f}" for k in ("classify", "tables", "splat", "composite", "resample")]
print(sys.argv[2] + "," + ",".join(cols))
PY
        tail -n 1 "$long"
      done
    done
  done
done
rm -f "$out/b.json"
