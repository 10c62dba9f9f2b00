#!/bin/sh
# Measures `iris validate --blender-import` on the glTF sample models of
# ../shared/assets/gltf under a uniform white sky (radiance 1): each model is
# imported by iris, given the constant environment, and rendered by iris and by
# Blender's own glTF importer + Cycles under iris's camera. Prints one line per
# model: channel ratios iris/Cycles, energy ratio, max block deviation, number
# of importer notes and whether the geometry agrees (docs/validation.md).
# Usage: bench/validate/blender_import.sh BUILD_DIR ASSETS_DIR [OUT_DIR] [SIZE] [SPP]
set -eu
BUILD=${1:?build dir}; ASSETS=${2:?assets dir}; OUT=${3:-/tmp/iris-blender-import}
SIZE=${4:-64}; SPP=${5:-64}
IRIS="$BUILD/tools/iris"
mkdir -p "$OUT"
for model in Box/glTF/Box.gltf BoxTextured/glTF/BoxTextured.gltf BoxVertexColors/glTF/BoxVertexColors.gltf \
             SimpleMeshes/glTF/SimpleMeshes.gltf CesiumMilkTruck/glTF/CesiumMilkTruck.gltf \
             Avocado/glTF/Avocado.gltf TextureCoordinateTest/glTF-Binary/TextureCoordinateTest.glb; do
  name=$(basename "$model"); name=${name%.*}
  "$IRIS" import "$ASSETS/$model" -o "$OUT/$name.json" -q
  /usr/bin/python3 - "$OUT/$name.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["environment"] = {"radiance": [1, 1, 1]}
json.dump(d, open(sys.argv[1], "w"))
PY
  set +e
  "$IRIS" validate "$OUT/$name.json" --blender-import="$ASSETS/$model" --spp "$SPP" --blender-spp "$SPP" \
      --width "$SIZE" --height "$SIZE" --threads 2 --quiet --out "$OUT/$name" 2>"$OUT/$name.err"
  code=$?
  set -e
  /usr/bin/python3 - "$OUT/$name/summary.json" "$name" "$code" <<'PY'
import json, sys
try:
    s = json.load(open(sys.argv[1]))
except OSError:
    print("%-22s exit %s (no summary)" % (sys.argv[2], sys.argv[3])); sys.exit(0)
m = s["methods"][0]; b = s.get("blender_import", {})
print("%-22s exit %s  iris/Cycles R %.4f G %.4f B %.4f  energy %.4f  max block dev %+.1f%%  notes %d  geometry %s"
      % (sys.argv[2], sys.argv[3], *m["channel_ratio"], m["energy_ratio"],
         100 * m["blocks"]["max_rel_dev"], b.get("note_count", -1),
         "DIFFERS" if b.get("geometry_differs") else "agrees"))
PY
done
