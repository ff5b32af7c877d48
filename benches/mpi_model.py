#!/usr/bin/env python3
"""Reads docs/perf/mpi-scaling.csv (benches/mpi_scaling.sh): prints the strong- and weak-scaling
tables (medians over repetitions) and fits the compositing-cost model

    t_composite(P, N) = a * ceil(log2 P) + b * N * (2 - 2/P) + f * N * [P not a power of two]

(N pixels; binary swap: ceil(log2 P) rounds of latency, each rank sending and compositing
N(1 - 1/P) pixels over the rounds and rank 0 receiving N(1 - 1/P) in the gather; a count that is
not a power of two first folds, one whole image per pair) by least squares on the relative error
(each point weighted by 1/measured, so small images count as much as large ones), then prints it
against every measured point. No numpy: the normal equations are solved by hand."""
import csv, math, statistics, sys
from collections import defaultdict

rows = list(csv.DictReader(open(sys.argv[1])))
groups = defaultdict(list)
for r in rows:
    groups[(r["kind"], int(r["ranks"]), r["size"], r["dims"])].append(r)

def med(rs, key):
    return statistics.median(float(r[key]) for r in rs)

for kind in ("strong", "weak"):
    print(f"\n{kind} scaling (medians):\n")
    print("| ranks | image | volume | wall s | slowest render s | composite (rank 0) s | most bytes read | most peak memory |")
    print("|---|---|---|---|---|---|---|---|")
    for (k, p, size, dims), rs in sorted(groups.items(), key=lambda x: (x[0][2], x[0][1])):
        if k != kind:
            continue
        read = med(rs, "bytes_read_max")
        print(f"| {p} | {size} | {dims} | {med(rs, 'wall_s'):.3f} | {med(rs, 'render_max_s'):.3f} | "
              f"{med(rs, 'composite_rank0_s'):.4f} | {'whole file' if read < 0 else f'{read / 2**20:.1f} MiB'} | "
              f"{med(rs, 'peak_mem_max') / 2**20:.1f} MiB |")

pts = []
for (k, p, size, dims), rs in groups.items():
    if p < 2:
        continue
    w, h = (int(x) for x in size.split("x"))
    n = w * h
    fold = 0 if p & (p - 1) == 0 else 1
    pts.append((math.ceil(math.log2(p)), n * (2 - 2 / p), n * fold, med(rs, "composite_rank0_s"), p, size, k))
wts = [1 / max(x[3], 1e-6) for x in pts]
def fit(cols):
    """Weighted least squares over the columns `cols` of (latency, volume, fold); 0 elsewhere."""
    k = len(cols)
    A = [[sum(w * w * x[cols[i]] * x[cols[j]] for x, w in zip(pts, wts)) for j in range(k)] for i in range(k)]
    y = [sum(w * w * x[cols[i]] * x[3] for x, w in zip(pts, wts)) for i in range(k)]
    for i in range(k):
        piv = max(range(i, k), key=lambda r: abs(A[r][i]))
        A[i], A[piv], y[i], y[piv] = A[piv], A[i], y[piv], y[i]
        for r in range(k):
            if r != i and A[i][i]:
                m = A[r][i] / A[i][i]
                A[r] = [A[r][c] - m * A[i][c] for c in range(k)]
                y[r] -= m * y[i]
    out = [0.0, 0.0, 0.0]
    for i, c in enumerate(cols):
        out[c] = y[i] / A[i][i] if A[i][i] else 0.0
    return out

# Every coefficient is a cost: a negative one is dropped and the rest refitted.
cols = [0, 1, 2]
while True:
    coef = fit(cols)
    neg = [c for c in cols if coef[c] < 0]
    if not neg:
        break
    cols.remove(neg[0])
a, b, f = coef
print(f"\ncompositing model: t = {a * 1e3:.3f} ms x ceil(log2 P) + {b * 1e9:.2f} ns x N(2 - 2/P)"
      f" + {f * 1e9:.2f} ns x N [fold]\n")
print("| kind | ranks | image | measured ms | model ms | measured / model |")
print("|---|---|---|---|---|---|")
for lg, vol, fold, t, p, size, k in sorted(pts, key=lambda x: (x[6], x[5], x[4])):
    m = a * lg + b * vol + f * fold
    print(f"| {k} | {p} | {size} | {t * 1e3:.2f} | {m * 1e3:.2f} | {t / m:.2f} |")
