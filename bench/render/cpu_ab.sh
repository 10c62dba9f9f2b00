#!/bin/sh
# CPU seconds (user + sys) of `iris render` for two builds of iris, the runs
# alternating A, B, A, B, ... and the fastest of each kept, so that the
# machine's drift between runs cancels as far as it can (docs/rendering.md,
# "Environment maps", Cost; docs/guiding.md, cache_res; docs/benchmarks.md).
# usage: bench/render/cpu_ab.sh IRIS_A IRIS_B SCENE METHOD [SPP [REPS [WIDTH HEIGHT]]]
# (env ARGS_A / ARGS_B: more `iris render` options for A / B, e.g. the same
# build twice with ARGS_B="--light-sampler learned")
# prints: SCENE METHOD SPP: A <s> B <s> B/A <ratio>
set -eu
A=$1; B=$2; SCENE=$3; METHOD=$4; SPP=${5:-128}; REPS=${6:-3}; W=${7:-144}; H=${8:-96}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
best_a=""; best_b=""
for r in $(seq "$REPS"); do
  for v in a b; do
    bin=$A; extra=${ARGS_A:-}
    [ "$v" = b ] && bin=$B && extra=${ARGS_B:-}
    # shellcheck disable=SC2086 # extra holds several options
    /usr/bin/time -o "$OUT/t" -f "%U %S" "$bin" render "$SCENE" --width "$W" --height "$H" --spp "$SPP" \
      --method "$METHOD" --threads 2 --quiet -o "$OUT/img.exr" $extra > /dev/null
    t=$(awk '{print $1 + $2}' "$OUT/t")
    if [ "$v" = a ]; then
      best_a=$(echo "$t ${best_a:-$t}" | awk '{print ($1 < $2) ? $1 : $2}')
    else
      best_b=$(echo "$t ${best_b:-$t}" | awk '{print ($1 < $2) ? $1 : $2}')
    fi
  done
done
echo "$SCENE $METHOD $SPP: A $best_a B $best_b B/A $(echo "$best_a $best_b" | awk '{printf "%.3f", $2 / $1}')"
