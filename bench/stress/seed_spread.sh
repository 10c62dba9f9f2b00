#!/bin/sh
# Mean image energy (R+G+B, averaged over pixels) of one scene over many
# seeds, per sampler: shows whether a method whose single low-spp images fail
# a z-test is biased (the mean over seeds misses the reference) or only
# heavy-tailed (single images are bimodal, their mean matches).
# Usage: bench/stress/seed_spread.sh SCENE SPP SEEDS [METHOD] [IRIS]
# Prints one line per sampler: sampler, seeds, mean, standard error, min, max.
set -eu
scene=$1; spp=$2; n=$3; method=${4:-mis}; iris=${5:-build/tools/iris}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
for k in sobol independent; do
  for seed in $(seq 1 "$n"); do
    "$iris" render "$scene" --method "$method" --sampler "$k" --width 64 --height 48 --spp "$spp" \
      --seed "$seed" -o "$tmp/img.exr" --quiet --threads 1
    oiiotool "$tmp/img.exr" --printstats 2>/dev/null | awk '/Stats Avg/ {print $3 + $4 + $5}'
  done | awk -v k="$k" '{s += $1; q += $1 * $1; n++; if (n == 1 || $1 < lo) lo = $1; if (n == 1 || $1 > hi) hi = $1}
    END {m = s / n; printf "%s %d %.5f %.5f %.5f %.5f\n", k, n, m, sqrt((q / n - m * m) / n), lo, hi}'
done
