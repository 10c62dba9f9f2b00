#!/bin/sh
# Portals at equal wall time (docs/guiding.md, "Portals"): METHOD with and
# without --no-portals, each an `iris render --time T --time-total` (setup
# counted) per seed and budget, alternating, relMSE (the benchmarks' trimmed
# metric, bench/render/relmse) against REFDIR/ref_SCENE.exr, made here when
# missing (mis, 32768 spp or $REFSPP, seed 999, independent sampler, with its
# variance), 72 rows (door scenes 96 wide, the rest 108), 2 threads. Prints
# per scene, budget and variant the relMSE per seed, their geometric mean and
# that mean less the reference's own relMSE (relmse --own), and the ratio.
# usage: bench/guiding/portal_ab.sh BUILD REFDIR "TIMES" "SEEDS" [METHOD [SCENE...]]
#   e.g. bench/guiding/portal_ab.sh build refs "4 16" "1 2 3 4" guided-nee door door-shielded
set -eu
B=$1; R=$2; TIMES=$3; SEEDS=$4
METHOD=${5:-guided-nee}
[ $# -ge 5 ] && shift 5 || shift $#
SCENES=${*:-door}
mkdir -p "$R"
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for sc in $SCENES; do
  case $sc in door*) W=96 ;; *) W=108 ;; esac
  ref="$R/ref_$sc.exr"
  if [ ! -f "$ref" ]; then
    "$B/tools/iris" render "$sc" --method mis --sampler independent --spp "${REFSPP:-32768}" --width "$W" --height 72 \
      --seed 999 --threads 2 --variance --quiet -o "$ref"
  fi
  own=$("$B/bench/render/relmse" --own "$ref")
  echo "$sc ($METHOD): reference $ref, own relMSE $own"
  for t in $TIMES; do
    on=""; off=""
    for s in $SEEDS; do
      for v in on off; do
        extra=""
        [ "$v" = off ] && extra="--no-portals"
        # shellcheck disable=SC2086
        "$B/tools/iris" render "$sc" --method "$METHOD" --time "$t" --time-total --width "$W" --height 72 --threads 2 \
          --seed "$s" $extra -o "$OUT/img.exr" > /dev/null 2>&1
        val=$("$B/bench/render/relmse" "$OUT/img.exr" "$ref")
        if [ "$v" = on ]; then on="$on $val"; else off="$off $val"; fi
      done
    done
    echo "$on|$off" | awk -v t="$t" -v own="$own" -F'|' '
      function geo(s,   n, i, a, p) { n = split(s, a, " "); p = 0; for (i = 1; i <= n; i++) p += log(a[i]); return exp(p / n) }
      { g1 = geo($1); g0 = geo($2)
        printf "  %s s with portals:%s  geo %.4g (net %.4g)\n", t, $1, g1, g1 - own
        printf "  %s s --no-portals:%s  geo %.4g (net %.4g)\n", t, $2, g0, g0 - own
        printf "  %s s gain (net): %.2fx\n", t, (g0 - own) / (g1 - own) }'
  done
done
