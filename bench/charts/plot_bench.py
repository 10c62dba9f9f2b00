#!/usr/bin/python3
"""Convergence charts of `iris bench`: log-log relMSE against seconds, one line
per method, the spread over seeds as a min/max band.

Usage: plot_bench.py DIR   (reads DIR/results.csv and DIR/results.json, writes
DIR/charts/<scene>.png|svg and DIR/charts/convergence.png|svg with every scene)

Run by `iris bench` with Debian's /usr/bin/python3 (python3-matplotlib).
docs/benchmarks.md describes the charts.
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter, NullFormatter  # noqa: E402

# Reproducible SVG output (no date, fixed ids).
matplotlib.rcParams["svg.hashsalt"] = "iris-bench"
matplotlib.rcParams["svg.fonttype"] = "path"

STYLE = {
    "mis": ("#1f77b4", "o", "-"),
    "guided": ("#d62728", "s", "-"),
    "guided-nee": ("#ff7f0e", "D", "-"),
    "nee": ("#2ca02c", "^", "-"),
    "bsdf": ("#9467bd", "v", "-"),
    "cycles": ("#444444", "x", "--"),
    "cycles-adaptive": ("#888888", "+", ":"),
}


def load(dir_):
    rows = []
    with open(os.path.join(dir_, "results.csv"), newline="") as f:
        for r in csv.DictReader(f):
            rows.append(r)
    meta = {}
    try:
        with open(os.path.join(dir_, "results.json")) as f:
            meta = json.load(f)
    except (OSError, ValueError):
        pass
    return rows, meta


def curves(rows, scene):
    """{method: [(budget, mean seconds, mean relmse, min, max, n)]} sorted by budget."""
    acc = {}
    for r in rows:
        if r["scene"] != scene:
            continue
        rel = float(r["relmse"])
        if not math.isfinite(rel) or rel <= 0:
            continue
        key = (r["method"], float(r["budget_s"]))
        acc.setdefault(key, []).append((float(r["seconds"]), rel))
    out = {}
    for (m, b), v in acc.items():
        secs = sum(s for s, _ in v) / len(v)
        rels = [x for _, x in v]
        out.setdefault(m, []).append((b, secs, sum(rels) / len(rels), min(rels), max(rels), len(v)))
    for m in out:
        out[m].sort()
    return out


def method_order(meta, found):
    order = list(meta.get("params", {}).get("methods", []))
    for m in sorted(found):
        if m not in order:
            order.append(m)
    return [m for m in order if m in found]


def draw(ax, scene, rows, meta, target):
    cs = curves(rows, scene)
    for m in method_order(meta, cs):
        pts = cs[m]
        colour, marker, ls = STYLE.get(m, ("#17becf", "o", "-"))
        x = [p[1] for p in pts]
        y = [p[2] for p in pts]
        lo = [p[3] for p in pts]
        hi = [p[4] for p in pts]
        n = max(p[5] for p in pts)
        label = m if n <= 1 else f"{m} ({n} seeds)"
        ax.plot(x, y, ls, color=colour, marker=marker, markersize=4, linewidth=1.5, label=label)
        if n > 1:
            ax.fill_between(x, lo, hi, color=colour, alpha=0.18, linewidth=0)
    if target and target > 0:
        ax.axhline(target, color="#888888", linewidth=0.8, linestyle=":")
        ax.annotate(f"target {target:.3g}", xy=(0.01, target), xycoords=("axes fraction", "data"),
                    fontsize=7, color="#666666", va="bottom")
    ax.set_xscale("log")
    ax.set_yscale("log")
    # seconds as plain numbers (1, 2, 4 ...) rather than powers of ten
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("seconds (wall-clock, setup included)")
    ax.set_ylabel("relMSE")
    ax.set_title(scene)
    ax.grid(True, which="both", linewidth=0.4, alpha=0.5)
    ax.legend(fontsize=7, loc="best")


def save(fig, base):
    fig.savefig(base + ".png", dpi=110)
    fig.savefig(base + ".svg", metadata={"Date": None})
    plt.close(fig)


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    dir_ = argv[1]
    rows, meta = load(dir_)
    scenes = [s["name"] for s in meta.get("scenes", [])]
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    targets = {s["name"]: s.get("target_relmse") for s in meta.get("scenes", [])}
    out = os.path.join(dir_, "charts")
    os.makedirs(out, exist_ok=True)
    for s in scenes:
        fig, ax = plt.subplots(figsize=(5.2, 3.9))
        draw(ax, s, rows, meta, targets.get(s))
        fig.tight_layout()
        save(fig, os.path.join(out, s))
    n = max(1, len(scenes))
    cols = min(3, n)
    rows_ = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows_, cols, figsize=(5.0 * cols, 3.9 * rows_), squeeze=False)
    for i, s in enumerate(scenes):
        draw(axes[i // cols][i % cols], s, rows, meta, targets.get(s))
    for j in range(len(scenes), rows_ * cols):
        axes[j // cols][j % cols].axis("off")
    fig.tight_layout()
    save(fig, os.path.join(out, "convergence"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
