#!/bin/sh
# Where iris stands against Cycles (docs/benchmarks.md): per scene, one
# `iris bench` run beside Cycles 3.4 as Blender users run it (adaptive
# sampling, threshold 0.01, each budget as Cycles' time limit) and one beside
# Cycles at the spp of each budget's iris mis run (--cycles), equal wall time
# with iris's setup included; then tables of times to target and iris's
# speed-up against each Cycles row (time(Cycles) / time(iris method)), as
# measured and net of the reference's own relMSE (docs/benchmarks.md).
# usage: bench/cycles_stand.sh BUILD OUT "TIMES" HEIGHT METHODS REF SCENE...
#   TIMES e.g. "4,16"; METHODS e.g. mis,auto; REF: auto (a cached iris mis
#   reference of 4096 spp), auto:N (of N spp) or a directory holding ref_SCENE.exr.
# Runs that already have results in OUT are kept (delete them to rerun).
# SEEDS=N in the environment: N seeds per row (default 1), iris's and Cycles'
# alike; the times to target are then those of the seeds' mean relMSE.
set -eu
B=$1; O=$2; T=$3; H=$4; M=$5; R=$6
S=${SEEDS:-1}
shift 6
mkdir -p "$O"
for sc in "$@"; do
  case "$R" in
    auto) ref="--reference auto --reference-spp 4096" ;;
    auto:*) ref="--reference auto --reference-spp ${R#auto:}" ;;
    *) ref="--reference $R/ref_$sc.exr" ;;
  esac
  for mode in cycles-adaptive cycles; do
    d="$O/$sc-$mode"
    [ -f "$d/results.csv" ] && continue
    # shellcheck disable=SC2086
    "$B/tools/iris" bench "$sc" --methods "$M" --times "$T" --seeds "$S" --height "$H" $ref --threads 2 \
      "--$mode" --no-charts --out "$d" > "$O/$sc-$mode.log" 2>&1 ||
      { echo "$sc ($mode): iris bench failed (see $O/$sc-$mode.log)"; continue; }
  done
done
/usr/bin/python3 - "$O" "$M" "$@" <<'PY'
import os, re, sys
out, methods, scenes = sys.argv[1], sys.argv[2].split(","), sys.argv[3:]

def times(path):
    """(gross, net): method -> (seconds to target, extrapolated?) from a bench
    table.md's first table and its table net of the reference's own relMSE"""
    got, which = ({}, {}), 0
    if not os.path.exists(path):
        return got
    for line in open(path):
        if line.startswith("### "):
            which = 1 if " net of the reference's own relMSE " in line else 0
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 4 or cells[0] in ("method", "---"):
            continue
        m = re.match(r"(~?)([0-9.]+) s", cells[-2])
        if m:
            got[which][cells[0].split(" (")[0]] = (float(m.group(2)), m.group(1) == "~")
    return got

for which, title in ((0, "measured against the reference"),
                     (1, "net of the reference's own relMSE (an estimate of the error against the truth)")):
    print(f"\nTimes to target, {title}:\n")
    print("| scene | " + " | ".join(f"{m}: time to target" for m in methods) +
          " | Cycles adaptive | Cycles fixed spp | " +
          " | ".join(f"{m} vs Cycles adaptive / fixed" for m in methods) + " |")
    print("|---|" + "---:|" * (2 * len(methods) + 2))
    for sc in scenes:
        a = times(os.path.join(out, f"{sc}-cycles-adaptive", "table.md"))[which]
        f = times(os.path.join(out, f"{sc}-cycles", "table.md"))[which]
        fmt = lambda v: ("~" if v[1] else "") + f"{v[0]:.2f} s" if v else "-"
        cyc_a, cyc_f = a.get("cycles-adaptive"), f.get("cycles")
        row = [sc] + [fmt(a.get(m)) for m in methods] + [fmt(cyc_a), fmt(cyc_f)]
        for m in methods:
            ia, iff = a.get(m), f.get(m)
            ra = f"{cyc_a[0] / ia[0]:.1f}x" if ia and cyc_a else "-"
            rf = f"{cyc_f[0] / iff[0]:.1f}x" if iff and cyc_f else "-"
            row.append(f"{ra} / {rf}")
        print("| " + " | ".join(row) + " |")
PY
