#!/bin/sh
# The instancing benchmark (docs/performance.md, "Instancing: the forest"): a
# generated glTF forest (make_forest.py: one 20,480-triangle shrub under N glTF
# nodes, a ground plane, a camera), lit by the shared HDR sky, rendered at
# 256x160, 64 spp, 2 threads by iris (`iris render`, its default method) and by
# Blender 3.4's own glTF import + Cycles, one after the other for each N: whole
# process wall time and peak RSS from GNU time. Prints a table.
#
#   bench/instancing/forest.sh build/tools/iris OUT_DIR [N...]     (default N: 100 1000 10000 100000)
set -eu
iris=$1
out=$2
shift 2
counts=${*:-100 1000 10000 100000}
here=$(cd "$(dirname "$0")" && pwd)
sky=$(cd "$here/../../../shared/assets/env" && pwd)/immenstadter_horn_1k.hdr
mkdir -p "$out"
printf '| placements | world triangles | iris wall s | iris peak MB | Cycles wall s | Cycles peak MB |\n|---|---|---|---|---|---|\n'
for n in $counts; do
  glb=$out/forest-$n.glb
  [ -f "$glb" ] || /usr/bin/python3 "$here/make_forest.py" "$n" "$glb"
  /usr/bin/time -f '%e %M' -o "$out/time-iris-$n" "$iris" render "$glb" --env "$sky" --spp 64 --width 256 \
    --height 160 --threads 2 --quiet -o "$out/iris-$n.exr" --png "$out/iris-$n.png"
  /usr/bin/time -f '%e %M' -o "$out/time-cycles-$n" blender -b --factory-startup --python-exit-code 1 \
    -P "$here/blender_forest.py" -- "$glb" "$sky" "$out/cycles-$n.exr" 64 256 160 2 >"$out/blender-$n.log" 2>&1
  ti=$(tail -1 "$out/time-iris-$n")
  tb=$(tail -1 "$out/time-cycles-$n")
  set -- $ti $tb
  printf '| %s | %s | %s | %s | %s | %s |\n' "$n" "$((n * 20480 + 2))" "$1" "$(($2 / 1000))" "$3" "$(($4 / 1000))"
done
