#!/usr/bin/env bash
# Footprint side by side with the renderers a user would pick instead, on one machine, run
# alternately (these machines are shared and noisy: only ratios measured in one session mean much).
#
#   benches/peers.sh [--reps N] [--frames N] [--quick]
#
# Installs what it needs (Debian: libvolpack1-dev, libosmesa6, libegl-mesa0; a Python venv with vtk,
# numpy, pillow, matplotlib under target/peers/), builds ../shared/peers/vp_bench.c, and renders at
# 512x512, azimuth 30 / elevation 20, orthographic, emission, grey ramp, on:
#   - the 256^3 blobs of ../shared/peers/make_volumes.py;
#   - ../shared/data/walnut and headsq, quantised once to u8 over their full range (VolPack reads u8
#     only, so all three renderers get the same u8 file);
#   - the real-size CT phantom of benches/ct_phantom.py (256x256x113, spacing 1:1:2, dense bone;
#     issue 74), quantised to u8 over CT numbers 0..3071 (its ramp 100..200 is 1200..2400).
# The camera is VTK's (Azimuth, Elevation, the bounding sphere fitted to the image height): the
# script reads it from VTK's JSON and hands Footprint the same world-to-screen matrix
# (--view-matrix), so coverage matches; a side-by-side picture per volume goes to
# docs/images/peers-*.png to check by eye. Opacity is per world unit in all three (VTK's
# --opacity-unit-distance 1; VolPack's per-slice opacity equals it at unit spacing).
#
# Per volume and repetition, in this order: Footprint's default (`--slicing auto`: object slicing
# where its pilot measures 44 dB against the continuous model, slabs otherwise, each subsampled
# first where the footprints allow it; fresh includes the pilot) on 1 and 2 threads, object slicing float 1 thread, float 2 threads, fixed 1 thread, float with --subsample auto on 1 and 2 threads, image-aligned slabs (--slicing image) on
# 1 and 2 threads, object slicing and slabs with occlusion culling (--cull 0.004) on 1 and 2
# threads (each `footprint bench --frames N --orbit 2`: first_ms = fresh volume, median_ms =
# re-render), post-classified slabs on 1 thread, VTK vtkFixedPointVolumeRayCastMapper 1 and 2
# threads, VolPack pre-classified. Once per volume, each of those methods against the default
# continuous model (`verify --reference continuous`) and its culled voxels: docs/perf/methods.csv.
# The 16-core table comes from docs/perf/threads16.csv (benches/threads16.sh and
# benches/threads16_report.py, run on a lent machine). The
# medians over the repetitions go to docs/performance.md as ratios; the raw rows to
# docs/perf/peers.csv. After VolPack in each repetition, benches/floor.rs times the scene's
# unavoidable work at 512² (its pixel updates and composites, counted by `footprint render --json`,
# in the simplest vectorised loops): docs/perf/floor.csv. Once per volume, `footprint verify --reference continuous` with
# --subsample 1 and auto measures what subsampling costs in accuracy (docs/perf/subsample.csv). Then the scaling runs (Footprint only): frame time against image size
# (128^2 ... 2048^2, blobs) and against volume size (64^3 ... 512^3, synthetic blobs), charted in
# docs/charts/perf-scaling.svg/.png with docs/perf/scaling.csv.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
reps=5
frames=10
quick=0
while [ $# -gt 0 ]; do
  case "$1" in
    --reps) reps=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --quick) quick=1; reps=1; frames=3; shift ;;
    *) echo "usage: $0 [--reps N] [--frames N] [--quick]"; exit 2 ;;
  esac
done
peers=$root/../shared/peers
data=$root/../shared/data
work=$root/target/peers
mkdir -p "$work/out" docs/perf docs/charts docs/images

echo "== set-up"
if ! dpkg -s libvolpack1-dev libosmesa6 libegl-mesa0 >/dev/null 2>&1; then
  apt-get update -qq && apt-get install -y -qq libosmesa6 libegl-mesa0 libvolpack1-dev >/dev/null
fi
[ -x "$work/venv/bin/python" ] || python3 -m venv "$work/venv"
"$work/venv/bin/pip" install -q vtk numpy pillow matplotlib
py=$work/venv/bin/python
gcc -O2 -o "$work/vp_bench" "$peers/vp_bench.c" -lvolpack -lm
cargo build -q --release -p footprint-harness
cargo bench -q --bench floor --no-run 2>/dev/null
fp=$root/target/release/footprint

