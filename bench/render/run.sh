#!/bin/sh
# Renderer benchmarks, side by side in one run (docs/performance.md, "Rendering"):
# iris mis with 1 and 2 threads, the raw Embree loop (same scene, same closest-hit
# and occlusion rays per path, occlusion rays ending on emitters; 1 and 2 threads), and Blender 3.4.1 Cycles on the exported scene (render time without
# start-up), for cornell-box, veach-mis and the bunny in the box.
# usage: bench/render/run.sh BUILD_DIR OUT_DIR [SPP [HEIGHT]]
set -eu
B=$1
O=$2
SPP=${3:-64}
H=${4:-256}
HERE=$(cd "$(dirname "$0")" && pwd)
ASSETS=${IRIS_ASSETS:-$HERE/../../../shared/assets}
IRIS=$B/tools/iris
BENCH=$B/bench/render/bench_render
mkdir -p "$O"
"$BENCH" write-bunny-box "$ASSETS/ply/stanford-bunny/bun_zipper.ply" "$O/bunny-box.json" 2>/dev/null
echo "loadavg_before $(cut -d' ' -f1-3 /proc/loadavg)" > "$O/machine.txt"
nproc >> "$O/machine.txt"
for scene in cornell-box veach-mis "$O/bunny-box.json"; do
  name=$(basename "$scene" .json)
  W=$H
  [ "$name" = veach-mis ] && W=$((H * 3 / 2))
  for t in 1 2; do
    "$IRIS" render "$scene" -o "$O/$name.iris.t$t.exr" --spp "$SPP" --width "$W" --height "$H" \
      --threads "$t" --json --quiet > "$O/$name.iris.t$t.json"
  done
  # the raw loop casts iris's closest-hit and occlusion rays per path (calibrated)
  set -- $(/usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['rays']/d['samples'], d['shadow_rays']/d['samples'])" "$O/$name.iris.t2.json")
  "$BENCH" raw "$scene" 2 "$SPP" "$W" "$H" "$1" "$2" > "$O/$name.raw.json" 2>/dev/null
  "$BENCH" raw "$scene" 1 "$SPP" "$W" "$H" "$1" "$2" > "$O/$name.raw.t1.json" 2>/dev/null
  if command -v blender > /dev/null; then
    "$IRIS" export "$scene" --to blender -o "$O/$name.py" --width "$W" --height "$H" --spp "$SPP" --quiet
    blender -b --factory-startup --python-exit-code 1 -P "$O/$name.py" -- --output "$O/$name.cycles.exr" \
      --spp "$SPP" --threads 2 --width "$W" --height "$H" 2>/dev/null | grep IRIS_BLENDER > "$O/$name.cycles.txt" || true
  fi
done
echo "loadavg_after $(cut -d' ' -f1-3 /proc/loadavg)" >> "$O/machine.txt"
/usr/bin/python3 "$HERE/summary.py" "$O"
