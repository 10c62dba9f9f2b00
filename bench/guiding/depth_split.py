#!/usr/bin/python3
"""Where a method's error is by path depth (docs/guiding.md, "Sky visibility").

  bench/guiding/depth_split.py IRIS SCENE [--methods mis,guided-nee] [--spp 64]
      [--seeds 1,2,3,4] [--ref-spp 4096] [--width 144 --height 96] [--out DIR]
      [-- extra iris render options for the methods' renders]

Renders references (mis, independent sampler, seed 999) with --max-depth 0
(direct light only), 1 (and one bounce) and the default, then each method at
--spp for each seed and the same three depths, and prints per method and depth
the relMSE (bench's: (1/3) sum_c (t - r)^2 / (R^2 + 0.01), top 0.1% of pixels
dropped) against the reference of the same depth, always normalised by the
full reference R, so the three numbers share one scale: depth 0 is the error of
direct light at the first vertex, depth 1 adds the first bounce, "full" is the
render's. Debian's /usr/bin/python3 with numpy; oiiotool reads the EXRs.
"""
import argparse
import importlib.util
import os
import subprocess
import sys
import tempfile

import numpy as np

spec = importlib.util.spec_from_file_location(
    "error_split", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "error_split.py"))
es = importlib.util.module_from_spec(spec)
spec.loader.exec_module(es)

ap = argparse.ArgumentParser()
ap.add_argument("iris")
ap.add_argument("scene")
ap.add_argument("--methods", default="mis,guided-nee")
ap.add_argument("--spp", type=int, default=64)
ap.add_argument("--seeds", default="1,2,3,4")
ap.add_argument("--ref-spp", type=int, default=4096)
ap.add_argument("--width", type=int, default=144)
ap.add_argument("--height", type=int, default=96)
ap.add_argument("--out", default=None)
a, extra = ap.parse_known_args()  # the rest goes to every iris render of a method
extra = [x for x in extra if x != "--"]
out = a.out or tempfile.mkdtemp(prefix="depth-split-")
os.makedirs(out, exist_ok=True)
size = ["--width", str(a.width), "--height", str(a.height)]
depths = [("0", ["--max-depth", "0"]), ("1", ["--max-depth", "1"]), ("full", [])]


def render(path, opts):
    if not os.path.exists(path):
        subprocess.run([a.iris, "render", a.scene, "-q", "-o", path] + size + opts, check=True)


def relmse(img, ref, den):
    e = np.sort((((img - ref) ** 2) / den).mean(axis=2).ravel())
    return e[: int(len(e) * 0.999)].mean()


with tempfile.TemporaryDirectory() as tmp:
    refs = {}
    for name, opts in depths:
        p = os.path.join(out, f"ref-{name}.exr")
        render(p, ["--method", "mis", "--sampler", "independent", "--seed", "999", "--spp", str(a.ref_spp)] + opts)
        refs[name] = es.read_exr(p, tmp)
    den = refs["full"] ** 2 + 0.01
    print(f"{a.scene} {a.width}x{a.height}, {a.spp} spp, seeds {a.seeds}; references {a.ref_spp} spp (mis)")
    print("| method | depth 0 (direct) | depth <= 1 | full | share of full: depth 0 / depth <= 1 |")
    print("|---|---|---|---|---|")
    for m in a.methods.split(","):
        vals = {}
        for name, opts in depths:
            v = []
            for s in a.seeds.split(","):
                p = os.path.join(out, f"{m}-{name}-{s}.exr")
                render(p, ["--method", m, "--seed", s, "--spp", str(a.spp)] + opts + extra)
                v.append(relmse(es.read_exr(p, tmp), refs[name], den))
            vals[name] = float(np.mean(v))
        print(f"| {m} | {vals['0']:.5f} | {vals['1']:.5f} | {vals['full']:.5f} | "
              f"{vals['0'] / vals['full']:.2f} / {vals['1'] / vals['full']:.2f} |")
        sys.stdout.flush()
