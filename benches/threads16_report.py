#!/usr/bin/env python3
"""Summarises benches/threads16.sh's threads_long.csv into docs/perf/threads16.csv.

    benches/threads16_report.py THREADS_LONG.csv [OUT.csv]

One row per (volume, size, method): the plan, the median re-render (frames 2..5) at each thread
count, 16 threads' and 2 threads' speed-up over one (medians; 16's also from the fastest
re-render of each), and where the 16-thread frame's
time went (the re-render's phases on 16 threads: tables, resample, and what no phase names).
benches/peers_report.py renders it in docs/performance.md.
"""
import csv
import sys

src = sys.argv[1]
out = sys.argv[2] if len(sys.argv) > 2 else "docs/perf/threads16.csv"
rows = list(csv.DictReader(open(src)))
keys = []
by = {}
for r in rows:
    k = (r["volume"], r["size"], r["method"])
    if k not in by:
        keys.append(k)
    by.setdefault(k, {})[int(r["threads"])] = r
fields = ["machine", "commit", "date", "volume", "size", "method", "plan"]
counts = sorted({int(r["threads"]) for r in rows})
fields += [f"t{t}_ms" for t in counts] + ["speedup2", "speedup16", "speedup16_min", "t16_tables_ms", "t16_resample_ms", "t16_classify_ms", "t16_other_ms"]
with open(out, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=fields)
    w.writeheader()
    for k in keys:
        t = by[k]
        first = next(iter(t.values()))
        med = {n: float(r["median_ms"]) for n, r in t.items()}
        row = {x: first[x] for x in ("machine", "commit", "date", "volume", "size", "method", "plan")}
        for n in counts:
            row[f"t{n}_ms"] = f"{med[n]:.2f}" if n in med else ""
        row["speedup2"] = f"{med[1] / med[2]:.2f}" if 1 in med and 2 in med else ""
        row["speedup16"] = f"{med[1] / med[16]:.2f}" if 1 in med and 16 in med else ""
        # The fastest re-render's ratio too: one slow frame of the four moves a median.
        mins = {n: float(r["min_ms"]) for n, r in t.items()}
        row["speedup16_min"] = f"{mins[1] / mins[16]:.2f}" if 1 in mins and 16 in mins else ""
        if 16 in t:
            r = t[16]
            ph = {p: float(r[f"{p}_ms"]) for p in ("classify", "tables", "splat", "composite", "resample")}
            row["t16_tables_ms"] = f"{ph['tables']:.2f}"
            row["t16_resample_ms"] = f"{ph['resample']:.2f}"
            row["t16_classify_ms"] = f"{ph['classify']:.2f}"
            row["t16_other_ms"] = f"{max(0.0, med[16] - sum(ph.values())):.2f}"
        w.writerow(row)
print(f"wrote {out}")
