#!/bin/sh
# Variance-aware guiding (Rath et al. 2020) measured per sample
# (docs/guiding.md, "What limits the door scene": measured, not built).
# Builds a scratch copy of HEAD with variance_aware.patch: training's path
# samples also splat (Li cos)^2 / q, and with IRIS_VA=1 each cache's trained
# table is sqrt(texel solid angle x that second moment) per texel (the
# density that minimises the variance of the guided direction alone when Li
# is itself a noisy estimate) instead of the mean Li cos, mixed with the
# photons' table as before. Prints, per seed, guided-nee's relMSE against
# REFDIR/ref_SCENE.exr with and without it and the rays traced.
# usage: bench/guiding/variance_aware_ab.sh REFDIR SPP "SEEDS" SCENE...
#   REFDIR holds 72-row references ref_SCENE.exr (96 wide for the door
#   scenes, 108 for the rest), e.g. `iris render door --method mis --sampler
#   independent --spp 32768 --width 96 --height 72 --seed 999 -o REFDIR/ref_door.exr`
set -eu
REFDIR=$1; SPP=$2; SEEDS=$3
shift 3
REPO=$(cd "$(dirname "$0")/../.." && pwd)
# shellcheck source=bench/guiding/scratch_patch.sh
. "$REPO/bench/guiding/scratch_patch.sh"
scratch_build variance_aware.patch
B=$SCRATCH/build
for sc in "$@"; do
  case "$sc" in door*) w=96 ;; *) w=108 ;; esac
  for s in $SEEDS; do
    for va in 0 1; do
      rays=$(IRIS_VA=$va "$B/tools/iris" render "$sc" --method guided-nee --spp "$SPP" --width "$w" --height 72 \
        --seed "$s" --threads 2 --json --quiet -o "$W/img.exr" | awk -F: '/"rays":/ { gsub(/[ ,\t]/, "", $2); print $2 }')
      echo "$sc seed $s variance-aware $va: relMSE $("$B/bench/render/relmse" "$W/img.exr" "$REFDIR/ref_$sc.exr"), rays $rays"
    done
  done
done
