#!/usr/bin/env python3
"""Validates `--quality DB --quality-reference continuous` (or `field`) against the full reference.

  validate_quality_continuous.py FOOTPRINT VOLUME... [--size 256x256] [--targets 40,50,60]
                                 [--views 0,0,0:30,20,0] [--shadings emission,phong]
                                 [--reference continuous|field]

A VOLUME `scene:N` is the built-in scene sampled N³ (`--scene-size N`); with `--reference field`
(built-in scene only) the reference is the continuous integral of its field sampled 128³, and
the pilot may choose refinement (`--refine 0`). For every volume, view, shading and target it runs

  FOOTPRINT verify VOLUME --quality Q --quality-reference R --reference R

which chooses a configuration on a pilot of sampled rays, renders it, and measures it against
the continuous integral over the whole image. Then every candidate the pilot tried is verified
the same way with its configuration given explicitly (once per volume, view and shading), so
that each pilot estimate can be set against the whole image's figure. Prints a Markdown table
per choice and a summary of estimate − actual over every candidate. Exits 1 if a choice the
pilot judged to reach its target misses it, or if a candidate the pilot rejected (a cheaper
one) in fact reached it by more than 1 dB (a costly false rejection).
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile


def flags(label):
    """Command-line flags for a configuration label (`pipeline::config::Config::label`)."""
    parts = label.split("/")
    if parts[0] == "image":
        return ["--slicing", "image", "--slab", parts[1].split("=")[1]]
    method = "robust" if parts[2] == "view" else parts[2]
    refine = ["--refine", parts[5].split("=")[1]] if len(parts) > 5 else []
    # Object slicing said explicitly: the default, `--slicing auto`, would choose again.
    return ["--slicing", "object", "--table", parts[0].split("=")[1], "--lookup", parts[1],
            "--method", method, "--accum", parts[3]] + refine


def source(volume):
    """The command-line arguments naming VOLUME (`scene:N`: the built-in scene at N³)."""
    if volume.startswith("scene:"):
        return ["--scene-size", volume.split(":")[1]]
    return [volume]


def verify(fp, volume, reference, common, extra, tmp):
    out = os.path.join(tmp, "v.json")
    cmd = ([fp, "verify"] + source(volume) + ["--reference", reference, "--json", out] + common
           + extra)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(out) as f:
        return json.load(f)


def option(args, name, default):
    if name in args:
        i = args.index(name)
        value = args[i + 1]
        del args[i:i + 2]
        return value
    return default


def main():
    args = sys.argv[1:]
    size = option(args, "--size", "256x256")
    targets = [float(t) for t in option(args, "--targets", "40,50,60").split(",")]
    views = option(args, "--views", "0,0,0:30,20,0").split(":")
    shadings = option(args, "--shadings", "emission,phong").split(",")
    reference = option(args, "--reference", "continuous")
    fp, volumes = args[0], args[1:]
    failed = False
    deviations = []
    print("| volume | view | shading | target | chosen | pilot estimate / bound | actual | "
          "rejected (pilot → actual) | pilot s |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for volume in volumes:
            name = volume if volume.startswith("scene:") else os.path.basename(volume).split("_")[0]
            for view in views:
                for shading in shadings:
                    common = ["--size", size, "--view", view, "--shading", shading]
                    actual = {}  # label -> whole-image PSNR against the continuous integral

                    def measured(label):
                        if label not in actual:
                            j = verify(fp, volume, reference, common, flags(label), tmp)
                            actual[label] = j["continuous"]["psnr_db"]
                        return actual[label]

                    for q in targets:
                        j = verify(fp, volume, reference, common,
                                   ["--quality", str(q), "--quality-reference", reference], tmp)
                        quality = j["quality"]
                        chosen = quality["chosen"]
                        got = j["continuous"]["psnr_db"]
                        actual.setdefault(chosen, got)
                        pilot = quality["pilot"]
                        notes = []
                        bad = False
                        for t in pilot["tried"]:
                            a = measured(t["config"])
                            if t["estimate_db"] is not None and a is not None:
                                deviations.append(t["estimate_db"] - a)
                            if t["config"] != chosen:
                                notes.append(f"{t['config']} {t['bound_db']:.1f} → {a:.1f}")
                                if a >= q + 1.0 and t["bound_db"] < q:
                                    bad = True
                        mine = next(t for t in pilot["tried"] if t["config"] == chosen)
                        reached = mine["bound_db"] >= q
                        if reached and got < q:
                            bad = True
                        failed |= bad
                        seconds = pilot["reference_seconds"] + pilot["render_seconds"]
                        print(f"| {name} | {view} | {shading} | {q:g} | {chosen} | "
                              f"{mine['estimate_db']:.1f} / {mine['bound_db']:.1f} | {got:.1f}"
                              f"{'' if reached else ' (unreachable: most accurate)'} | "
                              f"{'; '.join(notes) or '–'} | {seconds:.2f}"
                              f"{' **FAIL**' if bad else ''} |", flush=True)
    if deviations:
        d = sorted(deviations)
        print(f"\npilot estimate − whole-image PSNR over {len(d)} candidate renders: "
              f"median {statistics.median(d):+.2f} dB, range {d[0]:+.2f} to {d[-1]:+.2f} dB")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
