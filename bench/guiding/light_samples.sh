#!/bin/sh
# Learned light tables from the training's light samples (docs/guiding.md,
# "Learned light selection"; docs/benchmarks.md, "Light tables from light
# samples"): the tree, the photons' tables and the tables that also learned
# from training's light samples, (1) on direct light alone at equal spp and
# (2) on the whole path at equal wall-clock time.
#
#   bench/guiding/light_samples.sh BUILD_DIR OUT_DIR [SEEDS] [SCENES] [TIME]
#
# (1) --max-depth 0, 144 x 96, 16 spp (guided-nee: 8 training spp, discarded;
#     mis learned: 8 light-only training spp, never in the image),
#     against mis with the tree, --max-depth 0, 1024 spp, seed 99.
# (2) 108 x 72, TIME seconds (default 4) on 2 threads, against mis with the
#     tree, 4096 spp, independent sampler, seed 1000003 (rendered once into
#     OUT_DIR and kept). Prints each variant's relMSE per seed and their
#     geometric mean.
set -e
B=${1:?usage: light_samples.sh BUILD_DIR OUT_DIR [SEEDS] [SCENES] [TIME]}
OUT=${2:?usage: light_samples.sh BUILD_DIR OUT_DIR [SEEDS] [SCENES] [TIME]}
SEEDS=${3:-"1 2 3 4"}
SCENES=${4:-"corridor-rooms office"}
T=${5:-4}
IRIS="$B/tools/iris"
RELMSE="$B/bench/render/relmse"
mkdir -p "$OUT"

row() { # row SCENE LABEL REF OUTPUT_STEM IRIS_ARGS...
  scene=$1 label=$2 ref=$3 stem=$4
  shift 4
  vals=""
  for seed in $SEEDS; do
    "$IRIS" render "$scene" "$@" --threads 2 --seed "$seed" -o "$stem-$seed.exr" --quiet
    vals="$vals $("$RELMSE" "$stem-$seed.exr" "$ref" | tail -n 1)"
  done
  printf '%-16s %-36s' "$scene" "$label"
  echo "$vals" | awk '{l = 0; for (i = 1; i <= NF; i++) l += log($i)
    printf " geomean %.4g  (", exp(l / NF); for (i = 1; i <= NF; i++) printf " %.4g", $i; print " )" }'
}

for s in $SCENES; do
  ref0="$OUT/ref-direct-$s.exr"
  [ -f "$ref0" ] || "$IRIS" render "$s" --method mis --max-depth 0 --spp 1024 --height 96 --threads 2 --seed 99 \
    -o "$ref0" --quiet
  d="--max-depth 0 --spp 16 --height 96"
  g="--train-spp 8 --discard-training"
  echo "== $s: direct light, 16 spp"
  row "$s" "mis tree" "$ref0" "$OUT/d-$s-mis" --method mis $d
  row "$s" "mis learned, photons alone" "$ref0" "$OUT/d-$s-mislp" --method mis --light-sampler learned \
    --no-light-samples $d
  row "$s" "mis learned, + light samples" "$ref0" "$OUT/d-$s-misl" --method mis --light-sampler learned \
    --train-spp 8 $d
  row "$s" "guided-nee tree" "$ref0" "$OUT/d-$s-gn" --method guided-nee $d $g
  row "$s" "guided-nee learned, photons" "$ref0" "$OUT/d-$s-gnp" --method guided-nee --light-sampler learned \
    --no-light-samples $d $g
  row "$s" "guided-nee learned, + light samples" "$ref0" "$OUT/d-$s-gnl" --method guided-nee \
    --light-sampler learned $d $g
done
for s in $SCENES; do
  ref="$OUT/ref-$s.exr"
  [ -f "$ref" ] || "$IRIS" render "$s" --method mis --spp 4096 --width 108 --height 72 --threads 2 --seed 1000003 \
    --sampler independent -o "$ref" --quiet
  e="--time $T --time-total --adaptive off --width 108 --height 72"
  echo "== $s: whole path, $T s"
  row "$s" "mis tree" "$ref" "$OUT/e-$s-mis" --method mis $e
  row "$s" "mis learned, photons alone" "$ref" "$OUT/e-$s-mislp" --method mis --light-sampler learned \
    --no-light-samples $e
  row "$s" "mis learned, + light samples" "$ref" "$OUT/e-$s-misl" --method mis --light-sampler learned $e
  row "$s" "guided-nee tree" "$ref" "$OUT/e-$s-gn" --method guided-nee $e
  row "$s" "guided-nee learned, photons" "$ref" "$OUT/e-$s-gnp" --method guided-nee --light-sampler learned \
    --no-light-samples $e
  row "$s" "guided-nee learned, + light samples" "$ref" "$OUT/e-$s-gnl" --method guided-nee \
    --light-sampler learned $e
  row "$s" "auto tree" "$ref" "$OUT/e-$s-auto" --method auto $e
  row "$s" "auto learned" "$ref" "$OUT/e-$s-autol" --method auto --light-sampler learned $e
done
