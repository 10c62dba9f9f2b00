#!/bin/sh
# POV-Ray radiosity against iris (docs/export.md, "Indirect light: radiosity"):
# for each scene and --pov-radiosity level, the mean R of POV-Ray's image
# (single-threaded, +WT1, so that the radiosity cache is reproducible) and of
# iris's render, plus POV-Ray's CPU seconds. Whole images, emitter pixels
# included (POV-Ray samples pixel centres; see the docs for what that does).
# Usage: bench/export/pov_radiosity.sh BUILD_DIR [OUT_DIR]
set -eu
BUILD=${1:?build dir}; OUT=${2:-/tmp/iris-pov-radiosity}
IRIS="$BUILD/tools/iris"
mkdir -p "$OUT/home/.povray/3.7"
cp /etc/povray/3.7/povray.conf "$OUT/home/.povray/3.7/" 2>/dev/null || true
mean_r() { oiiotool "$1" --printstats | awk '/Stats Avg/ {print $3}'; }
run() { # scene w h spp levels...
  scene=$1; w=$2; h=$3; spp=$4; shift 4
  "$IRIS" render "$scene" -o "$OUT/$scene-iris.exr" --width "$w" --height "$h" --spp "$spp" -q
  "$IRIS" render "$scene" -o "$OUT/$scene-iris-d0.exr" --width "$w" --height "$h" --spp "$spp" --max-depth 0 -q
  line="$scene ${w}x$h: iris $(mean_r "$OUT/$scene-iris.exr") (direct only $(mean_r "$OUT/$scene-iris-d0.exr"))"
  for q in "$@"; do
    "$IRIS" export "$scene" --to pov -o "$OUT/$scene-$q.pov" --width "$w" --height "$h" --pov-radiosity "$q" -q
    t=$( { /usr/bin/time -f "%U" env HOME="$OUT/home" povray +I"$OUT/$scene-$q.pov" +O"$OUT/$scene-$q.exr" \
           +FE +W"$w" +H"$h" -D -V +WT1 2>&1 >/dev/null; } | tail -1)
    line="$line; $q $(mean_r "$OUT/$scene-$q.exr") (${t} s)"
  done
  echo "$line"
}
run cornell-box 128 128 512 off low medium high
run door 192 144 512 off low medium
run door-shielded 96 72 1024 off low medium
