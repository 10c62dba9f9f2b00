#!/bin/sh
# Cost per sample of an HDR environment map against a constant sky of the same
# mean radiance (docs/performance.md, "Environment maps"). For each scene and
# method the two worlds alternate, REPS times each, single-threaded (the
# render's path-tracing seconds are then CPU seconds), and the fastest run of
# each is kept; the ratio of the two within one invocation is the number
# reported, so machine load cancels as far as it can.
# Usage: bench/render/env_cost.sh [IRIS] [REPS] [MAP]   (MAP: the map env-objects and sky-room use)
set -eu
IRIS=${1:-build/tools/iris}
REPS=${2:-3}
MAP=${3:-$(cd "$(dirname "$0")/../.." && pwd)/../shared/assets/env/immenstadter_horn_1k.hdr}
# the map's solid-angle mean luminance (0.6072, the mean_luminance of renderer/envmap.c)
MEAN=0.6072
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
printf '%-12s %-6s %12s %12s %8s\n' scene method const_Ms/s map_Ms/s map/const
for scene in env-objects sky-room; do
  for method in mis bsdf; do
    best_c=0; best_m=0
    i=0
    while [ $i -lt "$REPS" ]; do
      for world in const map; do
        if [ $world = const ]; then flags="--env-color $MEAN,$MEAN,$MEAN"; else flags="--env $MAP"; fi
        # shellcheck disable=SC2086
        r=$("$IRIS" render $scene $flags --method $method --spp 16 --height 128 --threads 1 \
              --seed 7 -o "$OUT/x.exr" --json --quiet | /usr/bin/python3 -c \
              'import json,sys; print(json.load(sys.stdin)["samples_per_second"])')
        if [ $world = const ]; then
          best_c=$(/usr/bin/python3 -c "print(max($best_c, $r))")
        else
          best_m=$(/usr/bin/python3 -c "print(max($best_m, $r))")
        fi
      done
      i=$((i + 1))
    done
    /usr/bin/python3 -c "print('%-12s %-6s %12.4f %12.4f %8.3f' % ('$scene', '$method', $best_c / 1e6, $best_m / 1e6, $best_c / $best_m))"
  done
done
