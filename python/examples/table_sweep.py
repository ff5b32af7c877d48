"""Time against accuracy over the generic table's size, from Python: each table size of the
command line's (3 to 257 nodes a side) renders the CT head shipped with the tests, timed by
`bench` (median of 7 frames, one thread) and measured by `verify --reference continuous`
(the continuous integral under today's extinction-reconstruction model, supersampled rays);
matplotlib plots one against the other.

    python python/examples/table_sweep.py [OUT.png]

(needs `pip install ./python matplotlib`; writes docs/images/python-table-sweep.png by default).
Frame times depend on the machine and its load: the picture shows one run's.
"""

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import footprint  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
volume, spacing, _ = footprint.load(ROOT / "tests" / "data" / "headsq_64x64x93_int16_le.nhdr")
out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "images" / "python-table-sweep.png"

rows = []
for n in [3, 5, 7, 9, 11, 17, 21, 33, 65, 101, 129, 257]:
    r = footprint.time_table(
        volume, n, spacing=spacing, size=(256, 256), view=(30, 20, 0), frames=7, threads=1
    )
    rows.append(r)
    print(f"table {n:3d}: {r['median_ms']:7.2f} ms, {r['psnr_db']:6.2f} dB against the continuous integral (extinction model)")

fig, ax = plt.subplots(figsize=(6, 4), dpi=110)
ax.plot([r["median_ms"] for r in rows], [r["psnr_db"] for r in rows], "o")
for r in rows:
    ax.annotate(str(r["table"]), (r["median_ms"], r["psnr_db"]), textcoords="offset points", xytext=(4, -10), fontsize=8)
ax.set_xlabel("median frame, ms (256², one thread)")
ax.set_ylabel("PSNR vs continuous integral (extinction), dB")
ax.set_title("headsq: generic table size, time against accuracy")
ax.grid(alpha=0.3)
fig.tight_layout()
fig.savefig(out)
print(f"wrote {out}")
