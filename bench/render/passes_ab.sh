#!/bin/sh
# Render-pass seconds of two iris binaries (or one binary with two option
# sets), the runs alternating A, B, A, B, ... on one thread at a fixed spp:
# the `seconds` of `iris render --json` (the image passes, without the setup,
# so that a change of the per-sample cost is not hidden by the photons and
# the guide's build). Prints each side's minimum and median and the median of
# the per-pair ratios B/A, which cancels most of the machine's drift; on the
# 2-core development machine single runs move by up to 30%, and paired medians
# of 10-16 pairs by 1-4% between runs of one comparison (the door's
# unchanged code path: 1.007; sky-room with the same instructions in another
# order: 1.014-1.037), so a difference under ~4% needs several runs.
# usage: bench/render/passes_ab.sh IRIS_A IRIS_B SCENE METHOD [SPP [PAIRS [WIDTH HEIGHT]]]
# (env ARGS_A / ARGS_B: more `iris render` options for A / B)
# e.g. bench/render/passes_ab.sh /tmp/base/build/tools/iris build/tools/iris sky-room guided-nee 48 10
set -eu
A=$1; B=$2; SCENE=$3; METHOD=$4; SPP=${5:-48}; PAIRS=${6:-10}; W=${7:-108}; H=${8:-72}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for r in $(seq "$PAIRS"); do
  for v in a b; do
    bin=$A; extra=${ARGS_A:-}
    [ "$v" = b ] && bin=$B && extra=${ARGS_B:-}
    # shellcheck disable=SC2086 # extra holds several options
    "$bin" render "$SCENE" --method "$METHOD" --spp "$SPP" --width "$W" --height "$H" --seed 1 --threads 1 \
      --json --quiet -o "$OUT/img.exr" $extra > "$OUT/run.json"
    s=$(awk -F: '/"seconds":/ { gsub(/[ ,\t]/, "", $2); print $2 }' "$OUT/run.json")
    echo "$v $s" >> "$OUT/times"
  done
done
awk -v scene="$SCENE" -v method="$METHOD" -v spp="$SPP" '
  function median(a, n,   i, j, t) {
    for (i = 2; i <= n; i++) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
    return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
  }
  $1 == "a" { na++; ta[na] = $2; sa[na] = $2 }
  $1 == "b" { nb++; tb[nb] = $2; r[nb] = $2 / sa[nb] }
  END {
    ma = median(ta, na); mb = median(tb, nb); mr = median(r, nb)
    mina = ta[1]; minb = tb[1]
    printf "%s %s %s spp, %d pairs: A min %.3f med %.3f s, B min %.3f med %.3f s, B/A min %.3f med %.3f, paired median %.3f\n",
           scene, method, spp, nb, mina, ma, minb, mb, minb / mina, mb / ma, mr
  }' "$OUT/times"
