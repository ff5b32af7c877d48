#!/usr/bin/env bash
# Post-classification's two reconstructions (issue 75): `--classification post --reconstruction
# kernel|trilinear` at their default slabs, against the post-classified continuous integral of
# the same reconstruction (`verify --reference continuous`: an f64 march, converged), and timed.
#
#   benches/post_reconstruction.sh [--reps N] [FOOTPRINT_BINARY]
#
# Volumes: benches/ct_phantom.py's real-size CT (256x256x113, 1:1:2, ramp 1200..2400) and the
# shared walnut, headsq, neghip and hydrogen (the window `info` picks). Accuracy: views 30,20,0
# and 0,0,0, emission and Phong, 512². Time: view 30,20,0, emission, 512², one thread, `bench
# --frames 3 --orbit 2`, the two reconstructions run alternately N times (default 3; medians).
# Writes docs/perf/post-reconstruction.csv.
#
# With VTK_PYTHON set to a Python that has the `vtk` package, the CT is also rendered by VTK's
# vtkFixedPointVolumeRayCastMapper on one thread (../shared/peers/vtk_render.py, azimuth 30 /
# elevation 20, the grey ramp 1200..2400 as opacity and colour, opacity unit distance 1), timed
# alternately with both reconstructions at VTK's exact camera (its view as --view-matrix), and
# every image is measured against both post-classified integrals: docs/perf/post-vtk.csv.
# VTK_ONLY=1 measures that part alone.
set -euo pipefail
# shellcheck source=benches/bench_common.sh
source "$(dirname "$0")/bench_common.sh"
work=$root/target/post-reconstruction
mkdir -p "$work" docs/perf
ct=$root/target/real-size/ct.nhdr
if [ ! -s "$ct" ]; then
  python3 -m venv "$work/venv" && "$work/venv/bin/pip" install -q numpy
  mkdir -p "$root/target/real-size" && "$work/venv/bin/python" benches/ct_phantom.py "${ct%.nhdr}"
