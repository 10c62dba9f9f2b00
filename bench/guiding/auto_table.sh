#!/bin/sh
# Issue 33's `auto` table (docs/guiding.md, "--method auto"): every built-in
# scene with lights rendered with mis, guided-nee and auto at equal wall time
# (setup included), against an auto reference (iris mis, REFSPP samples,
# cached), SEEDS seeds; prints per scene the mean relMSE of each, auto's
# choice and auto's efficiency against the better single method
# (relMSE_best / relMSE_auto: 1 = as good, 0.9 = 10% worse).
# usage: bench/guiding/auto_table.sh BUILD OUT [TIME] [SEEDS] [HEIGHT] [REFSPP] [SCENE...]
set -eu
B=$1; O=$2; T=${3:-2}; S=${4:-2}; H=${5:-72}; R=${6:-4096}
shift 2; [ $# -gt 0 ] && shift; [ $# -gt 0 ] && shift; [ $# -gt 0 ] && shift; [ $# -gt 0 ] && shift
SCENES=${*:-cornell-box veach-mis door door-shielded furnace-diffuse furnace-glossy inside-sphere stress-gap \
stress-veach-lights stress-caustic stress-thin-walls stress-small-dim stress-closed-box stress-firefly \
stress-glossy-room env-objects env-spheres sky-room sky-room-glazed sky-room-pane lamp-shade office corridor-rooms}
mkdir -p "$O"
for sc in $SCENES; do
  [ -f "$O/$sc/results.csv" ] && continue
  "$B/tools/iris" bench "$sc" --methods mis,guided-nee,auto --times "$T" --seeds "$S" --height "$H" \
    --reference auto --reference-spp "$R" --threads 2 --no-charts --out "$O/$sc" > "$O/$sc.log" 2>&1 ||
    { echo "$sc: iris bench failed (see $O/$sc.log)"; continue; }
done
/usr/bin/python3 - "$O" $SCENES <<'PY'
import csv, sys, os, statistics
out, scenes = sys.argv[1], sys.argv[2:]
print("| scene | mis relMSE | guided-nee relMSE | auto relMSE | auto chose | auto / best |")
print("|---|---|---|---|---|---|")
worst = []
for sc in scenes:
    f = os.path.join(out, sc, "results.csv")
    if not os.path.exists(f): continue
    rows = list(csv.DictReader(open(f)))
    m = {k: statistics.mean(float(r["relmse"]) for r in rows if r["method"] == k) for k in ("mis", "guided-nee", "auto")}
    chose = sorted({r["resolved"] for r in rows if r["method"] == "auto"})
    best = min(m["mis"], m["guided-nee"])
    ratio = best / m["auto"] if m["auto"] > 0 else float("nan")
    worst.append((ratio, sc))
    print(f"| {sc} | {m['mis']:.4g} | {m['guided-nee']:.4g} | {m['auto']:.4g} | {'/'.join(chose)} | {ratio:.2f} |")
worst.sort()
print(f"\nauto's efficiency against the better method: worst {worst[0][0]:.2f} ({worst[0][1]}), "
      f"{sum(1 for r, _ in worst if r >= 0.9)} of {len(worst)} scenes within 10%")
PY
