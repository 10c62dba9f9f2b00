#!/bin/sh
# Adaptive sampling against fixed spp and against Cycles as Blender users run it
# (docs/benchmarks.md, "Adaptive sampling"): one `iris bench` run per scene with
# iris's default method fixed, @adaptive (relMSE allocation) and @freeze (Cycles'
# rule at 0.01), beside Cycles with adaptive sampling on (threshold 0.01, each
# budget its time limit) and Cycles at fixed spp, all at equal wall time.
# usage: bench/render/adaptive.sh BUILD_DIR OUT_DIR [TIMES [HEIGHT [SEEDS]]]
set -eu
B=$1
O=$2
TIMES=${3:-4,16}
H=${4:-96}
SEEDS=${5:-1}
IRIS=$B/tools/iris
mkdir -p "$O"
for scene in cornell-box veach-mis door sky-room env-spheres office; do
  echo "== $scene ($(cut -d' ' -f1-3 /proc/loadavg))"
  "$IRIS" bench "$scene" --methods auto,auto@adaptive,auto@freeze --times "$TIMES" --seeds "$SEEDS" \
    --height "$H" --reference auto --reference-spp 8192 --threads 2 --cycles --cycles-adaptive \
    --no-charts --quiet --out "$O/$scene"
  tail -n +2 "$O/$scene/table.md" | sed -n '/^###/,$p'
done
