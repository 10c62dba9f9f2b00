#!/bin/sh
# Light tracing into the camera on env-spheres, measured per sample
# (docs/guiding.md, "Open work": measured, not built). Builds a scratch copy
# of HEAD with light_trace_prototype.patch (a prototype for env-spheres only:
# per camera sample one light path from the sky map, aimed at the metal
# sphere of roughness 0.05, reflected by it and splatted into the camera from
# the surface it lands on; the path tracer leaves out exactly the paths
# camera -> x -> that sphere -> sky, which the light paths then carry; one
# thread, as the splats are summed without locks; IRIS_LT=1 turns it on) and
# prints, per seed, the relMSE of mis with and without it against REF and
# the render passes' seconds.
# usage: bench/guiding/light_trace_ab.sh REF SPP "SEEDS"
#   REF: a 108 x 72 env-spheres reference (e.g. iris bench's cached
#   ~/.cache/iris/bench/env-spheres-108x72-32768spp-*.exr)
set -eu
REF=$1; SPP=$2; SEEDS=$3
REPO=$(cd "$(dirname "$0")/../.." && pwd)
# shellcheck source=bench/guiding/scratch_patch.sh
. "$REPO/bench/guiding/scratch_patch.sh"
scratch_build light_trace_prototype.patch
B=$SCRATCH/build
for s in $SEEDS; do
  for lt in 0 1; do
    if [ "$lt" = 1 ]; then export IRIS_LT=1; else unset IRIS_LT; fi
    sec=$("$B/tools/iris" render env-spheres --method mis --spp "$SPP" --width 108 --height 72 --seed "$s" \
      --threads 1 --json --quiet -o "$W/img.exr" | awk -F: '/"seconds":/ { gsub(/[ ,\t]/, "", $2); print $2 }')
    echo "seed $s light tracing $lt: relMSE $("$B/bench/render/relmse" "$W/img.exr" "$REF"), render passes $sec s"
  done
done
