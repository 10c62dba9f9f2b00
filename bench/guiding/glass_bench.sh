#!/bin/sh
# Issue 31's benchmark (docs/benchmarks.md, "Light off mirrors and through
# glass"): iris (mis, guided-nee, auto) beside Cycles 3.4 with adaptive
# sampling as Blender users run it, in one `iris bench` run per scene, equal
# wall time, 128 x 96. References: guided-nee, 1024 spp (REFDIR/ref_SCENE.exr,
# made here when missing; bench/guiding/refine_ab.sh makes the same ones).
# usage: bench/guiding/glass_bench.sh BUILD REFDIR OUT [SCENE...]
set -eu
B=$1; R=$2; O=$3; shift 3
SCENES=${*:-env-spheres sky-room sky-room-glazed sky-room-pane lamp-shade door}
for sc in $SCENES; do
  if [ ! -f "$R/ref_$sc.exr" ]; then
    "$B/tools/iris" render "$sc" --method guided-nee --force-guiding --spp 1024 --width 128 --height 96 \
      --seed 777 --threads 2 -o "$R/ref_$sc.exr" > /dev/null 2>&1
  fi
  "$B/tools/iris" bench "$sc" --methods mis,guided-nee,auto --times 2,8 --seeds 1 \
    --reference "$R/ref_$sc.exr" --threads 2 --cycles-adaptive --no-charts --out "$O/$sc"
done
