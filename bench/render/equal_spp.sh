#!/bin/sh
# relMSE at equal samples per pixel: iris mis with each sampler and emitter
# sampling, and Blender Cycles rendering iris's export of the same scene, all
# against one reference EXR (e.g. the bench's cached auto reference).
# Usage: bench/render/equal_spp.sh SCENE REFERENCE.exr WIDTH HEIGHT "SPPS" [SEEDS] [BUILD]
#   e.g. bench/render/equal_spp.sh cornell-box ~/.cache/iris/bench/cornell-box-96x96-8192spp-*.exr 96 96 "256 1024" 2
# Prints the reference's own relMSE (its noise, contained in every value), then
# one line per (spp, variant): spp, variant, mean relMSE over the seeds, that
# mean minus the reference's own relMSE, and the per-seed values.
set -eu
scene=$1; ref=$2; w=$3; h=$4; spps=$5; seeds=${6:-2}; build=${7:-build}
iris=$build/tools/iris; relmse=$build/bench/render/relmse
blender=${IRIS_BLENDER:-blender}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
own=$("$relmse" --own "$ref")
echo "reference own relMSE $own"
"$iris" export "$scene" --to blender -o "$tmp/scene.py" --width "$w" --height "$h" --quiet
for spp in $spps; do
  for variant in "sobol solid-angle" "independent solid-angle" "sobol area" "independent area" cycles; do
    vals=""
    s=0
    while [ "$s" -lt "$seeds" ]; do
      if [ "$variant" = cycles ]; then
        "$blender" -b --factory-startup --python-exit-code 1 -P "$tmp/scene.py" -- --output "$tmp/img.exr" \
          --spp "$spp" --threads 2 --seed "$s" >"$tmp/blender.log" 2>&1 || { cat "$tmp/blender.log" >&2; exit 1; }
      else
        set -- $variant
        "$iris" render "$scene" --method mis --sampler "$1" --light-sampling "$2" --width "$w" --height "$h" \
          --spp "$spp" --seed "$s" --threads 2 -o "$tmp/img.exr" --quiet
      fi
      vals="$vals $("$relmse" "$tmp/img.exr" "$ref")"
      s=$((s + 1))
    done
    echo "$spp $(echo "$variant" | tr ' ' '/') $vals" | awk -v own="$own" '{s = 0; for (i = 3; i <= NF; i++) s += $i; m = s / (NF - 2); printf "%s %-24s %.4g  minus own %.4g  (", $1, $2, m, m - own; for (i = 3; i <= NF; i++) printf " %s", $i; print " )"}'
  done
done
