#!/usr/bin/env python3
"""Writes docs/performance.md and the scaling chart from the CSVs benches/peers.sh measured.

usage: peers_report.py PEERS.csv SCALING.csv OUT.md CHART_STEM [SUBSAMPLE.csv [FLOOR.csv [POST.csv
       [METHODS.csv [THREADS16.csv]]]]]
Every ratio is of medians over the repetitions, all measured alternately in one session.
"""
import csv
import datetime
import os
import platform
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402,F401

peers_csv, scaling_csv, out_md, stem = sys.argv[1:5]
sub_csv = sys.argv[5] if len(sys.argv) > 5 else None
floor_csv = sys.argv[6] if len(sys.argv) > 6 else None
post_csv = sys.argv[7] if len(sys.argv) > 7 else None
methods_csv = sys.argv[8] if len(sys.argv) > 8 else None
threads16_csv = sys.argv[9] if len(sys.argv) > 9 else None
rows = list(csv.DictReader(open(peers_csv)))
volumes = list(dict.fromkeys(r["volume"] for r in rows))


def med(vol, renderer, threads, accum, key):
    v = [float(r[key]) for r in rows if r["volume"] == vol and r["renderer"] == renderer
         and r["threads"] == str(threads) and r["accum"] == accum]
    return statistics.median(v) if v else float("nan")


def footprint_times(vol, accum):
    """Fresh (1 thread), re-render on 1 and on 2 threads, ms."""
    return (med(vol, "footprint", 1, accum, "first_ms"), med(vol, "footprint", 1, accum, "median_ms"),
            med(vol, "footprint", 2, accum, "median_ms"))


def peer_times(vol):
    """VTK on 1 and 2 threads and VolPack, median frame, ms."""
    return (med(vol, "vtk", 1, "-", "median_ms"), med(vol, "vtk", 2, "-", "median_ms"),
            med(vol, "volpack", 1, "-", "median_ms"))


def cpu():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


reps = max(int(r["rep"]) for r in rows)
lines = [
    "# Performance: Footprint beside VTK and VolPack",
    "",
    f"Measured {datetime.date.today().isoformat()} on {cpu()}, {os.cpu_count()} cores, by "
    "`benches/peers.sh` (which regenerates this page): 512×512, orthographic, azimuth 30 / elevation 20 "
    "with VTK's camera handed to Footprint as the same world-to-screen matrix, emission, grey ramp over "
    "the same u8 window, opacity per world unit. Each figure is the median of "
    f"{reps} repetitions; within a repetition the renderers run one after another, so every ratio compares "
    "runs of the same minutes. Footprint: `footprint bench --frames N --orbit 2`, *fresh* = frame 1 "
    "(tables and classification included, loading excluded), *re-render* = the median of frames 2…N, each "
    "turned 2° further and reusing the visible-voxel lists. VTK: `vtkFixedPointVolumeRayCastMapper`, "
    "median frame after a warm-up frame. VolPack: pre-classified shear-warp, median frame; its one-off "
    "classification is excluded, as VolPack's own figures exclude it. Footprint's columns are its "
    "default (`--slicing auto`, its pilot in the fresh frame, subsampled where the pilot took it) where "
    "this run measured it; *fixed* is "
    "object slicing, and fixed ÷ float compares it with float object slicing.",
    "",
    "| volume | Footprint fresh, 1 thread | re-render, 1 thread | re-render, 2 threads | fixed re-render, 1 thread | VTK 1 thread | VTK 2 threads | VolPack |",
    "|---|---|---|---|---|---|---|---|",
]
ratios = []
# Footprint's own columns are its default (`--slicing auto`) where the run measured it; the fixed
# path is object slicing, so "fixed ÷ float" compares it with float object slicing.
head = "float-default" if any(r["accum"] == "float-default" for r in rows) else "float"
for v in volumes:
    f1, r1, r2 = footprint_times(v, head)
    x1 = med(v, "footprint", 1, "fixed", "median_ms")
    o1 = med(v, "footprint", 1, "float", "median_ms")
    t1, t2, vp = peer_times(v)
    lines.append(f"| {v} | {f1:.1f} ms | {r1:.1f} ms | {r2:.1f} ms | {x1:.1f} ms | {t1:.1f} ms | {t2:.1f} ms | {vp:.2f} ms |")
    ratios.append((v, t1 / f1, r1 / r2, r1 / vp, x1 / o1, t1 / r1))