fi
data=$root/../shared/data
[ -d "$data" ] || data=$root/tests/data
volumes=(
  "ct|$ct|--window 1200,2400"
  "walnut|$data/walnut/walnut_128x96x114_uint16_le.nhdr|"
  "headsq|$data/headsq/headsq_64x64x93_int16_le.nhdr|"
  "neghip|$data/neghip/neghip_64x64x64_uint8.nhdr|"
  "hydrogen|$data/hydrogen/hydrogen_orbital_64x64x64_float32_le.nhdr|"
)
csv=docs/perf/post-reconstruction.csv
field() { python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print($2)" "$1"; }
cpu="$(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores"
today=$(date +%F)
[ "${VTK_ONLY:-0}" = 1 ] || {
echo "volume,view,shading,reconstruction,slab,value_subsample,psnr_own_db,first_ms,median_ms,date,cpu" > "$csv"
for v in "${volumes[@]}"; do
  IFS='|' read -r name file window <<<"$v"
  [ -s "$file" ] || { echo "skipping $name: $file missing"; continue; }
  # Time: both reconstructions alternately.
  declare -A first=() median=()
  for rep in $(seq "$reps"); do
    for r in kernel trilinear; do
      # shellcheck disable=SC2086
      "$fp" bench "$file" $window --tf grey --view 30,20,0 --size 512x512 --threads 1 \
        --classification post --reconstruction "$r" --frames 3 --orbit 2 --json "$work/b.json" > /dev/null
      first[$r]="${first[$r]:-} $(field "$work/b.json" "j['first_ms']")"
      median[$r]="${median[$r]:-} $(field "$work/b.json" "j['median_ms']")"
    done
  done
  med() { tr ' ' '\n' | sed '/^$/d' | sort -g | awk '{a[NR]=$1} END {printf "%.1f", a[int((NR+1)/2)]}'; }
  for view in 30,20,0 0,0,0; do
    for shading in emission phong; do
      for r in kernel trilinear; do
        # shellcheck disable=SC2086
        "$fp" verify "$file" $window --tf grey --view "$view" --size 512x512 --shading "$shading" \
          --classification post --reconstruction "$r" --reference continuous --json "$work/v.json" > /dev/null
        db=$(field "$work/v.json" "f\"{j['continuous']['psnr_db']:.2f}\"")
        slab=$(field "$work/v.json" "f\"{j['slab']:.2g}\"")
        vs=$(field "$work/v.json" "int(j['value_subsample'])")
        t1=; t2=
        if [ "$view" = 30,20,0 ] && [ "$shading" = emission ]; then
          t1=$(echo "${first[$r]}" | med); t2=$(echo "${median[$r]}" | med)
        fi
        echo "$name,\"$view\",$shading,$r,$slab,$vs,$db,$t1,$t2,$today,\"$cpu\"" >> "$csv"
      done
    done
  done
  unset first median
done
cat "$csv"
}

[ -n "${VTK_PYTHON:-}" ] || exit 0
peers=$root/../shared/peers
vcsv=docs/perf/post-vtk.csv
echo "volume,renderer,slab,first_ms,median_ms,psnr_kernel_db,psnr_trilinear_db,date,cpu" > "$vcsv"
raw=${ct%.nhdr}.raw
vtk() {
  VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow "$VTK_PYTHON" "$peers/vtk_render.py" "$raw" 256 256 113 \
    --dtype u16 --spacing 1 1 2 --size 512 512 --tf 1200 2400 --azimuth 30 --elevation 20 \
    --opacity-unit-distance 1 --mapper fixedpoint --threads 1 --frames 3 --out "$work/vtk-ct" > /dev/null
}
vtk
# VTK's camera as Footprint's world-to-screen matrix (rows right, down, away; pixels per unit).
vm=$("$VTK_PYTHON" benches/vtk_view_matrix.py "$work/vtk-ct.json" 512)
common=("$ct" --window 1200,2400 --tf grey --view-matrix "$vm" --size 512x512)
declare -A first=() median=()
for rep in $(seq "$reps"); do
  vtk
  first[vtk]="${first[vtk]:-} $(field "$work/vtk-ct.json" "j['seconds']['warmup_total']*1e3")"
  median[vtk]="${median[vtk]:-} $(field "$work/vtk-ct.json" "j['seconds']['frame']['median']*1e3")"
  for r in kernel trilinear; do
    "$fp" bench "${common[@]}" --threads 1 --classification post --reconstruction "$r" --frames 3 \
      --orbit 2 --json "$work/b.json" > /dev/null
    first[$r]="${first[$r]:-} $(field "$work/b.json" "j['first_ms']")"
    median[$r]="${median[$r]:-} $(field "$work/b.json" "j['median_ms']")"
  done
done
for r in kernel trilinear; do
  "$fp" verify "${common[@]}" --classification post --reconstruction "$r" --reference continuous \
    --json "$work/v-$r.json" --out "$work/post-$r.pfm" --reference-out "$work/ref-$r.pfm" > /dev/null
done
"$VTK_PYTHON" - "$work" "$vcsv" "$today" "$cpu" "${first[vtk]}" "${median[vtk]}" "${first[kernel]}" \
  "${median[kernel]}" "${first[trilinear]}" "${median[trilinear]}" <<'PY'
import json, statistics, sys, numpy as np
sys.path.insert(0, "benches")
from images import pfm, psnr
work, out, today, cpu = sys.argv[1:5]
times = [statistics.median(float(x) for x in a.split()) for a in sys.argv[5:11]]
ref = {r: pfm(f"{work}/ref-{r}.pfm") for r in ("kernel", "trilinear")}
img = {"vtk": np.fromfile(f"{work}/vtk-ct.rgba.f32.raw", np.float32).reshape(512, 512, 4)[..., :3]}
img.update({r: pfm(f"{work}/post-{r}.pfm") for r in ("kernel", "trilinear")})
slab = {"vtk": "-"}
slab.update({r: f"{json.load(open(f'{work}/v-{r}.json'))['slab']:.2g}" for r in ("kernel", "trilinear")})
with open(out, "a") as f:
    for i, name in enumerate(("vtk", "kernel", "trilinear")):
        label = "vtk-fixedpoint" if name == "vtk" else f"footprint-post-{name}"
        k, t = psnr(img[name], ref["kernel"]), psnr(img[name], ref["trilinear"])
        f.write(f'ct,{label},{slab[name]},{times[2 * i]:.1f},{times[2 * i + 1]:.1f},{k:.2f},{t:.2f},{today},"{cpu}"\n')
PY
cat "$vcsv"
