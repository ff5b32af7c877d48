#!/usr/bin/env python3
"""A small render against its large render box-filtered down (issue 41, "must show" 4).

    box_filtered.py SMALL.pfm LARGE.pfm [--max-bias 0.03] [--min-db 38]

Both are colour PFMs from `footprint render --out x.pfm` (linear RGB composited over the
background), the large one an integer multiple k of the small one's size. Each k x k block of the
large image is averaged into one pixel; the script prints the small image's mean brightness
(R + G + B over every pixel) relative to that average's, and the PSNR between them (peak 1), and
exits 1 if the bias exceeds --max-bias (a fraction) or the PSNR is below --min-db. Standard
library only.
"""
import argparse
import array
import math
import sys


def pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        a = array.array("f")
        a.frombytes(f.read())
    if kind != b"PF":
        sys.exit(f"{path}: not a colour PFM")
    if scale > 0:  # big-endian
        a.byteswap()
    if len(a) != w * h * 3:
        sys.exit(f"{path}: {len(a)} values for {w}x{h}")
    return w, h, a


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("small")
    ap.add_argument("large")
    ap.add_argument("--max-bias", type=float, default=0.03)
    ap.add_argument("--min-db", type=float, default=38.0)
    a = ap.parse_args()
    ws, hs, small = pfm(a.small)
    wl, hl, large = pfm(a.large)
    k = wl // ws
    if ws * k != wl or hs * k != hl:
        sys.exit(f"{wl}x{hl} is not a multiple of {ws}x{hs}")
    down = [0.0] * (ws * hs * 3)
    for y in range(hl):
        row, dst = y * wl * 3, (y // k) * ws * 3
        for x in range(wl):
            i, j = row + 3 * x, dst + 3 * (x // k)
            down[j] += large[i]
            down[j + 1] += large[i + 1]
            down[j + 2] += large[i + 2]
    down = [v / (k * k) for v in down]
    ms, md = sum(small) / len(small), sum(down) / len(down)
    bias = ms / md - 1.0 if md > 0 else 0.0
    mse = sum((p - q) ** 2 for p, q in zip(small, down)) / len(small)
    db = 10 * math.log10(1 / mse) if mse > 0 else math.inf
    print(f"brightness {bias * 100:+.2f} %, {db:.2f} dB")
    return 0 if abs(bias) <= a.max_bias and db >= a.min_db else 1


if __name__ == "__main__":
    sys.exit(main())
