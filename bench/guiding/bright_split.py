#!/usr/bin/python3
"""relMSE of renders against a reference, split into the brightest pixels of
the reference (a caustic, the sun's patch) and the rest (docs/guiding.md,
"Refinement"): per pixel (1/3) sum_c (t - r)^2 / (r^2 + 0.01), the worst 0.1%
of each image's pixels dropped as bench does, then the mean over the images
of a group (per image, as bench averages seeds).

usage: bench/guiding/bright_split.py REF.exr --share 0.05 LABEL=A.exr,B.exr,... ...
"""
import argparse
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from error_split import DROP, EPS, read_exr  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("ref")
ap.add_argument("--share", type=float, default=0.05)
ap.add_argument("groups", nargs="+")
a = ap.parse_args()
with tempfile.TemporaryDirectory() as t:
    ref = read_exr(a.ref, t)
    lum = ref.mean(axis=-1)
    bright = lum >= np.quantile(lum, 1.0 - a.share)
    print(f"| images | relMSE (drop 0.1%) | brightest {100 * a.share:g}% of pixels | rest |")
    print("|---|---|---|---|")
    for g in a.groups:
        label, _, files = g.partition("=")
        rows = []
        for f in files.split(","):
            e = ((read_exr(f, t) - ref) ** 2 / (ref ** 2 + EPS)).mean(axis=-1)
            keep = e <= np.quantile(e, 1.0 - DROP)
            rows.append((e[keep].mean(), e[keep & bright].mean(), e[keep & ~bright].mean()))
        m = np.mean(rows, axis=0)
        print(f"| {label} ({len(rows)}) | {m[0]:.5f} | {m[1]:.5f} | {m[2]:.5f} |")
