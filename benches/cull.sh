#!/usr/bin/env bash
# Occlusion culling's threshold against its error and its savings (issue 42): the CT head
# (ct-bone-skin, the default transfer function: bone behind skin), seen obliquely and from below,
# and the walnut, at 512x512 with default flags otherwise, object slicing and slabs, culling at
# each ε of EPS (and off). Per case:
#   - `render --json` on one thread: voxels culled, pixel updates and composites, against off;
#   - `footprint compare` against the unculled image: the largest change (bounded by ε) and PSNR;
#   - against the default continuous model (opacity reconstruction; `verify --reference
#     continuous --reference-out`, once per scene, then `compare`): the method's own error, which
#     culling should leave alone;
# Counts, not times (they are exact and need no quiet machine): what culling costs in time is
# timed by benches/peers.sh, culled and unculled alternately (docs/performance.md).
# Writes docs/perf/cull.csv and docs/charts/cull-threshold.{svg,png} (needs matplotlib: the venv
# benches/peers.sh makes, or any python3 with it).
#
#   benches/cull.sh
set -euo pipefail
cd "$(dirname "$0")/.."
data=../shared/data
cargo build --release -q -p footprint-harness
fp=target/release/footprint
py=target/peers/venv/bin/python
[ -x "$py" ] || py=python3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
csv=docs/perf/cull.csv
mkdir -p docs/perf docs/charts
echo "scene,slicing,eps,voxels,culled_voxels,pixel_updates,pixels_composited,max_change,psnr_vs_unculled_db,psnr_model_db" > "$csv"
scenes=(
  "headsq-oblique|$data/headsq/headsq_64x64x93_int16_le.nhdr|30,20,0"
  "headsq-below|$data/headsq/headsq_64x64x93_int16_le.nhdr|180,-90,0"
  "walnut|$data/walnut/walnut_128x96x114_uint16_le.nhdr|30,20,0"
)
json() { "$py" -c "import json,sys; j=json.load(open(sys.argv[1])); print(*(j[k] for k in sys.argv[2:]))" "$@"; }
for spec in "${scenes[@]}"; do
  IFS='|' read -r name vol view <<<"$spec"
  for slicing in object image; do
    common=("$vol" --size 512x512 --view "$view" --slicing "$slicing" --order front-to-back)
    "$fp" render "${common[@]}" --threads 1 -o "$tmp/off.pfm" --json "$tmp/off.json" >/dev/null
    # The continuous integral once per scene; each image is compared with it (the same PSNR
    # `verify` reports).
    "$fp" verify "${common[@]}" --reference continuous --reference-out "$tmp/model.pfm" >/dev/null 2>&1 || true
    for eps in off 0.001 0.004 0.02 0.1; do
      "$fp" render "${common[@]}" --cull "$eps" --threads 1 -o "$tmp/c.pfm" --json "$tmp/c.json" >/dev/null
      read -r voxels culled updates composites < <(json "$tmp/c.json" voxels culled_voxels pixel_updates pixels_composited)
      cmp=$("$fp" compare "$tmp/c.pfm" "$tmp/off.pfm" 2>&1 || true)
      change=$(sed -nE 's/^max \|A-B\| \/ peak\(B\) = ([0-9.e+-]+).*/\1/p' <<<"$cmp")
      psnr=$(sed -nE 's/.*PSNR ([0-9.inf]+) dB.*/\1/p' <<<"$cmp")
      model=$("$fp" compare "$tmp/c.pfm" "$tmp/model.pfm" 2>&1 | sed -nE 's/.*PSNR ([0-9.inf]+) dB.*/\1/p')
      echo "$name,$slicing,$eps,$voxels,$culled,$updates,$composites,${change:-0},${psnr:-inf},$model" | tee -a "$csv"
    done
  done
done
"$py" - "$csv" <<'PY'
import csv, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
for (scene, slicing) in dict.fromkeys((r["scene"], r["slicing"]) for r in rows):
    rs = [r for r in rows if r["scene"] == scene and r["slicing"] == slicing and r["eps"] != "off"]
    off = next(r for r in rows if r["scene"] == scene and r["slicing"] == slicing and r["eps"] == "off")
    eps = [float(r["eps"]) for r in rs]
    label = f"{scene}, {slicing}"
    seen = int(off["voxels"])
    axes[0].semilogx(eps, [100 * int(r["culled_voxels"]) / seen for r in rs], "o-", label=label)
    axes[1].semilogx(eps, [100 * int(r["pixel_updates"]) / int(off["pixel_updates"]) for r in rs], "o-", label=label)
    axes[2].semilogx(eps, [float(r["psnr_vs_unculled_db"]) for r in rs], "o-", label=label)
    axes[2].axhline(float(off["psnr_model_db"]), lw=0.6, ls=":", color=axes[2].lines[-1].get_color())
axes[0].set_ylabel("voxels culled, % of visible")
axes[1].set_ylabel("pixel updates, % of unculled")
axes[2].set_ylabel("PSNR vs unculled, dB (dotted: method vs model)")
for ax in axes:
    ax.set_xlabel("ε (a closed tile's pixels have opacity ≥ 1 − ε)")
    ax.grid(True, which="both", alpha=0.3)
axes[0].legend(fontsize=7)
fig.tight_layout()
fig.savefig("docs/charts/cull-threshold.svg")
fig.savefig("docs/charts/cull-threshold.png", dpi=90)
PY
echo "wrote $csv, docs/charts/cull-threshold.{svg,png}"
