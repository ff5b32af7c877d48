#!/usr/bin/env bash
# The default plan, `--slicing auto` (issue 42): what it chooses and what it costs.
#
#   benches/default_plan.sh [DATA_DIR] [ROUNDS]   (defaults ../shared/data, 2)
#
# 1. Accuracy: every shared volume, views 30,20,0 and 75,-40,20, emission and Phong, 256x256,
#    default flags: `verify --reference continuous` measures the whole image against the default
#    (opacity) model; the JSON says what the pilot chose (`plan`), its bound on the pilot
#    (`quality.predicted_db`) and the seconds of its reference and candidate renders. `chosen`
#    is `sheets/nearest` where object slicing read at the nearest phase was kept (`/s=N` where it
#    is subsampled at 1/N), and the object
#    column is the first object-slicing candidate's bound (the nearest phase where it was tried).
# 2. Cost: each volume at 512x512, view 30,20,0, emission, one thread, `bench --frames 3
#    --orbit 2`, the default and `--slicing object` run alternately ROUNDS times; the minimum
#    over rounds of `first_ms` (a fresh volume: the pilot, which renders frame 1, included) and of
#    `median_ms` (re-renders, which keep frame 1's plan).
# Writes docs/perf/default-plan.csv and docs/perf/default-plan-cost.csv and prints both as
# Markdown tables.
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data}
rounds=${2:-2}
cargo build --release -q -p footprint-harness
fp=target/release/footprint
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p docs/perf
acc=docs/perf/default-plan.csv
echo "volume,view,shading,chosen,slab,pilot_bound_db,whole_image_db,object_pilot_db,pilot_reference_s,pilot_renders_s" > "$acc"
for vol in "$data"/*/*.nhdr; do
  for view in 30,20,0 75,-40,20; do
    for shading in emission phong; do
      "$fp" verify "$vol" --size 256x256 --view "$view" --shading "$shading" \
        --reference continuous --json "$tmp/v.json" > /dev/null
      python3 - "$tmp/v.json" "$(basename "$vol" .nhdr)" "$view" "$shading" >> "$acc" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
name, view, shading = sys.argv[2:]
plan, q = j["plan"], j.get("quality")
chosen = plan["end"] + ("/nearest" if plan.get("phase_lookup") == "nearest" else "")
chosen += f"/s={int(plan['subsample'])}" if plan.get("subsample", 1) > 1 else ""
slab = plan["slab"] if plan["slab"] is not None else ""
if q:
    pilot = q["pilot"]
    obj = next((t["bound_db"] for t in pilot["tried"] if not t["config"].startswith("image")), None)
    row = [f"{q['predicted_db']:.1f}", f"{j['continuous']['psnr_db']:.1f}",
           f"{obj:.1f}" if obj is not None else "", f"{pilot['reference_seconds']:.2f}",
           f"{pilot['render_seconds']:.2f}"]
else:
    row = ["", f"{j['continuous']['psnr_db']:.1f}", "", "", ""]
print(",".join([name, f'"{view}"', shading, chosen, str(slab)] + row))
PY
    done
  done
done
cost=docs/perf/default-plan-cost.csv
echo "volume,round,slicing,plan,first_ms,median_ms,plan_ms" > "$cost"
for vol in "$data"/*/*.nhdr; do
  name=$(basename "$vol" .nhdr)
  for r in $(seq 1 "$rounds"); do
    for slicing in auto object; do
      "$fp" bench "$vol" --size 512x512 --view 30,20,0 --threads 1 --frames 3 --orbit 2 \
        --slicing "$slicing" --json "$tmp/b.json" > /dev/null
      python3 -c "
import json,sys
j=json.load(open('$tmp/b.json'))
p=j['plan']
print(f\"$name,$r,$slicing,{p['end']}{'/nearest' if p.get('phase_lookup') == 'nearest' else ''}{'/s='+str(int(p['subsample'])) if p.get('subsample', 1) > 1 else ''}{'' if p['slab'] is None else ' '+str(p['slab'])},{j['first_ms']:.1f},{j['median_ms']:.1f},{j['plan_ms']:.1f}\")" >> "$cost"
    done
  done
done
python3 - "$acc" "$cost" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("| volume | view | shading | chosen | pilot bound | whole image | object on the pilot | pilot reference, renders |")
print("|---|---|---|---|---|---|---|---|")
for r in rows:
    ch = r["chosen"] + (f" {r['slab']}" if r["slab"] else "")
    print(f"| {r['volume']} | {r['view']} | {r['shading']} | {ch} | {r['pilot_bound_db']} dB | "
          f"{r['whole_image_db']} dB | {r['object_pilot_db']} dB | {r['pilot_reference_s']} s, {r['pilot_renders_s']} s |")
print()
cost = list(csv.DictReader(open(sys.argv[2])))
vols = sorted({r["volume"] for r in cost})
print("| volume | default plan | default fresh | object fresh | fresh ratio | default re-render | object re-render | re-render ratio |")
print("|---|---|---|---|---|---|---|---|")
for v in vols:
    m = {}
    for s in ("auto", "object"):
        rs = [r for r in cost if r["volume"] == v and r["slicing"] == s]
        m[s] = (min(float(r["first_ms"]) for r in rs), min(float(r["median_ms"]) for r in rs), rs[0]["plan"])
    a, o = m["auto"], m["object"]
    print(f"| {v} | {a[2]} | {a[0]:.0f} ms | {o[0]:.0f} ms | {a[0]/o[0]:.2f}× | {a[1]:.0f} ms | {o[1]:.0f} ms | {a[1]/o[1]:.2f}× |")
PY
