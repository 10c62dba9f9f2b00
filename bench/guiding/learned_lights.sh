#!/bin/sh
# Learned light selection (--light-sampler learned) against the light tree, at
# equal wall-clock time beside Cycles 3.4 as Blender users run it (adaptive
# sampling, threshold 0.01), one run per scene (docs/benchmarks.md,
# "Learned light selection").
#
#   bench/guiding/learned_lights.sh BUILD_DIR OUT_DIR [TIMES] [SCENES]
#
# References: iris mis, 1024 spp, independent sampler, seed 999, rendered once
# into OUT_DIR/ref-SCENE.exr (kept between runs). Then, per scene, one
# `iris bench` run of the methods with and without learned selection and the
# cycles-adaptive rows (Blender must be installed).
set -e
B=${1:?usage: learned_lights.sh BUILD_DIR OUT_DIR [TIMES] [SCENES]}
OUT=${2:?usage: learned_lights.sh BUILD_DIR OUT_DIR [TIMES] [SCENES]}
TIMES=${3:-2,4,8}
SCENES=${4:-"office corridor-rooms door veach-mis"}
mkdir -p "$OUT"
for s in $SCENES; do
  ref="$OUT/ref-$s.exr"
  [ -f "$ref" ] || "$B/tools/iris" render "$s" --method mis --spp 1024 --height 96 --threads 2 --seed 999 \
    --sampler independent -o "$ref" --quiet
  "$B/tools/iris" bench "$s" --methods mis,mis@learned,guided-nee,guided-nee@learned,auto,auto@learned \
    --times "$TIMES" --seeds 1 --reference "$ref" --threads 2 --cycles-adaptive --out "$OUT/$s"
done