echo "== volumes"
[ -s "$peers/data/blobs256_u8.raw" ] && cp "$peers/data/blobs256_u8.raw" "$work/" 2>/dev/null || true
if [ ! -s "$work/blobs256_u8.raw" ]; then
  (cd "$work" && cp "$peers/make_volumes.py" . && "$py" make_volumes.py >/dev/null && cp data/blobs256_u8.raw .)
fi
"$py" - "$data" "$work" <<'PY'
import sys, numpy as np
data, work = sys.argv[1], sys.argv[2]
for name, path, dt, dims in [
    ("walnut", f"{data}/walnut/walnut.raw", "<u2", (114, 96, 128)),
    ("headsq", f"{data}/headsq/headsq_64x64x93_int16_le.raw", "<i2", (93, 64, 64)),
]:
    v = np.fromfile(path, dt).astype(np.float64).reshape(dims)
    u8 = np.round(255 * (v - v.min()) / (v.max() - v.min())).astype(np.uint8)
    u8.tofile(f"{work}/{name}_u8.raw")
PY
[ -s "$work/ct.raw" ] || "$py" benches/ct_phantom.py "$work/ct" >/dev/null
"$py" - "$work" <<'PY'
import sys, numpy as np
work = sys.argv[1]
v = np.fromfile(f"{work}/ct.raw", "<u2").astype(np.float64)
np.round(np.clip(v, 0, 3071) * 255 / 3071).astype(np.uint8).tofile(f"{work}/ctphantom_u8.raw")
PY

# name | dims (x y z) | spacing | ramp LO HI (u8 units)
volumes=(
  "blobs|256 256 256|1 1 1|80 255"
  "walnut|128 96 114|1 1 1|40 255"
  "headsq|64 64 93|3.2 3.2 1.5|60 255"
  "ctphantom|256 256 113|1 1 2|100 200"
)
[ "$quick" = 1 ] && volumes=("${volumes[1]}")

