#!/bin/sh
# Import of one model as web pipelines deliver it (issue 23): the plain glTF
# against its Draco, meshopt (gltf-transform) and gltfpack encodings, in one
# run. iris: iris_import_bench (importer + scene validation, what `iris import`
# runs; best of 3 in one process) and the peak RSS of that process (GNU time).
# Blender 3.4.1: time.perf_counter() around bpy.ops.import_scene.gltf inside
# `blender -b --factory-startup` (startup excluded; peak RSS includes Blender).
# Usage: bench/import/run_web_bench.sh BUILD_DIR GLTF_TRANSFORM [RINGS SEGMENTS]
#   GLTF_TRANSFORM: the gltf-transform CLI (npm @gltf-transform/cli 4.5.1)
#   default sphere 600 x 1000: 601,601 vertices, 1.2M triangles
set -eu
BUILD=${1:?usage: run_web_bench.sh BUILD_DIR GLTF_TRANSFORM [RINGS SEGMENTS]}
GT=${2:?gltf-transform CLI path}
RINGS=${3:-600}; SEGS=${4:-1000}
HERE=$(cd "$(dirname "$0")" && pwd)
TMP=$(mktemp -d); trap 'rm -rf "$TMP"' EXIT
python3 - "$HERE/../../tests/importers_gltf/data" "$TMP/plain.glb" "$RINGS" "$SEGS" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
import make_web
doc, blob = make_web.base_doc([("image/png", make_web.png(32, 32, 4, make_web.rgba)),
                               ("image/png", make_web.png(32, 32, 3, make_web.rgb))], int(sys.argv[3]), int(sys.argv[4]))
open(sys.argv[2], "wb").write(make_web.glb(doc, blob))
PY
"$GT" draco "$TMP/plain.glb" "$TMP/draco.glb" > /dev/null
"$GT" meshopt --level high "$TMP/plain.glb" "$TMP/meshopt.glb" > /dev/null
gltfpack -cc -i "$TMP/plain.glb" -o "$TMP/gltfpack.glb" > /dev/null
rss() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1"; }
printf '%-8s %-13s %9s %10s %12s\n' tool file MB seconds peakRSS_MB
for f in plain draco meshopt gltfpack; do
  mb=$(echo "$(stat -c %s "$TMP/$f.glb") / 1048576" | bc -l)
  /usr/bin/time -v "$BUILD/bench/import/iris_import_bench" --repeat 3 "$TMP/$f.glb" > "$TMP/out" 2> "$TMP/time"
  s=$(sed -n 's/.*\t\([0-9.]*\) s\t.*/\1/p' "$TMP/out")
  printf '%-8s %-13s %9.2f %10s %12.1f\n' iris "$f.glb" "$mb" "$s" "$(echo "$(rss "$TMP/time")/1024" | bc -l)"
done
if command -v blender > /dev/null; then
  for f in plain draco; do
    mb=$(echo "$(stat -c %s "$TMP/$f.glb") / 1048576" | bc -l)
    /usr/bin/time -v blender -b --factory-startup --python-exit-code 1 --python-expr "
import time, numpy as np, bpy
np.bool = bool  # Blender 3.4's glTF add-on uses np.bool (removed in numpy 1.24)
t = time.perf_counter()
bpy.ops.import_scene.gltf(filepath='$TMP/$f.glb')
n = sum(len(o.data.polygons) for o in bpy.data.objects if o.type == 'MESH')
print('IRIS_IMPORT seconds=%.3f triangles=%d' % (time.perf_counter() - t, n))
" > "$TMP/out" 2> "$TMP/time" || {
      # Debian's Blender 3.4 lacks the add-on's libextern_draco.so
      printf '%-8s %-13s %9.2f %10s %12s   (fails: %s)\n' blender "$f.glb" "$mb" - - "$(grep -m1 'OSError' "$TMP/out")"
      continue; }
    s=$(sed -n 's/^IRIS_IMPORT seconds=\([0-9.]*\).*/\1/p' "$TMP/out")
    printf '%-8s %-13s %9.2f %10s %12.1f   (%s)\n' blender "$f.glb" "$mb" "$s" "$(echo "$(rss "$TMP/time")/1024" | bc -l)" \
      "$(sed -n 's/^IRIS_IMPORT //p' "$TMP/out")"
  done
fi
