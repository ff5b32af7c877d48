#!/usr/bin/env python3
"""Validates `footprint render --quality` against `footprint chart` sweeps.

  validate_quality.py FOOTPRINT SWEEP_DIR... [--runs 5]

Each SWEEP_DIR holds a `tradeoff.csv` written by
`footprint chart VOLUME --view V --size 512x512 --out SWEEP_DIR` and a `sweep.json` naming
{"volume": ..., "view": ...}. For every sweep and every target in 30, 40 and 50 dB it finds the
fastest configuration of the sweep that reached the target, asks `--quality` for its choice, then
times both with FOOTPRINT (the core render time `render --json` reports), `--runs` times each,
interleaved, and prints a Markdown table: achieved PSNR of the choice (from the sweep), both
median times, and their ratio. Exits 1 if a choice misses its target or is more than 1.5x slower.
"""
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile


def render(fp, volume, view, extra, tmp):
    out = os.path.join(tmp, "r.json")
    cmd = [fp, "render", volume, "--size", "512x512", "--view", view, "--out",
           os.path.join(tmp, "r.png"), "--json", out] + extra
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(out) as f:
        return json.load(f)


def config_flags(row):
    method = "robust" if row["method"] == "view" else row["method"]
    return ["--table", row["table"], "--lookup", row["lookup"], "--method", method,
            "--accum", row["accum"]]


def main():
    args = sys.argv[1:]
    runs = 5
    if "--runs" in args:
        i = args.index("--runs")
        runs = int(args[i + 1])
        del args[i:i + 2]
    fp, sweeps = args[0], args[1:]
    failed = False
    print("| volume | view | target | chosen | its PSNR (sweep) | chosen s | fastest meeting target | its s | ratio |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for d in sweeps:
            meta = json.load(open(os.path.join(d, "sweep.json")))
            rows = list(csv.DictReader(open(os.path.join(d, "tradeoff.csv"))))
            # --quality chooses among table configurations (object slicing) only.
            rows = [r for r in rows if r.get("slicing", "object") == "object"]
            by_label = {r["config"]: r for r in rows}
            for q in (30, 40, 50):
                meeting = [r for r in rows if float(r["psnr_db"]) >= q]
                fastest = min(meeting, key=lambda r: float(r["median_s"]))
                j = render(fp, meta["volume"], meta["view"], ["--quality", str(q)], tmp)
                chosen = by_label[j["quality"]["chosen"]]
                t_chosen, t_fast = [], []
                for _ in range(runs):
                    t_chosen.append(render(fp, meta["volume"], meta["view"], config_flags(chosen), tmp)["seconds"])
                    t_fast.append(render(fp, meta["volume"], meta["view"], config_flags(fastest), tmp)["seconds"])
                a, b = statistics.median(t_chosen), statistics.median(t_fast)
                ratio = a / b
                psnr = float(chosen["psnr_db"])
                bad = psnr < q or ratio > 1.5
                failed |= bad
                print(f"| {os.path.basename(meta['volume']).split('_')[0]} | {meta['view']} | {q} | "
                      f"{chosen['config']} | {psnr:.1f} | {a:.3f} | {fastest['config']} | {b:.3f} | "
                      f"{ratio:.2f}{' **FAIL**' if bad else ''} |", flush=True)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
