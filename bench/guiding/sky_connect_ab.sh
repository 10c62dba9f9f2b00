#!/bin/sh
# Connections to light vertices that the sky lit through sky-room's window,
# measured (docs/guiding.md, "Connections with the sky through a window": the
# prototype, since built with the window sky visibility finds). Builds a
# scratch copy of f494046 (the commit before the windows) with
# sky_connect_prototype.patch. IRIS_SKYVC="ox oy oz ux uy uz vx vy vz" names
# the window (corner o, edges u and v, normal u x v pointing out of the room).
# Per image sample index, light paths leave the window (a point uniform on it,
# a direction from the map's importance sampling, seen through it, its
# radiance x cos x area / pdf) and keep the first vertex z they hit in the
# room (a Lambertian reflector with flat shading). A camera vertex connects to
# one z of its sample index's pool, drawn uniformly, if they are more than
# IRIS_SKYVC_MIND x the window's longer side apart (default 0.15); the camera
# leaves out, at a vertex x_k (k >= 2, x_{k-1} not delta, x_k plain, |x_{k-1}
# - x_k| above that distance), the map's light that reaches x_k through the
# window (its light samples crossing the window, not traced, and its escapes
# through it): a partition of path space, no MIS. Knobs: IRIS_SKYVC_RR=c
# (trace a connection with probability min(1, value / (c x the pixel
# estimate)), weighted back), IRIS_SKYVC_MAXB=b (connect only from the first b
# camera vertices), IRIS_SKYVC_M=m (m candidates, one resampled by its
# unshadowed value), IRIS_SKYVC_GREEDY=1 (light paths walk on through the room
# and every vertex is kept; the first split of a path is the connections', the
# camera going on past it with probability IRIS_SKYVC_Q, default 0.1). Also in
# the patch: IRIS_DBG_PICK=1 prints per depth how many guided vertices found
# tied caches, and IRIS_DBG_SECOND=n moves every n-th camera cache one
# diffuse bounce further (caches on the walls the camera does not see).
# Prints per-sample A/Bs (64 spp, seeds 1-4, against `--connect off` of the
# same build) and equal-time ones (4 and 16 s with the setup, seeds 1-3).
# usage: bench/guiding/sky_connect_ab.sh REFDIR
#   REFDIR/ref_sky-room.exr: `iris render sky-room --method mis --sampler
#   independent --spp 32768 --width 108 --height 72 --seed 999 -o REFDIR/ref_sky-room.exr`
set -eu
REFDIR=$1
REPO=$(cd "$(dirname "$0")/../.." && pwd)
# shellcheck source=bench/guiding/scratch_patch.sh
. "$REPO/bench/guiding/scratch_patch.sh"
SCRATCH_BASE=f494046 scratch_build sky_connect_prototype.patch # the patch's commit
B=$SCRATCH/build
export IRIS_SKYVC="2 1 -0.6 0 1 0 0 0 1.2"
ab() { # LABEL BUDGET SEEDS [VAR=VALUE...]
  label=$1; budget=$2; seeds=$3
  shift 3
  echo "== $label"
  if [ "$budget" = spp ]; then
    env "$@" BUDGET=spp BASE_ARGS='--connect off' "$REPO/bench/guiding/ab_builds.sh" "$B" "$B" "$REFDIR" 64 "$seeds" \
      guided-nee sky-room | tail -n 2
  else
    env "$@" BASE_ARGS='--connect off' "$REPO/bench/guiding/ab_builds.sh" "$B" "$B" "$REFDIR" "$budget" "$seeds" \
      guided-nee sky-room | grep gain
  fi
}
ab "shortest connection 0.15 x 1.2 m" spp "1 2 3 4" IRIS_SKYVC_MIND=0.15
ab "1.2 m" spp "1 2 3 4" IRIS_SKYVC_MIND=1.0
ab "0.6 m, roulette 0.5" spp "1 2 3 4" IRIS_SKYVC_MIND=0.5 IRIS_SKYVC_RR=0.5
ab "1.2 m, roulette 0.5" spp "1 2 3 4" IRIS_SKYVC_MIND=1.0 IRIS_SKYVC_RR=0.5
ab "1.8 m, roulette 0.5" spp "1 2 3 4" IRIS_SKYVC_MIND=1.5 IRIS_SKYVC_RR=0.5
ab "1.2 m, roulette 1" spp "1 2 3 4" IRIS_SKYVC_MIND=1.0 IRIS_SKYVC_RR=1
ab "1.2 m, first camera vertex only" spp "1 2 3 4" IRIS_SKYVC_MIND=1.0 IRIS_SKYVC_MAXB=1
ab "1.2 m, first two camera vertices" spp "1 2 3 4" IRIS_SKYVC_MIND=1.0 IRIS_SKYVC_MAXB=2
ab "1.2 m, roulette 0.5, 4 candidates" spp "1 2 3 4" IRIS_SKYVC_MIND=1.0 IRIS_SKYVC_RR=0.5 IRIS_SKYVC_M=4
ab "1.2 m, roulette 0.5, 16 candidates" spp "1 2 3 4" IRIS_SKYVC_MIND=1.0 IRIS_SKYVC_RR=0.5 IRIS_SKYVC_M=16
ab "1.2 m, greedy (camera on with 0.1)" spp "1 2 3 4" IRIS_SKYVC_MIND=1.0 IRIS_SKYVC_GREEDY=1
ab "1.2 m, greedy (camera on with 1)" spp "1 2 3 4" IRIS_SKYVC_MIND=1.0 IRIS_SKYVC_GREEDY=1 IRIS_SKYVC_Q=1
ab "1.2 m, roulette 0.5, equal time" "4 16" "1 2 3" IRIS_SKYVC_MIND=1.0 IRIS_SKYVC_RR=0.5
for n in 0 2 3; do
  echo "== camera caches: every ${n}th one bounce further (0: none); guided vertices with / without tied caches"
  for s in 1 2 3 4; do
    env IRIS_DBG_PICK=1 IRIS_DBG_SECOND=$n "$B/tools/iris" render sky-room --method guided-nee --spp 64 --width 108 \
      --height 72 --seed "$s" --threads 2 --connect off --quiet -o "$W/img.exr" 2> "$W/err" || true
    [ "$s" = 1 ] && grep '^depth [0-3]' "$W/err"
    echo "  seed $s relMSE $("$B/bench/render/relmse" "$W/img.exr" "$REFDIR/ref_sky-room.exr")"
  done
done