csv=docs/perf/peers.csv
echo "volume,rep,renderer,threads,accum,first_ms,median_ms,culled_voxels" > "$csv"
mcsv=docs/perf/methods.csv
echo "volume,method,psnr_continuous_db,psnr_f64_db,voxels,culled_voxels,pixel_updates" > "$mcsv"
# Occlusion culling's threshold in the runs: 1/255, one 8-bit step at most per pixel.
cull=0.004
acsv=docs/perf/subsample.csv
echo "volume,subsample,factor,psnr_f64_db,psnr_continuous_db" > "$acsv"
pcsv=docs/perf/post.csv
echo "volume,slab,value_subsample,post_db,pre_db,vtk_db,vtk_trilinear_db,post_trilinear_db,trilinear_slab,trilinear_post_trilinear_db,trilinear_post_kernel_db" > "$pcsv"
fcsv=docs/perf/floor.csv
echo "volume,rep,pixel,pixel_updates,composites,voxels,sheets,box_px,accumulate_ms,composite_ms,floor_ms" > "$fcsv"
for spec in "${volumes[@]}"; do
  IFS='|' read -r name dims spacing ramp <<<"$spec"
  read -r nx ny nz <<<"$dims"; read -r sx sy sz <<<"$spacing"; read -r lo hi <<<"$ramp"
  raw=$work/${name}_u8.raw; [ "$name" = blobs ] && raw=$work/blobs256_u8.raw
  vtk() {
    VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow "$py" "$peers/vtk_render.py" "$raw" "$nx" "$ny" "$nz" \
      --spacing "$sx" "$sy" "$sz" --size 512 512 --tf "$lo" "$hi" --azimuth 30 --elevation 20 \
      --opacity-unit-distance 1 --mapper fixedpoint --threads "$1" --frames "$frames" --out "$work/out/vtk-$name" >/dev/null
  }
  vtk 1
  # VTK's camera as Footprint's world-to-screen matrix (rows right, down, away; pixels per unit).
  vm=$("$py" benches/vtk_view_matrix.py "$work/out/vtk-$name.json" 512)
  common=("$raw" --dims "$nx,$ny,$nz" --type u8 --spacing "$sx,$sy,$sz" --window "$lo,$hi" --tf grey
          --size 512x512 --view-matrix "$vm" --frames "$frames" --orbit 2)
  "$fp" render "$raw" --dims "$nx,$ny,$nz" --type u8 --spacing "$sx,$sy,$sz" --window "$lo,$hi" --tf grey \
    --size 512x512 --view-matrix "$vm" --slicing object --threads 1 --out "$work/out/fp-$name.png" --json "$work/out/fp-$name.json" >/dev/null
  # The scene's unavoidable work at 512² (benches/floor.rs): pixel updates, composites, voxels, sheets.
  counts=$("$py" -c "import json; j=json.load(open('$work/out/fp-$name.json')); print(*(int(j[k]) for k in ('pixel_updates', 'pixels_composited', 'voxels_splatted', 'sheets')))")
  # What --subsample auto costs in accuracy on this view: against the full-size f64 reference
  # (the splatting itself) and against the continuous integral, beside the full-size render's.
  for sub in 1 auto; do
    "$fp" verify "$raw" --dims "$nx,$ny,$nz" --type u8 --spacing "$sx,$sy,$sz" --window "$lo,$hi" --tf grey \
      --size 512x512 --view-matrix "$vm" --slicing object --subsample "$sub" --reference continuous --json "$work/v.json" >/dev/null
    "$py" -c "import json; j=json.load(open('$work/v.json')); print(f'$name,$sub,{int(j[\"subsample\"])},{j[\"overall\"][\"psnr_db\"]:.2f},{j[\"continuous\"][\"psnr_db\"]:.2f}')" >> "$acsv"
    [ "$sub" = 1 ] && cp "$work/v.json" "$work/v1.json"
  done
  # Each method of the timing runs against the default continuous model (opacity reconstruction,
  # `verify --reference continuous`), and what culling skipped (issue 42).
  for m in "default|--slicing auto" "object|--slicing object" "object-cull|--slicing object --cull $cull" "slabs|--slicing image" \
           "slabs-cull|--slicing image --cull $cull" "object-subsample|--slicing object --subsample auto"; do
    IFS='|' read -r label flags <<<"$m"
    # shellcheck disable=SC2086 # the method's flags
    "$fp" verify "$raw" --dims "$nx,$ny,$nz" --type u8 --spacing "$sx,$sy,$sz" --window "$lo,$hi" --tf grey \
      --size 512x512 --view-matrix "$vm" $flags --reference continuous --json "$work/m.json" >/dev/null
    # shellcheck disable=SC2086
    "$fp" render "$raw" --dims "$nx,$ny,$nz" --type u8 --spacing "$sx,$sy,$sz" --window "$lo,$hi" --tf grey \
      --size 512x512 --view-matrix "$vm" $flags --threads 1 --out "$work/m.png" --json "$work/mr.json" >/dev/null
    "$py" -c "import json; j=json.load(open('$work/m.json')); r=json.load(open('$work/mr.json')); print(f'$name,$label,{j[\"continuous\"][\"psnr_db\"]:.2f},{j[\"overall\"][\"psnr_db\"]:.2f},{int(r[\"voxels\"])},{int(r[\"culled_voxels\"])},{int(r[\"pixel_updates\"])}')" >> "$mcsv"
  done
  # Post-classification (issues 47, 75): Footprint's post-classified defaults with each
  # reconstruction (the kernel's, the default, and trilinear, VTK's own) and its pre-classified
  # default against both post-classified integrals, and VTK's image (from its first run above)
  # against the same integrals.
  for recon in kernel trilinear; do
    "$fp" verify "$raw" --dims "$nx,$ny,$nz" --type u8 --spacing "$sx,$sy,$sz" --window "$lo,$hi" --tf grey \
      --size 512x512 --view-matrix "$vm" --classification post --reference continuous --reconstruction "$recon" \
      --json "$work/post-$recon.json" --reference-out "$work/out/post-ref-$name-$recon.pfm" \
      --out "$work/out/post-$name-$recon.pfm" >/dev/null
  done
  "$py" - "$work" "$name" "$pcsv" <<'PY'
