#!/usr/bin/env python3
"""A scripted CT head phantom at real size: 256 x 256 x 113 voxels of uint16 (little-endian,
x fastest), spacing 1 x 1 x 2 mm, values in CT numbers + 1024 (air ~ 24, water 1024, soft tissue
~1060, cortical bone 2200-3000), written as OUT_PREFIX.raw with its NRRD header OUT_PREFIX.nhdr.

Why a phantom: issue 74 asks for a real-size CT (at least 256 x 256 x 100, anisotropic spacing,
dense bone) that CI can render without a network. No CT of that size that our fetch tool reaches
comes with a licence that lets us keep it in the repository, so this script builds one with the
same properties, deterministically (numpy's seeded generator; the script prints the raw file's
sha256: 2dec8ebe7e6b9e62... with numpy 2.4, the file the figures in docs/ were measured on; numpy
does not promise the same random stream across versions, so check it when comparing figures).

What is in it (world millimetres, the head centred in the box): skin and fat over soft tissue
(an ellipsoid 180 x 220 x 200 mm, tissue 1060, fat 930 in a 3 mm layer under the skin), a skull
shell 5-9 mm thick (outer and inner tables of cortical bone at 2400-2900 around a diploe of
1500-1900, its thickness varying around the head), brain (1045) with two lateral ventricles
(1030), air sinuses and a nasal cavity (24) behind a dense maxilla and teeth (3000), the mandible,
and two cervical vertebrae below; CT noise of standard deviation 12 on every voxel. Bone is
dense and thin on the grid (a few voxels through the shell, one or two along z), which is what
makes object slicing's sheets step visibly: the point of the benchmark.

Usage: ct_phantom.py OUT_PREFIX
"""
import hashlib
import os
import sys

import numpy as np

NX, NY, NZ = 256, 256, 113
SPACING = (1.0, 1.0, 2.0)


def main(prefix):
    rng = np.random.default_rng(20261207)
    # World coordinates (mm) of the voxel centres, the box centred at the origin; z up.
    x = (np.arange(NX) - (NX - 1) / 2) * SPACING[0]
    y = (np.arange(NY) - (NY - 1) / 2) * SPACING[1]
    z = (np.arange(NZ) - (NZ - 1) / 2) * SPACING[2]
    Z, Y, X = np.meshgrid(z, y, x, indexing="ij")
    vol = np.full(X.shape, 24.0)  # air

    def ell(cx, cy, cz, ax, ay, az):
        """Normalised radius of an axis-aligned ellipsoid: < 1 inside."""
        return np.sqrt(((X - cx) / ax) ** 2 + ((Y - cy) / ay) ** 2 + ((Z - cz) / az) ** 2)

    # The head: skin, a fat layer, soft tissue.
    head = ell(0, 0, 10, 90, 110, 100)
    vol[head < 1.0] = 930.0
    vol[head < 1.0 - 3.0 / 95] = 1060.0
    # The skull: an ellipsoidal shell whose thickness varies around the head (5-9 mm), outer and
    # inner tables of cortical bone around a spongier diploe.
    theta = np.arctan2(Y, X)
    thick = 7.0 + 2.0 * np.sin(3 * theta) * np.cos(Z / 40.0)
    r_skull = ell(0, 0, 14, 82, 102, 92)
    depth = (1.0 - r_skull) * 90.0  # mm inside the skull's outer surface, roughly
    in_shell = (depth > 0) & (depth < thick) & (Z > -60)
    table = in_shell & ((depth < 2.0) | (depth > thick - 2.0))
    diploe = in_shell & ~table
    vol[table] = 2400.0 + 500.0 * rng.random(table.sum())
    vol[diploe] = 1500.0 + 400.0 * rng.random(diploe.sum())
    # Brain and ventricles inside the skull.
    brain = (depth >= thick) & (Z > -60)
    vol[brain] = 1045.0
    for sx in (-1, 1):
        vent = ell(sx * 14, 5, 25, 8, 30, 14) < 1.0
        vol[vent & brain] = 1030.0
    # Face: maxilla (dense), teeth, nasal cavity and sinuses (air), the mandible.
    maxilla = (ell(0, -70, -55, 40, 28, 14) < 1.0) & (ell(0, -70, -55, 33, 21, 9) >= 1.0)
    vol[maxilla] = 2600.0
    for k in range(12):
        a = np.pi * (0.15 + 0.7 * k / 11)
        tooth = ell(36 * np.cos(a), -60 - 36 * np.sin(a), -70, 3.5, 3.5, 7) < 1.0
        vol[tooth] = 3000.0
    vol[ell(0, -72, -40, 9, 20, 16) < 1.0] = 24.0  # nasal cavity
    for sx in (-1, 1):
        vol[ell(sx * 24, -60, -45, 14, 16, 14) < 1.0] = 24.0  # maxillary sinuses
    vol[ell(0, -85, 20, 18, 9, 10) < 1.0] = 24.0  # frontal sinus
    mandible = (ell(0, -55, -85, 55, 45, 12) < 1.0) & (ell(0, -55, -85, 46, 36, 12) >= 1.0)
    vol[mandible & (Y < -20)] = 2500.0
    # Two cervical vertebrae below the skull: a dense cortical ring around cancellous bone.
    for cz in (-86.0, -104.0):
        body = ell(0, 25, cz, 14, 12, 7)
        vol[(body < 1.0) & (body >= 0.75)] = 2300.0
        vol[body < 0.75] = 1350.0
    # CT noise, then the unsigned range.
    vol += rng.normal(0.0, 12.0, vol.shape)
    out = np.clip(np.round(vol), 0, 65535).astype("<u2")
    raw = prefix + ".raw"
    out.tofile(raw)
    with open(prefix + ".nhdr", "w") as f:
        f.write(
            "NRRD0004\ntype: uint16\ndimension: 3\nsizes: %d %d %d\nspacings: %g %g %g\n"
            "encoding: raw\nendian: little\ndata file: %s\n"
            % (NX, NY, NZ, *SPACING, os.path.basename(raw))
        )
    with open(raw, "rb") as f:
        print(hashlib.sha256(f.read()).hexdigest(), raw)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
