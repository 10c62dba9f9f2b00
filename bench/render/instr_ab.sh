#!/bin/sh
# Instructions per camera sample of `iris render` for two builds of iris
# (valgrind's cachegrind without cache simulation, one thread): the count at
# SPP_HI minus the count at SPP_LO, divided by the extra samples, so that setup
# (import, BVH, textures) cancels. Unlike CPU seconds it does not move with the
# machine's load, so a 2% difference is visible on a shared machine
# (docs/performance.md, "Normal maps: the fold's cost").
# usage: bench/render/instr_ab.sh IRIS_A IRIS_B SCENE METHOD [SPP_LO [SPP_HI [WIDTH HEIGHT]]]
# Options for one side only go in ARGS_A / ARGS_B (e.g. the same build twice,
# ARGS_B='--refine 0').
# prints: SCENE METHOD: A <instr/sample> B <instr/sample> B/A <ratio>
set -eu
A=$1; B=$2; SCENE=$3; METHOD=$4; LO=${5:-2}; HI=${6:-6}; W=${7:-40}; H=${8:-40}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
count() { # binary spp extra-args -> instructions of the whole run
  # shellcheck disable=SC2086
  valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file="$OUT/cg" "$1" render "$SCENE" \
    --width "$W" --height "$H" --spp "$2" --threads 1 --quiet --method "$METHOD" --seed 1 \
    -o "$OUT/img.exr" $3 > /dev/null 2>&1
  awk '/^summary:/ {print $2}' "$OUT/cg"
}
per_sample() {
  lo=$(count "$1" "$LO" "$2"); hi=$(count "$1" "$HI" "$2")
  echo "$lo $hi $W $H $LO $HI" | awk '{printf "%.0f", ($2 - $1) / ($3 * $4 * ($6 - $5))}'
}
a=$(per_sample "$A" "${ARGS_A:-}"); b=$(per_sample "$B" "${ARGS_B:-}")
echo "$SCENE $METHOD: A $a B $b B/A $(echo "$a $b" | awk '{printf "%.4f", $2 / $1}')"
