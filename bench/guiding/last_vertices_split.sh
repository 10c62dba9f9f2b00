#!/bin/sh
# Where a two-room scene's light and variance come from, by the last vertices
# of the paths that collect it (docs/guiding.md, "What limits the door scene":
# what a bidirectional connection could take over). Builds a scratch copy of
# HEAD with last_vertices_split.patch (trace_path sums each image sample's
# light by category and prints the shares at exit; room B is x > 0, as in the
# door scenes, and a point on the divider, x = 0, belongs to the room it is
# seen from), renders each scene on one thread and prints the XS lines:
#   cat 0: collected at a vertex in room A
#   cat 1: at a room-B vertex whose path came from room A (..., x_A, y_B, light):
#          what connecting x to a light subpath's first hit would estimate
#   cat 2: at a room-B vertex after two or more in room B
#   the cross terms 2E[XiXj] and the variance of a sample with cat 1 replaced
#   by its mean (the most such a connection could remove).
# The patch is against the commit that added it; on a later HEAD that no
# longer takes it, apply it to that commit (git worktree add DIR COMMIT).
# usage: bench/guiding/last_vertices_split.sh [METHOD [SPP [SEED [SCENE...]]]]
#   e.g. bench/guiding/last_vertices_split.sh guided-nee 64 1 door door-shielded
set -eu
M=${1:-guided-nee}; SPP=${2:-64}; SEED=${3:-1}
if [ $# -ge 3 ]; then shift 3; else shift $#; fi
SCENES=${*:-door door-shielded}
REPO=$(cd "$(dirname "$0")/../.." && pwd)
# shellcheck source=bench/guiding/scratch_patch.sh
. "$REPO/bench/guiding/scratch_patch.sh"
scratch_build last_vertices_split.patch
for sc in $SCENES; do
  echo "== $sc ($M, $SPP spp, 96 x 72, seed $SEED)"
  "$SCRATCH/build/tools/iris" render "$sc" --method "$M" --spp "$SPP" --width 96 --height 72 --seed "$SEED" \
    --threads 1 --quiet -o "$W/img.exr" 2>&1 | grep '^XS' | grep -v 'cat 3'
done
