#!/bin/sh
# Two builds of iris (or one with two option sets) timed against each other,
# the runs alternating A, B, A, B, ... so that the machine's drift between
# runs cancels as far as it can (docs/rendering.md, "Environment maps", Cost;
# docs/guiding.md, cache_res; docs/benchmarks.md).
# usage: bench/render/cpu_ab.sh IRIS_A IRIS_B SCENE METHOD [SPP [REPS [WIDTH HEIGHT]]]
# (env ARGS_A / ARGS_B: more `iris render` options for A / B, e.g. the same
# build twice with ARGS_B="--light-sampler learned")
# MEASURE (env) says what is timed:
#   cpu (default): CPU seconds (user + sys) of the whole `iris render` on 2
#     threads, the fastest of each side kept; prints
#     SCENE METHOD SPP: A <s> B <s> B/A <ratio>
#   passes: the render passes alone, one thread (`seconds` of `--json`: the
#     setup before them, photons and the guide's build, left out, so that a
#     change of the per-sample cost is not hidden by them); prints each side's
#     minimum and median and the median of the per-pair ratios B/A, which
#     cancels most of the drift. On the 2-core development machine single runs
#     move by up to 30% and paired medians of 10-16 pairs by 1-4% between runs
#     of one comparison (the door's unchanged code path: 1.007; sky-room with
#     the same instructions in another order: 1.014-1.037), so a difference
#     under ~4% needs several runs. bench/render/passes_ab.sh is this with
#     its own defaults.
set -eu
A=$1; B=$2; SCENE=$3; METHOD=$4; SPP=${5:-128}; REPS=${6:-3}; W=${7:-144}; H=${8:-96}
MEASURE=${MEASURE:-cpu}
case "$MEASURE" in
  cpu) threads=2; seed= ;;
  passes) threads=1; seed="--seed 1" ;;
  *) echo "cpu_ab.sh: MEASURE must be cpu or passes, not '$MEASURE'" >&2; exit 2 ;;
esac
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for _ in $(seq "$REPS"); do
  for v in a b; do
    bin=$A; extra=${ARGS_A:-}
    [ "$v" = b ] && bin=$B && extra=${ARGS_B:-}
    # shellcheck disable=SC2086 # extra holds several options, seed none or two words
    /usr/bin/time -o "$OUT/t" -f "%U %S" "$bin" render "$SCENE" --width "$W" --height "$H" --spp "$SPP" \
      --method "$METHOD" $seed --threads "$threads" --json --quiet -o "$OUT/img.exr" $extra > "$OUT/run.json"
    if [ "$MEASURE" = cpu ]; then
      t=$(awk '{print $1 + $2}' "$OUT/t")
    else
      t=$(awk -F: '/"seconds":/ { gsub(/[ ,\t]/, "", $2); print $2 }' "$OUT/run.json")
    fi
    echo "$v $t" >> "$OUT/times"
  done
done
awk -v scene="$SCENE" -v method="$METHOD" -v spp="$SPP" -v measure="$MEASURE" '
  function median(a, n,   i, j, t) {
    for (i = 2; i <= n; i++) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
    return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
  }
  $1 == "a" { na++; ta[na] = $2; sa[na] = $2; if (na == 1 || $2 < mina) mina = $2 }
  $1 == "b" { nb++; tb[nb] = $2; r[nb] = $2 / sa[nb]; if (nb == 1 || $2 < minb) minb = $2 }
  END {
    if (measure == "cpu") { printf "%s %s %s: A %s B %s B/A %.3f\n", scene, method, spp, mina, minb, minb / mina; exit }
    ma = median(ta, na); mb = median(tb, nb); mr = median(r, nb)
    printf "%s %s %s spp, %d pairs: A min %.3f med %.3f s, B min %.3f med %.3f s, B/A min %.3f med %.3f, paired median %.3f\n",
           scene, method, spp, nb, mina, ma, minb, mb, minb / mina, mb / ma, mr
  }' "$OUT/times"
