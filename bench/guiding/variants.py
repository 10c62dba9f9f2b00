#!/usr/bin/python3
"""Guiding variants at equal CPU time, one scene (docs/guiding.md, "Training").

  bench/guiding/variants.py BUILD_DIR REF.exr SCENE --spp N --seeds 1,2,3 [--height 96]
      [--method guided-nee] 'label=bench_guiding options' ...

Runs bench_guiding once per variant and seed on one thread, and prints per variant
the mean relMSE_drop, mean CPU seconds (render + guide build, training included),
efficiency = relMSE_drop x CPU s (relMSE at equal time up to a constant; lower is
better) and its ratio to the first variant's, as geometric mean of the per-seed
ratios (paired by seed) with their range. A variant label may carry its own method
as 'label@method=options'."""
import argparse, math, subprocess, sys

ap = argparse.ArgumentParser()
ap.add_argument("build"); ap.add_argument("ref"); ap.add_argument("scene")
ap.add_argument("--spp", type=int, default=64); ap.add_argument("--seeds", default="1,2,3")
ap.add_argument("--height", type=int, default=96); ap.add_argument("--method", default="guided-nee")
ap.add_argument("variants", nargs="+")
a = ap.parse_args()
seeds = [int(s) for s in a.seeds.split(",")]
rows = []
for v in a.variants:
    label, _, opts = v.partition("=")
    method = a.method
    if "@" in label:
        method = label.split("@", 1)[1]
    per = []
    for s in seeds:
        cmd = [f"{a.build}/bench/guiding/bench_guiding", a.scene, method, "--spp", str(a.spp), "--height",
               str(a.height), "--threads", "1", "--seed", str(s), "--ref", a.ref] + opts.split()
        out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.strip().splitlines()[-1]
        kv = dict(x.split("=", 1) for x in out.split()[2:])
        cpu = float(kv["render_cpu"]) + float(kv["guide_cpu"])
        per.append((float(kv["relMSE_drop"]), cpu, float(kv["guide_cpu"])))
    rows.append((label, method, per))
    sys.stderr.write(f"{label}: done\n")
print(f"{a.scene}, {a.spp} spp, height {a.height}, seeds {a.seeds}, 1 thread; efficiency = relMSE_drop x CPU s")
print("| variant | method | relMSE_drop | CPU s (guide) | efficiency | vs first (range) |")
print("|---|---|---|---|---|---|")
base = rows[0][2]
for label, method, per in rows:
    e = [r * c for r, c, _ in per]
    ratios = [ei / (b[0] * b[1]) for ei, b in zip(e, base)]
    g = math.exp(sum(math.log(x) for x in ratios) / len(ratios))
    n = len(per)
    print(f"| {label} | {method} | {sum(r for r,_,_ in per)/n:.4g} | {sum(c for _,c,_ in per)/n:.2f} "
          f"({sum(g_ for _,_,g_ in per)/n:.2f}) | {sum(e)/n:.4g} | {g:.2f} ({min(ratios):.2f}-{max(ratios):.2f}) |")
