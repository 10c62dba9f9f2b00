#!/bin/sh
# Portals at equal wall time (docs/guiding.md, "Portals"): METHOD with and
# without --no-portals in one build, by bench/guiding/ab_builds.sh (setup
# counted, alternating, relMSE against REFDIR/ref_SCENE.exr made there when
# missing, geometric means net of the reference's own relMSE, the ratio).
# usage: bench/guiding/portal_ab.sh BUILD REFDIR "TIMES" "SEEDS" [METHOD [SCENE...]]
#   e.g. bench/guiding/portal_ab.sh build refs "4 16" "1 2 3 4" guided-nee door door-shielded
set -eu
B=$1; R=$2; TIMES=$3; SEEDS=$4
METHOD=${5:-guided-nee}
[ $# -ge 5 ] && shift 5 || shift $#
[ $# -eq 0 ] && set -- door
BASE_ARGS=--no-portals NEW_LABEL="with portals" BASE_LABEL="--no-portals" \
  exec "$(dirname "$0")/ab_builds.sh" "$B" "$B" "$R" "$TIMES" "$SEEDS" "$METHOD" "$@"
