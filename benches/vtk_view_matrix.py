"""VTK's camera (the `view` of ../shared/peers/vtk_render.py's JSON) as Footprint's
`--view-matrix`: world-to-screen rows right, down and away from the eye, in pixels per world unit
for an image SIZE pixels tall (parallel projection).

usage: vtk_view_matrix.py VTK.json [SIZE]   (prints nine comma-separated numbers)
"""
import json
import sys

import numpy as np

v = json.load(open(sys.argv[1]))["view"]
size = float(sys.argv[2]) if len(sys.argv) > 2 else 512.0
pos, foc, up = (np.array(v[k], float) for k in ("camera_position", "focal_point", "view_up"))
d = foc - pos
d /= np.linalg.norm(d)
right = np.cross(d, up)
right /= np.linalg.norm(right)
upo = np.cross(right, d)
s = size / (2 * v["parallel_scale"])
print(",".join(f"{x:.9g}" for x in (s * np.array([right, -upo, d])).ravel()))