import json, sys, numpy as np
sys.path.insert(0, "benches")
from images import pfm, psnr
work, name, out = sys.argv[1:]
vtk = np.fromfile(f"{work}/out/vtk-{name}.rgba.f32.raw", np.float32).reshape(512, 512, 4)[..., :3]
k, t = (json.load(open(f"{work}/post-{r}.json")) for r in ("kernel", "trilinear"))
ref = {r: pfm(f"{work}/out/post-ref-{name}-{r}.pfm") for r in ("kernel", "trilinear")}
pre = json.load(open(f"{work}/v1.json"))["continuous"]["models"]["post-classified"]
# Each reconstruction's frame (`verify --reconstruction R` renders it) against both integrals.
img = {r: pfm(f"{work}/out/post-{name}-{r}.pfm") for r in ("kernel", "trilinear")}
row = [name, f"{k['slab']:.2g}", str(int(k["value_subsample"])), k["continuous"]["psnr_db"], pre,
       psnr(vtk, ref["kernel"]), psnr(vtk, ref["trilinear"]), psnr(img["kernel"], ref["trilinear"]),
       f"{t['slab']:.2g}", t["continuous"]["psnr_db"], psnr(img["trilinear"], ref["kernel"])]
open(out, "a").write(",".join(str(x) if isinstance(x, str) else f"{x:.2f}" for x in row) + "\n")
PY
  "$work/vp_bench" "$raw" "$nx" "$ny" "$nz" "$sx" "$sy" "$sz" 512 512 30 20 "$lo" "$hi" 3 "$work/out/vp-$name" classified grey >/dev/null
  "$py" - "$work/out" "$name" "docs/images/peers-$name.png" <<'PY'
import sys, numpy as np
from PIL import Image
out, name, dest = sys.argv[1:]
fp = np.asarray(Image.open(f"{out}/fp-{name}.png").convert("RGB"))
vt = np.asarray(Image.open(f"{out}/vtk-{name}.png").convert("RGB"))
vp = np.asarray(Image.open(f"{out}/vp-{name}.ppm").convert("RGB"))
print(f"{name}: mean RGB  footprint {fp.mean():.2f}  vtk {vt.mean():.2f}  volpack {vp.mean():.2f}")
Image.fromarray(np.concatenate([fp, vt, vp], 1)).resize((768, 256)).save(dest)
PY
  for rep in $(seq 1 "$reps"); do
    # SUB "-" leaves --subsample unset: the default plan's pilot may subsample.
    for cfg in "1 float - auto off" "2 float - auto off" "1 float 1 object off" "2 float 1 object off" "1 fixed 1 object off" "1 float auto object off" \
               "2 float auto object off" "1 float 1 image off" "2 float 1 image off" "1 float 1 object $cull" \
               "2 float 1 object $cull" "1 float 1 image $cull" "2 float 1 image $cull"; do
      read -r th acc sub slicing cl <<<"$cfg"
      subarg=(); [ "$sub" != - ] && subarg=(--subsample "$sub")
      "$fp" bench "${common[@]}" --threads "$th" --accum "$acc" "${subarg[@]}" --slicing "$slicing" \
        --cull "$cl" --json "$work/b.json" >/dev/null
      label=$acc; [ "$sub" = auto ] && label=$label-subsample; [ "$slicing" = auto ] && label=$label-default
      [ "$slicing" = image ] && label=$label-slabs; [ "$cl" != off ] && label=$label-cull
      "$py" -c "import json,sys; j=json.load(open('$work/b.json')); print(f'$name,$rep,footprint,$th,$label,{j[\"first_ms\"]:.3f},{j[\"median_ms\"]:.3f},{int(j[\"culled_voxels\"])}')" >> "$csv"
    done
    # Post-classified (issue 47), one thread: beside VTK's ray caster, which post-classifies.
    # Both reconstructions (issue 75): the kernel's and trilinear, VTK's own model.
    for recon in kernel trilinear; do
      "$fp" bench "${common[@]}" --threads 1 --classification post --reconstruction "$recon" --json "$work/b.json" >/dev/null
      label=float-post; [ "$recon" = trilinear ] && label=float-post-trilinear
      "$py" -c "import json,sys; j=json.load(open('$work/b.json')); print(f'$name,$rep,footprint,1,$label,{j[\"first_ms\"]:.3f},{j[\"median_ms\"]:.3f},0')" >> "$csv"
    done
    for th in 1 2; do
      vtk "$th"
      "$py" -c "import json; j=json.load(open('$work/out/vtk-$name.json'))['seconds']; print(f'$name,$rep,vtk,$th,-,{j[\"warmup_total\"]*1e3:.3f},{j[\"frame\"][\"median\"]*1e3:.3f},0')" >> "$csv"
    done
    "$work/vp_bench" "$raw" "$nx" "$ny" "$nz" "$sx" "$sy" "$sz" 512 512 30 20 "$lo" "$hi" "$frames" "$work/out/vp-$name" classified grey >/dev/null
    "$py" -c "import json; j=json.load(open('$work/out/vp-$name.json'))['seconds']; print(f'$name,$rep,volpack,1,-,{(j[\"preprocess\"]+j[\"first_frame\"])*1e3:.3f},{j[\"frame\"][\"median\"]*1e3:.3f},0')" >> "$csv"
    # shellcheck disable=SC2086 # four counts
    cargo bench -q --bench floor -- $counts "$frames" 2>/dev/null \
      | sed -nE "s/^floor ([a-z]+): box ([0-9]+) px, accumulate ([0-9.]+) ms.*composite ([0-9.]+) ms.*floor ([0-9.]+) ms$/$name,$rep,\1,${counts// /,},\2,\3,\4,\5/p" >> "$fcsv"
  done
  echo "$name: $reps repetitions done"
