#!/usr/bin/env bash
# Strong and weak scaling of `footprint render` under mpirun, and the compositing-cost model
# checked against the measured points (issue 45). Writes docs/perf/mpi-scaling.csv and prints
# the tables docs/scale-out.md and the README quote.
#   benches/mpi_scaling.sh [FOOTPRINT] [REPS]
# FOOTPRINT: a build with `--features mpi` (default target/mpi/release/footprint, as .ci/run
# builds it). Ranks past the machine's cores are oversubscribed: they still show bytes and memory.
set -euo pipefail
cd "$(dirname "$0")/.."
fp=${1:-target/mpi/release/footprint}
reps=${2:-3}
tmp=$(mktemp -d)
mr="mpirun --allow-run-as-root --oversubscribe"
out=docs/perf/mpi-scaling.csv
echo "kind,ranks,size,dims,rep,wall_s,render_max_s,composite_rank0_s,bytes_read_max,peak_mem_max" > "$out"
row() { # kind ranks size dims rep json wall_seconds
  python3 - "$@" >> "$out" <<'PY'
import json, sys
kind, ranks, size, dims, rep, path, wall = sys.argv[1:8]
j = json.load(open(path))
per = j.get("per_rank")
if per:
    render = max(r["render_seconds"] for r in per)
    comp = per[0]["composite_seconds"]
    read = max(r["bytes_read"] for r in per)
    mem = max(r["peak_memory_bytes"] for r in per)
else:
    render, comp, read, mem = j["seconds"], 0.0, -1, j["peak_memory_bytes"]
print(f"{kind},{ranks},{size},{dims},{rep},{int(wall) / 1e9:.4f},{render:.4f},{comp:.5f},{read},{mem}")
PY
}
run() { # ranks volume size: one process without mpirun, else mpirun; one thread per rank
  if [ "$1" = 1 ]; then
    "$fp" render "$2" --size "$3" --threads 1 --out "$tmp/o.png" --json "$tmp/o.json" >/dev/null
  else
    $mr -np "$1" "$fp" render "$2" --size "$3" --threads 1 --out "$tmp/o.png" --json "$tmp/o.json" >/dev/null
  fi
}
python3 benches/synthetic.py 256 "$tmp/ball256"
for size in 512x512 1024x1024; do
  for np in 1 2 3 4 8; do
    for rep in $(seq "$reps"); do
      t0=$(date +%s%N)
      run "$np" "$tmp/ball256.nhdr" "$size"
      row strong "$np" "$size" 256x256x256 "$rep" "$tmp/o.json" "$(( $(date +%s%N) - t0 ))"
    done
  done
done
for np in 1 2 4 8; do
  z=$((64 * np))
  python3 benches/synthetic.py "256,256,$z" "$tmp/weak"
  for rep in $(seq "$reps"); do
    t0=$(date +%s%N)
    run "$np" "$tmp/weak.nhdr" 512x512
    row weak "$np" 512x512 "256x256x$z" "$rep" "$tmp/o.json" "$(( $(date +%s%N) - t0 ))"
  done
done
python3 benches/mpi_model.py "$out"
rm -rf "$tmp"
