#!/usr/bin/env python3
"""Writes a synthetic u8 volume (raw, x fastest) and its NRRD header: a ball of value 200 with a
denser shell (250) and a hollow core, built row by row as byte runs (no numpy). A box of
NX x NY x NZ voxels holds NZ/NX balls stacked along z (the weak-scaling volumes).
Usage: synthetic.py N|NX,NY,NZ OUT_PREFIX  ->  OUT_PREFIX.raw, OUT_PREFIX.nhdr"""
import math, os, sys

size = [int(x) for x in sys.argv[1].split(",")]
nx, ny, nz = size * 3 if len(size) == 1 else size
n, prefix = nx, sys.argv[2]
c = (n - 1) / 2
outer, shell, core = 0.45 * n, 0.40 * n, 0.15 * n


def runs(r2):
    """(start, end) of |x - c| < sqrt(R^2 - r2) on the row, or None."""
    out = []
    for radius in (outer, shell, core):
        h2 = radius * radius - r2
        if h2 <= 0:
            out.append(None)
            continue
        h = math.sqrt(h2)
        out.append((max(0, math.ceil(c - h)), min(n, math.floor(c + h) + 1)))
    return out


with open(prefix + ".raw", "wb") as f:
    for kk in range(nz):
        k = kk % n
        for j in range(ny):
            row = bytearray(n)
            o, s, cr = runs((j - c) ** 2 + (k - c) ** 2)
            if o:
                row[o[0]:o[1]] = b"\xfa" * (o[1] - o[0])
            if s:
                row[s[0]:s[1]] = b"\xc8" * (s[1] - s[0])
            if cr:
                row[cr[0]:cr[1]] = b"\x00" * (cr[1] - cr[0])
            f.write(row)
with open(prefix + ".nhdr", "w") as f:
    f.write(
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %d %d %d\nspacings: 1 1 1\n"
        "encoding: raw\nendian: little\ndata file: %s\n" % (nx, ny, nz, os.path.basename(prefix + ".raw"))
    )