done

echo "== scaling (Footprint only, blobs, float, 1 thread)"
scsv=docs/perf/scaling.csv
echo "kind,size,first_ms,median_ms,pixel_updates_hint" > "$scsv"
sizes=(128 256 512 1024 2048); [ "$quick" = 1 ] && sizes=(128 256)
for s in "${sizes[@]}"; do
  "$fp" bench "$work/blobs256_u8.raw" --dims 256,256,256 --type u8 --window 80,255 --tf grey --size "${s}x$s" \
    --view 30,20,0 --frames "$frames" --orbit 2 --threads 1 --json "$work/s.json" >/dev/null
  "$py" -c "import json; j=json.load(open('$work/s.json')); print(f'image,$s,{j[\"first_ms\"]:.3f},{j[\"median_ms\"]:.3f},')" >> "$scsv"
done
vsizes=(64 128 256 512); [ "$quick" = 1 ] && vsizes=(64)
for n in "${vsizes[@]}"; do
  "$py" - "$n" "$work/blobs${n}.raw" <<'PY'
import sys, numpy as np
n, path = int(sys.argv[1]), sys.argv[2]
# The same scene at every size: a spherical shell and three Gaussian blobs, x fastest, u8.
c = (np.arange(n, dtype=np.float32) - (n - 1) / 2) / ((n - 1) / 2)
out = np.memmap(path, np.uint8, "w+", shape=(n, n, n))
Y, X = np.meshgrid(c, c, indexing="ij")
for k in range(n):
    Z = c[k]
    r = np.sqrt(X * X + Y * Y + Z * Z)
    v = 0.6 * np.exp(-((r - 0.8) ** 2) / (2 * 0.03 ** 2))
    for (bx, by, bz, s) in [(0.3, 0.1, -0.2, 0.15), (-0.35, -0.2, 0.1, 0.12), (0.0, 0.4, 0.3, 0.1)]:
        v += np.exp(-((X - bx) ** 2 + (Y - by) ** 2 + (Z - bz) ** 2) / (2 * s * s))
    out[k] = np.clip(np.round(v / 1.6 * 255), 0, 255).astype(np.uint8)
out.flush()
PY
  "$fp" bench "$work/blobs${n}.raw" --dims "$n,$n,$n" --type u8 --window 80,255 --tf grey --size 512x512 \
    --view 30,20,0 --frames "$frames" --orbit 2 --threads 1 --json "$work/s.json" >/dev/null
  "$py" -c "import json; j=json.load(open('$work/s.json')); print(f'volume,$n,{j[\"first_ms\"]:.3f},{j[\"median_ms\"]:.3f},')" >> "$scsv"
  [ "$n" = 512 ] && rm -f "$work/blobs512.raw"
done

echo "== docs/performance.md"
"$py" "$root/benches/peers_report.py" "$csv" "$scsv" docs/performance.md docs/charts/perf-scaling "$acsv" "$fcsv" "$pcsv" \
  "$mcsv" docs/perf/threads16.csv
echo "wrote docs/performance.md, docs/perf/*.csv, docs/charts/perf-scaling.{svg,png}, docs/images/peers-*.png"
