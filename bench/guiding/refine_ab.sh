#!/bin/sh
# Refinement (docs/guiding.md, "Refinement") on and off at equal CPU time:
# bench/guiding/variants.py per scene, guided-nee forced, 64 spp, height 96,
# one thread, seeds 1-3. References: REFDIR/ref_SCENE.exr (height 96, the
# scene's aspect, as bench_guiding renders) (made by the
# commands below when missing; guided-nee is unbiased, guiding.unbiased_*,
# and converges where mis does not: the glass scenes).
# usage: bench/guiding/refine_ab.sh BUILD REFDIR SCENE...
set -eu
B=$1; R=$2; shift 2
for sc in "$@"; do
  if [ ! -f "$R/ref_$sc.exr" ]; then
    "$B/tools/iris" render "$sc" --method guided-nee --force-guiding --spp 1024 --height 96 \
      --seed 777 --threads 2 -o "$R/ref_$sc.exr" > /dev/null 2>&1
  fi
  /usr/bin/python3 "$(dirname "$0")/variants.py" "$B" "$R/ref_$sc.exr" "$sc" --spp 64 --seeds 1,2,3 \
    'refine=--force --refine 8' 'norefine=--force --refine 0'
done
