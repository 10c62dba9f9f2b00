#!/bin/sh
# Connections to a light-vertex cache, measured (docs/guiding.md, "What
# limits the door scene": a prototype, not built). Builds a scratch copy of
# HEAD with vertex_cache_prototype.patch. Two regions: the sides of the plane
# x = 0, room A at x < 0 and a point on the plane in the room it is seen from
# (the door scenes), or with IRIS_VC_REGION=portal the plane of the portal
# most caches keep, room A the side of those caches. Per image sample index,
# IRIS_VC_N light paths (default 864) leave the emissive triangles, walk room
# B through Lambertian, flatly shaded surfaces and keep the vertex where they
# enter room A; a camera vertex whose path so far lies in room A connects to
# one of them if they are more than IRIS_VC_D apart (default 0.3 m), and the
# paths so made are left out of the camera estimator: a partition of path
# space, no MIS. IRIS_VC=3 turns it on, the camera's paths going on into room
# B with probability 0.1 once they are such a path (1: in full; 2: not at
# all, which loses the paths that come back to room A, a bias). Prints, per
# seed, guided-nee's relMSE against REFDIR/ref_SCENE.exr without and with it,
# at BUDGET: a number of samples per pixel, or "4s" for 4 s with the setup
# counted.
# usage: bench/guiding/vertex_cache_ab.sh REFDIR BUDGET "SEEDS" SCENE...
#   REFDIR holds 72-row references ref_SCENE.exr (96 wide for the door scenes,
#   108 for the rest), e.g.
#   `iris render door --method mis --sampler independent --spp 32768 --width 96
#   --height 72 --seed 999 -o REFDIR/ref_door.exr`
set -eu
REFDIR=$1; BUDGET=$2; SEEDS=$3
shift 3
REPO=$(cd "$(dirname "$0")/../.." && pwd)
# shellcheck source=bench/guiding/scratch_patch.sh
. "$REPO/bench/guiding/scratch_patch.sh"
scratch_build vertex_cache_prototype.patch
B=$SCRATCH/build
case "$BUDGET" in
  *s) budget="--time ${BUDGET%s} --time-total --adaptive off" ;;
  *) budget="--spp $BUDGET" ;;
esac
for sc in "$@"; do
  case "$sc" in door*) w=96 ;; *) w=108 ;; esac
  for s in $SEEDS; do
    for vc in 0 3; do
      # shellcheck disable=SC2086
      out=$(IRIS_VC=$vc "$B/tools/iris" render "$sc" --method guided-nee $budget --width "$w" --height 72 \
        --seed "$s" --threads 2 --json --quiet -o "$W/img.exr" 2> "$W/err")
      spp=$(echo "$out" | awk -F: '/"spp":/ { gsub(/[ ,\t]/, "", $2); print $2 }')
      rays=$(echo "$out" | awk -F: '/"rays":/ { gsub(/[ ,\t]/, "", $2); print $2 }')
      light=$(sed -n 's/.*light rays \([0-9]*\).*/\1/p' "$W/err")
      echo "$sc seed $s vertex cache $vc: relMSE $("$B/bench/render/relmse" "$W/img.exr" "$REFDIR/ref_$sc.exr")," \
        "spp $spp, rays $rays (+ ${light:-0} light-path rays)"
    done
  done
done
