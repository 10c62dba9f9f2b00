#!/bin/sh
# `auto` against mis at equal wall time, setup included, for two builds
# (docs/guiding.md, "--method auto"; docs/benchmarks.md): per build one
# `iris bench SCENE --methods mis,auto` (which alternates the methods per
# seed, so that the machine's drift hits both alike), 108 x 72 or HEIGHT, 2
# threads, against the bench's cached auto reference (mis, 4096 spp or
# $REFSPP). Prints per build and scene the geometric mean relMSE of each
# method over the seeds, the mean spp, and auto's efficiency against mis
# (relMSE_mis / relMSE_auto: 0.9 = 10% worse).
# usage: bench/guiding/auto_ab.sh BUILD_A BUILD_B OUT TIME SEEDS [SCENE...]
#   e.g. bench/guiding/auto_ab.sh /tmp/base/build build out 4 6 office corridor-rooms
set -eu
A=$1; B=$2; O=$3; T=$4; S=$5; shift 5
SCENES=${*:-office corridor-rooms}
H=${HEIGHT:-72}
mkdir -p "$O"
for sc in $SCENES; do
  for x in A B; do
    eval "bin=\$$x"
    [ -f "$O/$x-$sc/results.csv" ] ||
      "$bin/tools/iris" bench "$sc" --methods mis,auto --times "$T" --seeds "$S" --height "$H" --reference auto \
        --reference-spp "${REFSPP:-4096}" --threads 2 --no-charts --out "$O/$x-$sc" > "$O/$x-$sc.log" 2>&1 ||
      { echo "$sc: iris bench ($x) failed (see $O/$x-$sc.log)"; continue; }
  done
done
/usr/bin/python3 - "$O" $SCENES <<'PY'
import csv, math, os, sys
out, scenes = sys.argv[1], sys.argv[2:]
print("| scene | build | mis relMSE (spp) | auto relMSE (spp) | auto chose | auto / mis |")
print("|---|---|---|---|---|---|")
for sc in scenes:
    for x in ("A", "B"):
        f = os.path.join(out, f"{x}-{sc}", "results.csv")
        if not os.path.exists(f): continue
        rows = list(csv.DictReader(open(f)))
        g, n = {}, {}
        for m in ("mis", "auto"):
            r = [row for row in rows if row["method"] == m]
            g[m] = math.exp(sum(math.log(float(row["relmse"])) for row in r) / len(r))
            n[m] = sum(float(row["spp"]) for row in r) / len(r)
        chose = "/".join(sorted({row["resolved"] for row in rows if row["method"] == "auto"}))
        print(f"| {sc} | {x} | {g['mis']:.4g} ({n['mis']:.0f}) | {g['auto']:.4g} ({n['auto']:.0f}) | {chose} | {g['mis'] / g['auto']:.3f} |")
PY
