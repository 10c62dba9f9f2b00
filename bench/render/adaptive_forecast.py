#!/usr/bin/python3
"""Will adaptive sampling pay on a scene? A forecast from two short renders
(docs/benchmarks.md, "A cross-validated forecast of adaptive sampling").

For each SCENE[:METHOD] (a built-in scene or a scene file; METHOD default mis)
renders A (8 spp, seed SA) and B (16 spp, seed SB) with --variance, 72 rows,
and prints three forecasts of relMSE(fixed spp) / relMSE(adaptive) at equal
samples, from each pixel's relative variance per sample v = var / (m^2 + 0.01)
(m: the two renders' mean, pooled 3 x 3):
  - cross-validated: samples allotted in proportion to w = sqrt(v_A pooled
    3 x 3), A standing for the scouts the relmse rule decided from
    (renderer/adaptive.h), and the result judged by B's independent v:
    mean(v_B) / (mean(v_B / w) * mean(w)); also with the 0.1% of pixels of
    largest v_B left out, as bench's relMSE leaves out the largest errors;
  - ideal, pooled: the same with w from B itself, mean(pool(v_B)) /
    mean(sqrt(pool(v_B)))^2 (the forecast docs/benchmarks.md measured on
    2026-12-05, which chose adaptive sampling for sky-room-pane, where it lost);
  - ideal, unpooled: mean(v_B) / mean(sqrt(v_B))^2.
A forecast ignores the scouts' cost (~1/9 of the samples) and the sampler's
loss at uneven sample counts. It models the scouts' rule, which decided
budgeted renders until 94a5892; since then the higher-ranked neighbours'
image samples decide (docs/benchmarks.md, "Adaptive sampling from the
neighbours"), with no scouts and far more samples behind each decision.

usage: bench/render/adaptive_forecast.py IRIS SCENE[:METHOD]... [--seeds SA,SB]
(Debian's /usr/bin/python3 with numpy; oiiotool reads the EXRs)
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from error_split import DROP, EPS, read_exr  # noqa: E402

SPP_A, SPP_B = 8, 16


def pool(x):
    p = np.pad(x, 1, mode="edge")
    h, w = x.shape
    return sum(p[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] for dy in (-1, 0, 1) for dx in (-1, 0, 1)) / 9.0


def render(iris, scene, method, spp, seed, out):
    subprocess.run([iris, "render", scene, "--method", method, "--force-guiding", "--spp", str(spp), "--height",
                    "72", "--seed", str(seed), "--threads", "2", "--quiet", "--variance", "-o", out], check=True)


def forecasts(a, va, b, vb):
    m = pool((SPP_A * a + SPP_B * b).mean(axis=2) / (SPP_A + SPP_B))
    den = m ** 2 + EPS
    ra, rb = va.mean(axis=2) / den, vb.mean(axis=2) / den  # relative variance of each mean
    w = np.sqrt(pool(ra))
    w = np.maximum(w, 1e-3 * w.mean())  # no pixel without samples (the rule's floor is its scouts)

    def judged(keep):  # samples spread over every pixel by w, the error counted where keep
        return rb[keep].mean() / ((rb[keep] / w[keep]).mean() * w.mean())

    k = max(1, int(rb.size * DROP))
    cv, cv_drop = judged(np.ones_like(rb, bool)), judged(rb < np.sort(rb.ravel())[-k])
    prb = pool(rb)
    pooled = prb.mean() / np.sqrt(prb).mean() ** 2
    unpooled = rb.mean() / np.sqrt(rb).mean() ** 2
    return cv, cv_drop, pooled, unpooled


def main():
    args = sys.argv[1:]
    seeds = (101, 202)
    if "--seeds" in args:
        i = args.index("--seeds")
        seeds = tuple(int(s) for s in args[i + 1].split(","))
        del args[i:i + 2]
    if len(args) < 2 or len(seeds) != 2:
        sys.exit(__doc__.strip().splitlines()[-2])
    iris = os.path.abspath(args[0])
    print(f"| scene | method | cross-validated | without the top {DROP:.1%} | ideal, pooled | ideal, unpooled |")
    print("|---|---|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for spec in args[1:]:
            scene, _, method = spec.partition(":")
            method = method or "mis"
            if os.path.exists(scene):
                scene = os.path.abspath(scene)
            pa, pb = os.path.join(tmp, "a.exr"), os.path.join(tmp, "b.exr")
            try:
                render(iris, scene, method, SPP_A, seeds[0], pa)
                render(iris, scene, method, SPP_B, seeds[1], pb)
            except (subprocess.CalledProcessError, OSError) as e:
                sys.exit(f"adaptive_forecast.py: rendering {spec} failed ({e})")
            channels = "R,G,B,var.R,var.G,var.B"  # one read of each image
            a, b = read_exr(pa, tmp, channels), read_exr(pb, tmp, channels)
            cv, cv_drop, pooled, unpooled = forecasts(a[..., :3], a[..., 3:], b[..., :3], b[..., 3:])
            name = os.path.basename(scene)
            print(f"| {name} | {method} | {cv:.2f} | {cv_drop:.2f} | {pooled:.2f} | {unpooled:.2f} |", flush=True)


if __name__ == "__main__":
    main()