lines += [
    "",
    "Ratios (the issue's targets in brackets; above 1 is better for the first two and the last):",
    "",
    "| volume | VTK 1 thread ÷ Footprint fresh 1 thread [≥ 5] | 1 ÷ 2 threads [≥ 1.8] | Footprint re-render ÷ VolPack [≤ 2] | fixed ÷ float [≤ 1.3] | VTK ÷ Footprint re-render |",
    "|---|---|---|---|---|---|",
]
for v, a, b, c, d, e in ratios:
    lines.append(f"| {v} | {a:.2f}× | {b:.2f}× | {c:.1f}× | {d:.2f}× | {e:.2f}× |")

if any(r["accum"] == "float-subsample" for r in rows):
    acc = {}
    if sub_csv:
        for r in csv.DictReader(open(sub_csv)):
            acc[(r["volume"], r["subsample"])] = r
    lines += [
        "",
        "### With `--subsample auto` (image-space level of detail, off by default)",
        "",
        "The frame rendered at 1/s of the size and resampled with Catmull-Rom (README, \"Subsampling\"); "
        "s keeps the footprints' shorter semi-axis ≥ 2 px (1 = unchanged). Same runs as above, float. "
        "Accuracy from `footprint verify --reference continuous` on the same view: *f64* is against the "
        "full-size f64 splatting reference (what subsampling changes), *continuous* against the "
        "volume-rendering integral, each as full size → `auto`.",
        "",
        "| volume | s | fresh, 1 thread | re-render, 1 thread | re-render, 2 threads | VTK 1 thread ÷ fresh [≥ 5] | re-render ÷ VolPack [≤ 2] | 1 ÷ 2 threads | PSNR against f64 | PSNR against the integral |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for v in volumes:
        f1, r1, r2 = footprint_times(v, "float-subsample")
        t1, _, vp = peer_times(v)
        a, full = acc.get((v, "auto")), acc.get((v, "1"))
        s_ = a["factor"] if a else "?"
        f64s = f"{float(full['psnr_f64_db']):.1f} → {float(a['psnr_f64_db']):.1f} dB" if a and full else "–"
        cont = f"{float(full['psnr_continuous_db']):.2f} → {float(a['psnr_continuous_db']):.2f} dB" if a and full else "–"
        lines.append(f"| {v} | {s_} | {f1:.1f} ms | {r1:.1f} ms | {r2:.1f} ms | {t1 / f1:.2f}× | {r1 / vp:.1f}× | {r1 / r2:.2f}× | {f64s} | {cont} |")

mrows = {(r["volume"], r["method"]): r for r in csv.DictReader(open(methods_csv))} if methods_csv else {}
if any(r["accum"] == "float-slabs" for r in rows):
    lines += [
        "",
        "## Methods: the default, object slicing, slabs, occlusion culling",
        "",
        "Same repetitions, float. *Default* is `--slicing auto` (object slicing where a pilot of sampled rays "
        "measures it at 44 dB or more against the continuous model, the thickest slabs that reach it "
        "otherwise, each tried at 1/s of the size first where the footprints allow it, `--subsample` unset; "
        "its fresh frame includes the pilot), *object* the paper's sheets, *slabs* image-aligned "
        "slabs one voxel spacing thick (`--slicing image`), *cull* adds occlusion culling at ε = 1/255 "
        "(`--cull 0.004`: 8×8-pixel tiles whose every pixel reached opacity 1 − ε take nothing more, and "
        "voxels landing only on them are skipped; each such pixel stays within ε per channel), "
        "*subsample* is `--subsample auto`. Accuracy: `footprint verify --reference continuous` with the "
        "same flags, PSNR against the default continuous model (opacity reconstruction) and, in brackets, "
        "against the f64 sheet reference of the same method; *culled* is the share of visible voxels "
        "culling skipped on one thread (`render --json`: `culled_voxels` ÷ (`voxels` + `culled_voxels`)). "
        "Data: `docs/perf/peers.csv`, `docs/perf/methods.csv`.",
        "",
        "| volume | method | fresh, 1 thread | re-render, 1 thread | re-render, 2 threads | 1 ÷ 2 threads [≥ 1.8] | "
        "VTK 1 thread ÷ fresh [≥ 5] | VTK 2 threads ÷ re-render 2 threads | re-render ÷ VolPack [≤ 2] | "
        "÷ object, 1 / 2 threads [slabs ≤ 2.5] | culled | PSNR vs the default model (vs f64) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for v in volumes:
        t1, t2, vp = peer_times(v)
        _, o1, o2 = footprint_times(v, "float")
        methods = [("default (`--slicing auto`)", "float-default", "default")] if any(
            r["accum"] == "float-default" for r in rows) else []
        for label, accum, method in methods + [("object", "float", "object"), ("object, cull", "float-cull", "object-cull"),
                                     ("object, subsample", "float-subsample", "object-subsample"),
                                     ("slabs", "float-slabs", "slabs"), ("slabs, cull", "float-slabs-cull", "slabs-cull")]:
            f1, r1, r2 = footprint_times(v, accum)
            m = mrows.get((v, method))
            if m:
                seen = int(m["voxels"]) + int(m["culled_voxels"])
                culled = f"{100 * int(m['culled_voxels']) / seen:.1f} %" if seen else "–"
                psnr = f"{m['psnr_continuous_db']} dB ({m['psnr_f64_db']} dB)"
            else:
                culled, psnr = "–", "–"
            lines.append(f"| {v} | {label} | {f1:.1f} ms | {r1:.1f} ms | {r2:.1f} ms | {r1 / r2:.2f}× | {t1 / f1:.2f}× | "
                         f"{t2 / r2:.2f}× | {r1 / vp:.1f}× | {r1 / o1:.2f}× / {r2 / o2:.2f}× | {culled} | {psnr} |")

if threads16_csv and os.path.exists(threads16_csv):
    t16 = list(csv.DictReader(open(threads16_csv)))
    if t16:
        counts = [c[1:-3] for c in t16[0] if c.startswith("t") and c.endswith("_ms") and c[1:-3].isdigit()]
        lines += [
            "",
            "## Threads on 16 cores",
            "",
            f"Not measured by this run (a 16-core machine is lent to some sessions only): `{threads16_csv}`, "
            f"made by `benches/threads16.sh` and `benches/threads16_report.py` on {t16[0]['machine']} at "
            f"commit {t16[0]['commit']} ({t16[0]['date']}): `footprint bench VOLUME --view 30,20,0 --frames 5 "
            "--orbit 2 --threads T`, the same u8 volumes and windows as above, median re-render; the thread "
            "counts alternated within each row. *default* is `--slicing auto` (its plan in the second column: "
            "s = the subsampling its pilot took), *object* `--slicing object --subsample 1`, *slabs* "
            "`--slicing image --subsample 1`. Target: 16 threads ≥ 10× one at 512² and 1024². *serial at 16* "
            "is the 16-thread frame outside its splat and composite phases: the tables, the slabs' classification "
            "(on every thread since a8a3277), the resampling and the rest (thread start-up, the image's hand-over). The machine is "
            "shared: the same binary's one-thread medians moved by up to 1.9× between two runs of the script "
            "that day, so the ratio from the fastest re-render of each is given beside the medians'. The same script "
            "at dd9a72d, before the slabs classified on every thread and the resampling stopped filling the image "
            "first: `docs/perf/threads16_dd9a72d_long.csv`; at 7e963b3, an hour before this run on a quieter "
            "machine (the walnut's default re-render 11.0 ms on 16 threads there, 19.1 ms here): "
            "`docs/perf/threads16_7e963b3_long.csv`.",
            "",
            "| volume | size | method | plan | " + " | ".join(f"{c} thr" for c in counts)
            + " | 2 ÷ 1 | 16 ÷ 1 [≥ 10] | 16 ÷ 1, fastest | serial at 16 |",
            "|---|---|---|---|" + "---|" * len(counts) + "---|---|---|---|",
        ]
        for r in t16:
            ms = lambda k: f"{float(r[k]):.1f} ms" if r.get(k) else "–"
            serial = "–"
            if r.get("t16_tables_ms"):
                cl = float(r["t16_classify_ms"])
                serial = (f"tables {float(r['t16_tables_ms']):.1f}, "
                          + (f"classify {cl:.1f}, " if cl > 0 else "")
                          + f"resample {float(r['t16_resample_ms']):.1f}, other {float(r['t16_other_ms']):.1f} ms")
            lines.append(f"| {r['volume']} | {r['size']}² | {r['method']} | {r['plan']} | "
                         + " | ".join(ms(f"t{c}_ms") for c in counts)
                         + f" | {float(r['speedup2']):.2f}× | {float(r['speedup16']):.1f}× | "
                         f"{float(r['speedup16_min']):.1f}× | {serial} |")

prows = {r["volume"]: r for r in csv.DictReader(open(post_csv))} if post_csv else {}
if any(r["accum"] == "float-post" for r in rows):
    lines += [
        "",
        "## Post-classification (`--classification post`)",
        "",
        "Values and gradients splatted into image-aligned slabs, classified per pixel (README, "
        "\"Post-classification\"), at its defaults (slab and value subsampling in the table), one thread, "
        "in the same repetitions as VTK above. Accuracy against the post-classified continuous integral "
        "(`footprint verify --classification post --reference continuous`, one ray per pixel centre) with "
        "the kernel's reconstruction (the default model) and with trilinear reconstruction (VTK's own); "
        "*pre* is Footprint's pre-classified default against the same integral; VTK's image (its "
        "`rgba.f32.raw`) is compared with the reference's PFM. Data: `docs/perf/post.csv`.",
        "",
        "| volume | slab, spacings | values at 1/s | post fresh, 1 thread | post re-render, 1 thread | VTK 1 thread | VTK ÷ post re-render [≥ 2] | post vs integral (kernel / trilinear) | pre vs integral | VTK vs integral (kernel / trilinear) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for v in volumes:
        p1, q1 = med(v, "footprint", 1, "float-post", "first_ms"), med(v, "footprint", 1, "float-post", "median_ms")
        t1, _, _ = peer_times(v)
        a = prows.get(v)
        acc_ = (f"{a['post_db']} / {a['post_trilinear_db']} dB", f"{a['pre_db']} dB",
                f"{a['vtk_db']} / {a['vtk_trilinear_db']} dB") if a else ("–", "–", "–")
        slab, vs = (a["slab"], a["value_subsample"]) if a else ("?", "?")
        lines.append(f"| {v} | {slab} | {vs} | {p1:.1f} ms | {q1:.1f} ms | {t1:.1f} ms | {t1 / q1:.2f}× | "
                     f"{acc_[0]} | {acc_[1]} | {acc_[2]} |")
        # Trilinear reconstruction (issue 75), where this run measured it.
        p3, q3 = (med(v, "footprint", 1, "float-post-trilinear", k) for k in ("first_ms", "median_ms"))
        if a and a.get("trilinear_post_trilinear_db") and q3 == q3:
            lines.append(f"| {v}, `--reconstruction trilinear` | {a['trilinear_slab']} | {vs} | {p3:.1f} ms | "
                         f"{q3:.1f} ms | {t1:.1f} ms | {t1 / q3:.2f}× | {a['trilinear_post_kernel_db']} / "
                         f"{a['trilinear_post_trilinear_db']} dB | – | – |")

def perf_rows(name):
    """The rows of docs/perf/NAME beside the page, or none if that run has not been made."""
    path = os.path.join(os.path.dirname(out_md), "perf", name)
    return list(csv.DictReader(open(path))) if os.path.exists(path) else []


# Post-classification's two reconstructions (issue 75): benches/post_reconstruction.sh, if run.
rr = perf_rows("post-reconstruction.csv")
if rr:
    lines += [
        "",
        "## Post-classification, kernel and trilinear reconstruction",
        "",
        "`--classification post --reconstruction kernel|trilinear` at their default slabs (kernel 0.7 "
        "for emission, 0.4 Phong; trilinear 0.5 and 0.3), 512², each against the post-classified "
        "continuous integral *of its own reconstruction* (`verify --reference continuous`); time at "
        "30,20,0, emission, one thread, `bench --frames 3 --orbit 2`, the two run alternately "
        f"(medians). `benches/post_reconstruction.sh`, {rr[0]['date']} on "
        f"{rr[0]['cpu']}. Data: `docs/perf/post-reconstruction.csv`.",
        "",
        "| volume | view | shading | reconstruction | slab | values at 1/s | vs its integral | fresh | re-render |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rr:
        t = (f"{float(r['first_ms']):.0f} ms | {float(r['median_ms']):.0f} ms" if r["first_ms"] else "– | –")
        lines.append(f"| {r['volume']} | {r['view']} | {r['shading']} | {r['reconstruction']} | {r['slab']} | "
                     f"{r['value_subsample']} | {r['psnr_own_db']} dB | {t} |")
    low = [float(r["psnr_own_db"]) for r in rr if r["reconstruction"] == "trilinear"]
    if low:
        lines += ["", f"Trilinear: {min(low):.2f}–{max(low):.2f} dB against its integral over these cases."]
    vr = perf_rows("post-vtk.csv")
    vtk = next((r for r in vr if r["renderer"] == "vtk-fixedpoint"), None)
    if vtk:
        lines += [
            "",
            "Beside VTK on the real-size CT (`VTK_PYTHON=… benches/post_reconstruction.sh`: "
            "`vtkFixedPointVolumeRayCastMapper`, one thread, azimuth 30 / elevation 20, Footprint at "
            "VTK's exact camera, each run alternately; every image against both post-classified "
            f"integrals; {vtk['date']}, {vtk['cpu']}; data `docs/perf/post-vtk.csv`):",
            "",
            "| renderer | slab | fresh | re-render | VTK ÷ it [target ≥ 1] | vs kernel integral | vs trilinear integral |",
            "|---|---|---|---|---|---|---|",
        ]
        for r in vr:
            ratio = float(vtk["median_ms"]) / float(r["median_ms"])
            lines.append(f"| {r['renderer']} | {r['slab']} | {float(r['first_ms']):.0f} ms | "
                         f"{float(r['median_ms']):.0f} ms | {ratio:.2f}× | {r['psnr_kernel_db']} dB | "
                         f"{r['psnr_trilinear_db']} dB |")

# The real-size CT (issue 74): benches/real_size.sh's medians, if it has run.
real = perf_rows("real-size.csv")
if real:
    sheets = next((r for r in real if r["method"] == "object"), None)
    lines += [
        "",
        "## A real-size CT: the phantom of `benches/ct_phantom.py`",
        "",
        "256×256×113 voxels of uint16, spacing 1:1:2, a skull of dense bone 5–9 mm thick (a few voxels "
        "across, one or two along z), teeth, sinuses, vertebrae, CT noise; grey ramp 1200→2400, view "
        f"30,20,0, 512², one thread; measured {real[0]['date']} on {real[0]['cpu']} (not necessarily the "
        "run above). `benches/real_size.sh` (medians of alternated runs of `footprint "
        "bench --frames 4 --orbit 2`; accuracy from `footprint verify --reference continuous`, the "
        "opacity model; `docs/perf/real-size.csv`). Object slicing stays well below the 44 dB target "
        "here, so the default plan renders slabs. *Section stencils*: `--depth-phases 8 --phases 8` "
        "(each voxel's depth snapped to one of 8 phases per slab, sections splatted from stencils "
        "built once per view, slab-major accumulators).",
        "",
        "| method | vs the model | fresh frame | re-render | splat | composite | (pixel, slab) updates "
        "| re-render ÷ object slicing's |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in real:
        ratio = float(r["median_ms"]) / float(sheets["median_ms"]) if sheets else float("nan")
        lines.append(f"| {r['method']} | {float(r['psnr_continuous_db']):.2f} dB | {float(r['first_ms']):.0f} ms | "
                     f"{float(r['median_ms']):.0f} ms | {float(r['splat_ms']):.0f} ms | "
                     f"{float(r['composite_ms']):.0f} ms | {int(r['pixel_updates']):,} | {ratio:.1f}× |")

frows = list(csv.DictReader(open(floor_csv))) if floor_csv else []
if frows:
    def floor_med(vol, pixel, key):
        return statistics.median(float(r[key]) for r in frows if r["volume"] == vol and r["pixel"] == pixel)

    lines += [
        "",
        "## The floor: what splatting at 512² cannot avoid",
        "",
        "A sheet-buffer splatter makes one *pixel update* per non-zero footprint weight of each visible "
        "voxel and one *composite* per sheet pixel a footprint touched; both counts are fixed by the scene, "
        "the kernel and the image size (`footprint render --json` on the same scene). `benches/floor.rs` "
        "times that work alone in the simplest vectorised loops (one weight read from a row, no blend of "
        "stencils, no per-voxel work; square footprints of the scene's mean width; one contiguous run "
        "composited per sheet), once per repetition right after VolPack: *RGBA* with the renderer's "
        "four-channel f32 pixel, *LA* with a two-channel one, the cheapest a grey scene could use. Any "
        "frame of this pipeline at this size costs at least the floor, so a re-render within 2× of VolPack "
        "needs floor ÷ VolPack ≤ 2, and 5× VTK needs VTK ÷ floor ≥ 5. Data: `docs/perf/floor.csv`.",
        "",
        "| volume | voxels splatted | pixel updates | composites | floor RGBA | floor LA | VolPack | floor ÷ VolPack, RGBA / LA [≤ 2 to meet it] | VTK 1 thread ÷ floor, RGBA / LA [≥ 5 to meet it] | Footprint re-render ÷ floor RGBA |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for v in volumes:
        r0 = next((r for r in frows if r["volume"] == v), None)
        if r0 is None:
            continue
        fr, fl = floor_med(v, "rgba", "floor_ms"), floor_med(v, "la", "floor_ms")
        _, r1, _ = footprint_times(v, "float")
        t1, _, vp = peer_times(v)
        lines.append(
            f"| {v} | {int(r0['voxels']):,} | {int(r0['pixel_updates']):,} | {int(r0['composites']):,} | "
            f"{fr:.1f} ms | {fl:.1f} ms | {vp:.2f} ms | {fr / vp:.1f}× / {fl / vp:.1f}× | "
            f"{t1 / fr:.2f}× / {t1 / fl:.2f}× | {r1 / fr:.2f}× |")

srows = list(csv.DictReader(open(scaling_csv)))
fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
for ax, kind, xlabel, title in [
    (axes[0], "image", "image side, pixels (square image)", "256³ blobs, 1 thread"),
    (axes[1], "volume", "volume side, voxels (cube)", "synthetic blobs at 512², 1 thread"),
]:
    pts = [(int(r["size"]), float(r["first_ms"]), float(r["median_ms"])) for r in srows if r["kind"] == kind]
    if not pts:
        continue
    xs = [p[0] for p in pts]
    ax.loglog(xs, [p[1] for p in pts], "o-", label="fresh (frame 1)")
    ax.loglog(xs, [p[2] for p in pts], "s-", label="re-render (median of later frames)")
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xticks(xs)
    ax.set_xticklabels([str(x) for x in xs])
    ax.set_xlabel(xlabel)
    ax.set_ylabel("frame time, ms")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
fig.tight_layout()
fig.savefig(stem + ".svg")
fig.savefig(stem + ".png", dpi=90)
lines += [
    "",
    "## How cost grows",
    "",
    f"![frame time against image and volume size]({os.path.relpath(stem, os.path.dirname(out_md))}.png)",
    "",
    "Left: the 256³ blobs at 128² … 2048²; right: one synthetic scene (a shell and three blobs) sampled "
    "at 64³ … 512³, rendered at 512². Data: `docs/perf/scaling.csv`.",
    "",
    "| kind | size | fresh ms | re-render ms |",
    "|---|---|---|---|",
]
for r in srows:
    lines.append(f"| {r['kind']} | {r['size']} | {float(r['first_ms']):.1f} | {float(r['median_ms']):.1f} |")
lines += [
    "",
    "Side-by-side pictures (Footprint | VTK | VolPack) are in `docs/images/peers-*.png`.",
    "",
]
open(out_md, "w").write("\n".join(lines))
