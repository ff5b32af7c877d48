#!/usr/bin/env bash
# `--phase-lookup blend` against `nearest` (docs/modes.md, "Phase lookup"): object slicing of the
# peers' u8 volumes (made by benches/peers.sh into WORK, default target/peers) at 512x512, view
# 30,20,0, one thread, `bench --frames 10 --orbit 0` (re-renders of one view), the two lookups run
# alternately ROUNDS times (default 10), each order in turn; prints per round the minimum frame
# time of each (ms) and blend / nearest, then per volume the median ratio and the ratio of the
# minima. ACCUM (default float) is `float`, `fixed` (the fixed path's integer stencils) or `both`:
# then the four (accumulation, lookup) runs alternate, and fixed / float is printed per lookup.
#
#   benches/phase_lookup.sh [WORK] [ROUNDS] [ACCUM]
set -euo pipefail
cd "$(dirname "$0")/.."
work=${1:-target/peers}
rounds=${2:-10}
accum=${3:-float}
case $accum in float | fixed) accums=$accum ;; both) accums="float fixed" ;; *)
  echo "ACCUM: float, fixed or both" >&2; exit 2 ;; esac
cargo build --release -q -p footprint-harness
fp=target/release/footprint
out=$(mktemp)
trap 'rm -f "$out" "$out.json"' EXIT
W="$work/walnut_u8.raw --dims 128,96,114 --type u8 --window 40,255 --tf grey"
H="$work/headsq_u8.raw --dims 64,64,93 --spacing 3.2,3.2,1.5 --type u8 --window 60,255 --tf grey"
blobs=$work/blobs256_u8.raw
[ -s "$blobs" ] || blobs=$work/data/blobs256_u8.raw
B="$blobs --dims 256,256,256 --type u8 --window 80,255 --tf grey"
run() {
  # shellcheck disable=SC2086
  "$fp" bench ${!1} --size 512x512 --view 30,20,0 --threads 1 --frames 10 --orbit 0 \
    --slicing object --accum "$3" --phase-lookup "$2" --json "$out.json" > /dev/null
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['min_ms'])" "$out.json"
}
for r in $(seq 1 "$rounds"); do
  for name in W H B; do
    line="$r $name"
    for a in $accums; do
      if [ $((r % 2)) = 1 ]; then b=$(run $name blend "$a"); n=$(run $name nearest "$a")
      else n=$(run $name nearest "$a"); b=$(run $name blend "$a"); fi
      line="$line $a $b $n $(python3 -c "print(round($b / $n, 3))")"
    done
    echo "$line" | tee -a "$out"
  done
done
python3 - "$out" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1]) if l.strip()]
for v, name in (("W", "walnut"), ("H", "headsq"), ("B", "blobs")):
    runs = [a for a in rows if a[1] == v]
    minima = {}
    for i in range(2, len(runs[0]), 4):
        acc = runs[0][i]
        r = [(float(a[i + 1]), float(a[i + 2]), float(a[i + 3])) for a in runs]
        mb, mn = min(x[0] for x in r), min(x[1] for x in r)
        minima[acc] = (mb, mn)
        print(f"{name} {acc}: median blend/nearest {statistics.median(x[2] for x in r):.2f} over {len(r)} rounds "
              f"(range {min(x[2] for x in r):.2f}-{max(x[2] for x in r):.2f}, nearest faster in "
              f"{sum(x[2] > 1 for x in r)}); minima {mb:.1f} / {mn:.1f} ms = {mb / mn:.2f}")
    if len(minima) == 2:
        (fb, fn), (xb, xn) = minima["float"], minima["fixed"]
        print(f"{name} fixed/float (minima): blend {xb / fb:.2f}, nearest {xn / fn:.2f}")
PY
