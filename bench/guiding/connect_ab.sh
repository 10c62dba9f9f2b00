#!/bin/sh
# The door's one-bounce light-subpath connection, measured per sample
# (docs/guiding.md, "What limits the door scene": measured, not built).
# Builds a scratch copy of HEAD with connect_prototype.patch (a prototype
# for the door scenes only, x > 0 being room B: per camera path one light
# subpath, a point on the lamp and its first hit y in room B, connected to
# every room-A camera vertex up to bounce MAXB, with the power heuristic over
# the three strategies that make a path ..., x_A, y_B, lamp: the connection,
# light sampling at y and the guided direction at y; IRIS_CONNECT=1 turns
# it on) and compares it with the same build without (bench/guiding/ab_builds.sh,
# BUDGET=spp: relMSE per sample and per ray).
# usage: bench/guiding/connect_ab.sh REFDIR "SPP" "SEEDS" [MAXB [SCENE...]]
#   REFDIR holds ref_SCENE.exr (ab_builds.sh makes it when missing)
#   e.g. bench/guiding/connect_ab.sh refs "64 256" "1 2 3 4" 1000 door door-shielded
set -eu
R=$1; SPP=$2; SEEDS=$3; MAXB=${4:-1000}
if [ $# -ge 4 ]; then shift 4; else shift $#; fi
SCENES=${*:-door door-shielded}
REPO=$(cd "$(dirname "$0")/../.." && pwd)
# shellcheck source=bench/guiding/scratch_patch.sh
. "$REPO/bench/guiding/scratch_patch.sh"
scratch_build connect_prototype.patch
mkdir -p "$W/on/tools" "$W/on/bench/render"
printf '#!/bin/sh\nIRIS_CONNECT=1 IRIS_CONNECT_MAXB=%s exec %s "$@"\n' "$MAXB" "$SCRATCH/build/tools/iris" > "$W/on/tools/iris"
chmod +x "$W/on/tools/iris"
ln -s "$SCRATCH/build/bench/render/relmse" "$W/on/bench/render/relmse"
# shellcheck disable=SC2086 # SCENES is a list
BUDGET=spp "$REPO/bench/guiding/ab_builds.sh" "$W/on" "$SCRATCH/build" "$R" "$SPP" "$SEEDS" guided-nee $SCENES
