#!/usr/bin/env python3
"""Validates `--quality DB`'s choice of level of detail against full resolution.

  validate_quality_lod.py FOOTPRINT VOLUME_SPEC... [--quality 40] [--sizes 64,128,512]
                          [--views 30,20,0:0,0,0:75,-40,20] [--runs 3]

A VOLUME_SPEC is a path (a file with a header), or `PATH@X,Y,Z@TYPE` for a headerless raw file.
For every volume, image size and view it runs `footprint verify VOLUME --quality DB` (which
renders the choice and, when it chose a coarser level, also compares it with the f64 reference of
level 0), then times the chosen frame against `--lod 0` (`render --json`'s `seconds`, the core's
frame time; `--runs` times each, interleaved, medians). Prints a Markdown table: the level chosen,
the pilot's estimate and bound of every level it tried, the PSNR achieved against full resolution,
the pilot's seconds, and the speed-up of the chosen frame over level 0 (pilot excluded, and
pilot included). Exits 1 if a choice misses its target.
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile


def volume_args(spec):
    parts = spec.split("@")
    if len(parts) == 3:
        return [parts[0], "--dims", parts[1], "--type", parts[2]], os.path.basename(parts[0])
    return [spec], os.path.basename(spec)


def run_json(cmd, path):
    subprocess.run(cmd + ["--json", path], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    with open(path) as f:
        return json.load(f)


def main(argv):
    opts = {"--quality": "40", "--sizes": "64,128,512", "--views": "30,20,0", "--runs": "3"}
    rest = []
    i = 0
    while i < len(argv):
        if argv[i] in opts:
            opts[argv[i]] = argv[i + 1]
            i += 2
        else:
            rest.append(argv[i])
            i += 1
    fp, specs = rest[0], rest[1:]
    q = float(opts["--quality"])
    runs = int(opts["--runs"])
    failed = False
    print(f"| volume | size | view | level | levels tried (estimate / bound, dB) | PSNR vs full resolution | "
          f"pilot s | level-0 frame s | chosen frame s | speed-up | with pilot |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        j = os.path.join(tmp, "v.json")
        for spec in specs:
            vargs, name = volume_args(spec)
            for size in opts["--sizes"].split(","):
                for view in opts["--views"].split(":"):
                    common = [fp] + ["verify"] + vargs + ["--size", f"{size}x{size}", "--view", view]
                    v = run_json(common + ["--quality", str(q)], j)
                    choice = v["quality"]
                    full = v.get("full_resolution", v["overall"])["psnr_db"]
                    pilot = choice.get("level_pilot")
                    tried = ", ".join(f"L{t['level']} {t['estimate_db']:.1f} / {t['bound_db']:.1f}"
                                      for t in (pilot["tried"] if pilot else [])) or "none"
                    pilot_s = pilot["seconds"] if pilot else 0.0
                    render = [fp, "render"] + vargs + ["--size", f"{size}x{size}", "--view", view,
                                                       "--out", os.path.join(tmp, "r.pfm")]
                    chosen = render + ["--lod", str(choice["level"])] + table_flags(choice["chosen"])
                    t0, tc = [], []
                    for _ in range(runs):
                        t0.append(run_json(render + ["--lod", "0"], j)["seconds"])
                        tc.append(run_json(chosen, j)["seconds"])
                    m0, mc = statistics.median(t0), statistics.median(tc)
                    ok = full >= q
                    failed |= not ok
                    print(f"| {name} | {size}² | {view} | {choice['level']} | {tried} | "
                          f"{full:.1f}{'' if ok else ' MISSED'} | {pilot_s:.2f} | {m0:.3f} | {mc:.3f} | "
                          f"{m0 / mc:.1f}× | {m0 / (mc + pilot_s):.1f}× |", flush=True)
    return 1 if failed else 0


def table_flags(label):
    """`n=33/nearest/view/float/libm` → the render flags of that configuration."""
    n, lookup, method, accum, _ = label.split("/")
    method = {"view": "robust"}.get(method, method)
    return ["--table", n.split("=")[1], "--lookup", lookup, "--method", method, "--accum", accum]


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
