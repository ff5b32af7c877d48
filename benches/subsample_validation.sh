#!/usr/bin/env bash
# What `--subsample auto` costs in accuracy, on every volume in ../shared/data and the built-in
# scene, at two views and two shadings, 512x512: `footprint verify --reference
# continuous` with --subsample 1 and auto. Writes docs/subsample-validation.md (and the raw rows
# to docs/perf/subsample-validation.csv).
#
#   benches/subsample_validation.sh
#
# "f64" is the PSNR against the full-size f64 splatting reference (what subsampling changes: the
# full-size float render's own figure there is the table error, 80-100 dB); "continuous" is
# against the volume-rendering integral, the figure a user sees. Both RGB, peak 1.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
cargo build --release -q -p footprint-harness
fp=$root/target/release/footprint
data=$root/../shared/data
csv=docs/perf/subsample-validation.csv
mkdir -p docs/perf
echo "volume,size,view,shading,factor,f64_full_db,f64_sub_db,continuous_full_db,continuous_sub_db,ms_full,ms_sub" > "$csv"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
volumes=(builtin)
for f in "$data"/*/*.nhdr; do volumes+=("$f"); done
for vol in "${volumes[@]}"; do
  src=(); [ "$vol" != builtin ] && src=("$vol")
  name=$(basename "$vol" .nhdr)
  for size in 512; do
    for view in 30,20,0 75,-40,20; do
      for shading in emission phong; do
        for sub in 1 auto; do
          "$fp" verify "${src[@]}" --size "${size}x$size" --view "$view" --shading "$shading" \
            --subsample "$sub" --reference continuous --threads 2 --json "$tmp/$sub.json" >/dev/null 2>&1
        done
        python3 - "$tmp" "$name" "$size" "$view" "$shading" >> "$csv" <<'PY'
import json, sys
tmp, name, size, view, shading = sys.argv[1:]
a, b = (json.load(open(f"{tmp}/{s}.json")) for s in ("1", "auto"))
print(f"{name},{size},\"{view}\",{shading},{int(b['subsample'])},"
      f"{a['overall']['psnr_db']:.2f},{b['overall']['psnr_db']:.2f},"
      f"{a['continuous']['psnr_db']:.2f},{b['continuous']['psnr_db']:.2f},"
      f"{a['core_seconds']*1e3:.1f},{b['core_seconds']*1e3:.1f}")
PY
      done
    done
  done
  echo "$name done"
done
python3 - "$csv" docs/subsample-validation.md <<'PY'
import csv, sys, datetime
rows = list(csv.DictReader(open(sys.argv[1])))
out = [
    "# `--subsample auto`: accuracy on every shared volume",
    "",
    f"Generated {datetime.date.today().isoformat()} by `benches/subsample_validation.sh`: `footprint verify "
    "--reference continuous` with `--subsample 1` and `auto`, float, default table, each volume's default "
    "window and transfer function. *s* is the factor auto chose (1: the image is the full-size one, bit for "
    "bit). PSNR is RGB, peak 1. *f64*: against the full-size f64 splatting reference; *continuous*: against "
    "the volume-rendering integral. Times are the core's frame on 2 threads, fresh (one run each, so only "
    "a rough guide; `docs/performance.md` has measured ratios).",
    "",
    "| volume | size | view | shading | s | f64, full → auto | continuous, full → auto | change | ms, full → auto |",
    "|---|---|---|---|---|---|---|---|---|",
]
worst = 0.0
for r in rows:
    d = float(r["continuous_sub_db"]) - float(r["continuous_full_db"])
    if r["factor"] != "1":
        worst = min(worst, d)
    out.append(f"| {r['volume']} | {r['size']}² | {r['view']} | {r['shading']} | {r['factor']} | "
               f"{float(r['f64_full_db']):.1f} → {float(r['f64_sub_db']):.1f} dB | "
               f"{float(r['continuous_full_db']):.2f} → {float(r['continuous_sub_db']):.2f} dB | {d:+.2f} dB | "
               f"{float(r['ms_full']):.0f} → {float(r['ms_sub']):.0f} |")
sub = [r for r in rows if r["factor"] != "1"]
out += ["", f"{len(sub)} of {len(rows)} cases subsampled; the largest loss against the continuous integral "
        f"among them is {-worst:.2f} dB.", ""]
open(sys.argv[2], "w").write("\n".join(out))
PY
echo "wrote docs/subsample-validation.md"
