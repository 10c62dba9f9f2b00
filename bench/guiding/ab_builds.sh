#!/bin/sh
# Two builds at equal wall time: NEW against BASE (another checkout's build
# directory), each an `iris render --time T --time-total --adaptive off` (setup counted) per
# seed and budget, alternating, relMSE (bench/render/relmse, the benchmarks'
# trimmed metric) against REFDIR/ref_SCENE.exr (made as bench/guiding/portal_ab.sh
# makes it when missing), 72 rows (door scenes 96 wide, the rest 108), 2
# threads. Prints per scene and budget each build's relMSE per seed, their
# geometric mean net of the reference's own relMSE, and the ratio BASE / NEW.
# NEW_ARGS / BASE_ARGS in the environment: extra `iris render` options of
# each side (NEW and BASE may then be one build: bench/guiding/portal_ab.sh).
# BUDGET=spp in the environment: TIMES are samples per pixel instead (`--spp`,
# error per sample: deterministic, free of the machine's speed); then also each
# build's rays per image sample (closest-hit and shadow rays of the whole
# render, the guide's training passes included, from `--json`) and the ratio
# of net relMSE x rays per sample, a per-unit-of-work measure free of the clock.
# NEW_METHOD / BASE_METHOD in the environment: each side's method instead of
# METHOD (e.g. one build's auto against its mis).
# usage: bench/guiding/ab_builds.sh NEW BASE REFDIR "TIMES" "SEEDS" [METHOD [SCENE...]]
#   e.g. git worktree add /tmp/base HEAD~1 && cmake -S /tmp/base -B /tmp/base/build -DCMAKE_BUILD_TYPE=Release &&
#        cmake --build /tmp/base/build --target iris relmse &&
#        bench/guiding/ab_builds.sh build /tmp/base/build refs "4 16" "1 2 3 4" auto door
set -eu
N=$1; B=$2; R=$3; TIMES=$4; SEEDS=$5
METHOD=${6:-auto}
[ $# -ge 6 ] && shift 6 || shift $#
SCENES=${*:-door}
mkdir -p "$R"
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for sc in $SCENES; do
  case $sc in door*|stress*) W=96 ;; *) W=108 ;; esac
  ref="$R/ref_$sc.exr"
  if [ ! -f "$ref" ]; then
    "$N/tools/iris" render "$sc" --method mis --sampler independent --spp "${REFSPP:-32768}" --width "$W" --height 72 \
      --seed 999 --threads 2 --variance --quiet -o "$ref"
  fi
  own=$("$N/bench/render/relmse" --own "$ref")
  echo "$sc (new ${NEW_METHOD:-$METHOD}, base ${BASE_METHOD:-$METHOD}): reference $ref, own relMSE $own"
  for t in $TIMES; do
    new=""; base=""; new_rays=""; base_rays=""
    for s in $SEEDS; do
      for v in new base; do
        if [ "$v" = new ]; then b=$N; extra=${NEW_ARGS:-}; m=${NEW_METHOD:-$METHOD}
        else b=$B; extra=${BASE_ARGS:-}; m=${BASE_METHOD:-$METHOD}; fi
        if [ "${BUDGET:-time}" = spp ]; then budget="--spp $t --json"; else budget="--time $t --time-total --adaptive off"; fi
        # shellcheck disable=SC2086
        "$b/tools/iris" render "$sc" --method "$m" $budget --width "$W" --height 72 --threads 2 \
          --seed "$s" $extra -o "$OUT/img.exr" > "$OUT/run.json" 2>/dev/null
        val=$("$N/bench/render/relmse" "$OUT/img.exr" "$ref")
        rays=$(awk -F: '/"rays":/ { r = $2 + 0 } /"samples":/ { n = $2 + 0 } END { if (n > 0) printf "%.4f", r / n; else print 0 }' \
          "$OUT/run.json" | tr -d ',')
        if [ "$v" = new ]; then new="$new $val"; new_rays="$new_rays $rays"; else base="$base $val"; base_rays="$base_rays $rays"; fi
      done
    done
    unit=s; [ "${BUDGET:-time}" = spp ] && unit=spp
    echo "$new|$base" | awk -v t="$t" -v unit="$unit" -v own="$own" -v nl="${NEW_LABEL:-new}" -v bl="${BASE_LABEL:-base}" -F'|' '
      function geo(s,   n, i, a, p) { n = split(s, a, " "); p = 0; for (i = 1; i <= n; i++) p += log(a[i]); return exp(p / n) }
      { g1 = geo($1); g0 = geo($2)
        printf "  %s %s %s:%s  geo %.4g (net %.4g)\n", t, unit, nl, $1, g1, g1 - own
        printf "  %s %s %s:%s  geo %.4g (net %.4g)\n", t, unit, bl, $2, g0, g0 - own
        printf "  %s %s gain (net): %.2fx\n", t, unit, (g0 - own) / (g1 - own) }'
    if [ "${BUDGET:-time}" = spp ]; then
      echo "$new|$base|$new_rays|$base_rays" | awk -v own="$own" -F'|' '
        function geo(s,   n, i, a, p) { n = split(s, a, " "); p = 0; for (i = 1; i <= n; i++) p += log(a[i]); return exp(p / n) }
        { r1 = geo($3); r0 = geo($4)
          printf "  rays per sample: new %.3f, base %.3f; per unit of work (net relMSE x rays): %.2fx\n",
                 r1, r0, ((geo($2) - own) * r0) / ((geo($1) - own) * r1) }'
    fi
  done
done
