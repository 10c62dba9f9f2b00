#!/usr/bin/python3
"""bench.cycles: `iris bench --cycles --cycles-adaptive` with real Blender (a
small Cornell box, mis, two budgets, two seeds).

Checks: one Cycles row per budget and seed, each at the spp of the mis run
with that seed and budget, rendered with that seed (its own EXR, and the two
seeds' images differ); Cycles' relMSE against iris's reference is finite and
within 3x of iris mis's at the same spp (the exported scene is the same scene:
a wrong light or material would put Cycles far off); table.md's Cycles row is
the mean over the seeds, as iris's rows are. The cycles-adaptive rows: one per
budget and seed, rendered by a Cycles that held adaptive sampling on at the
asked threshold with the budget as its time limit (read back from Blender),
their relMSE within 6x of mis's at the same budget.

Skips (exit 77) without Blender. Usage: test_bench_cycles.py WORKDIR IRIS
"""
import json
import os
import shutil
import subprocess
import sys

failures = 0


def check(ok, what):
    global failures
    if not ok:
        failures += 1
        print("FAIL:", what)
    return ok


def main():
    work, iris = sys.argv[1], sys.argv[2]
    blender = os.environ.get("IRIS_BLENDER", "blender")
    if not shutil.which(blender):
        print("SKIP: no Blender")
        return 77
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    out = os.path.join(work, "out")
    args = [iris, "bench", "cornell-box", "--methods", "mis", "--times", "0.4,0.8", "--seeds", "2",
            "--width", "32", "--height", "24", "--reference", "auto", "--reference-spp", "1024",
            "--cache", os.path.join(work, "cache"), "--threads", "2", "--cycles", "--cycles-adaptive",
            "--cycles-threshold", "0.02", "--no-charts",
            "--quiet", "--out", out]
    p = subprocess.run(args, capture_output=True, text=True, timeout=600)
    if not check(p.returncode == 0, f"bench exit {p.returncode}: {p.stderr.strip()[-400:]}"):
        return 1
    rows = json.load(open(os.path.join(out, "results.json")))["rows"]
    mis = {(r["budget_s"], r["seed"]): r for r in rows if r["method"] == "mis"}
    cyc = {(r["budget_s"], r["seed"]): r for r in rows if r["method"] == "cycles"}
    check(sorted(cyc) == sorted(mis) and len(cyc) == 4, f"Cycles rows {sorted(cyc)} vs mis rows {sorted(mis)}")
    for key, c in sorted(cyc.items()):
        m = mis.get(key)
        if not m:
            continue
        check(c["spp"] == m["spp"], f"{key}: Cycles at {c['spp']} spp, mis reached {m['spp']}")
        ok = c["relmse"] > 0 and c["relmse"] < 3 * m["relmse"] and m["relmse"] < 3 * c["relmse"]
        check(ok, f"{key}: Cycles relMSE {c['relmse']:.4g} vs iris mis {m['relmse']:.4g} at {m['spp']} spp")
        exr = os.path.join(out, "cycles", "cornell-box", f"cycles-{key[0]:g}s-seed{key[1]}.exr")
        check(os.path.isfile(exr), f"no {exr}")
    # the seeds are Cycles' seeds: the two images of one budget differ
    for b in (0.4, 0.8):
        a = os.path.join(out, "cycles", "cornell-box", f"cycles-{b:g}s-seed0.exr")
        c = os.path.join(out, "cycles", "cornell-box", f"cycles-{b:g}s-seed1.exr")
        if os.path.isfile(a) and os.path.isfile(c):
            check(open(a, "rb").read() != open(c, "rb").read(), f"{b} s: seeds 0 and 1 gave the same image")
    # the table's Cycles cell is the mean over the seeds
    table = open(os.path.join(out, "table.md")).read()
    line = next((l for l in table.splitlines() if l.startswith("| cycles |")), "")
    mean = (cyc.get((0.8, 0), {}).get("relmse", 0) + cyc.get((0.8, 1), {}).get("relmse", 0)) / 2
    check(f"{mean:.4g}" in line, f"table's Cycles row {line!r} lacks the mean relMSE {mean:.4g}")
    # Cycles as users run it: adaptive at the threshold, the budget its time limit
    ada = {(r["budget_s"], r["seed"]): r for r in rows if r["method"] == "cycles-adaptive"}
    check(sorted(ada) == sorted(mis), f"adaptive Cycles rows {sorted(ada)} vs mis rows {sorted(mis)}")
    for key, c in sorted(ada.items()):
        m = mis.get(key)
        ok = m and c["relmse"] > 0 and c["relmse"] < 6 * m["relmse"] and m["relmse"] < 6 * c["relmse"]
        check(ok, f"{key}: adaptive Cycles relMSE {c['relmse']:.4g} vs iris mis {m and m['relmse']}")
        log = os.path.join(out, "cycles", "cornell-box", f"cycles-adaptive-{key[0]:g}s-seed{key[1]}.log")
        text = open(log).read() if os.path.isfile(log) else ""
        want = f"adaptive=1 adaptive_threshold=0.02 time_limit={key[0]:g}"
        check(want in text, f"{log}: Blender did not report '{want}'")
    fixed = os.path.join(out, "cycles", "cornell-box", "cycles-0.4s-seed0.log")
    check(os.path.isfile(fixed) and "adaptive=0 " in open(fixed).read(), f"{fixed}: fixed-spp Cycles was adaptive")
    print("bench.cycles:", "ok" if failures == 0 else f"{failures} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
