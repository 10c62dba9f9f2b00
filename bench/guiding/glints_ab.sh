#!/bin/sh
# Glints at equal wall time (docs/guiding.md, "Glints"; docs/benchmarks.md):
# mis, guided-nee without glints (--no-glints) and guided-nee with them (both
# --force-guiding: without glints the 30% rule would skip the guide), each
# an `iris render --time T` per seed and budget, relMSE (the benchmarks'
# trimmed metric, bench/render/relmse) against REFDIR/ref_SCENE.exr, made here
# when missing (guided-nee with glints, 8192 spp or $REFSPP, seed 999, with its variance:
# `relmse --own` says how converged it is), 108 x 72, 2 threads. Prints one
# line per method and budget: the relMSE per seed, their geometric mean, and
# the mean spp reached.
# usage: bench/guiding/glints_ab.sh BUILD REFDIR "TIMES" "SEEDS" [SCENE...]
#   e.g. bench/guiding/glints_ab.sh build refs "4 16" "1 2 3" env-spheres
set -eu
B=$1; R=$2; TIMES=$3; SEEDS=$4; shift 4
SCENES=${*:-env-spheres}
mkdir -p "$R"
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for sc in $SCENES; do
  ref="$R/ref_$sc.exr"
  if [ ! -f "$ref" ]; then
    "$B/tools/iris" render "$sc" --method guided-nee --spp "${REFSPP:-8192}" --width 108 --height 72 --seed 999 --threads 2 \
      --variance --quiet -o "$ref"
  fi
  echo "$sc: reference $ref, own relMSE $("$B/bench/render/relmse" --own "$ref")"
  for t in $TIMES; do
    for m in "mis|--method mis" "guided-nee --no-glints|--method guided-nee --force-guiding --no-glints" \
             "guided-nee (glints)|--method guided-nee --force-guiding"; do
      label=${m%%|*}; opts=${m#*|}
      vals=""; spps=""
      for s in $SEEDS; do
        # shellcheck disable=SC2086
        "$B/tools/iris" render "$sc" --time "$t" --time-total --adaptive off --width 108 --height 72 --threads 2 --seed "$s" $opts \
          -o "$OUT/img.exr" > /dev/null 2> "$OUT/log"
        vals="$vals $("$B/bench/render/relmse" "$OUT/img.exr" "$ref")"
        spps="$spps $(sed -n 's/.*, \([0-9]*\) spp.*/\1/p' "$OUT/log" | tail -1)"
      done
      geo=$(echo "$vals" | awk '{p = 1; for (i = 1; i <= NF; i++) p *= $i; printf "%.4g", exp(log(p) / NF)}')
      mspp=$(echo "$spps" | awk '{s = 0; for (i = 1; i <= NF; i++) s += $i; printf "%.0f", s / NF}')
      echo "  $t s $label:$vals  geo $geo  mean spp $mspp"
    done
  done
done
