#!/bin/sh
# Import benchmark: iris vs `assimp info` vs Blender 3.4's importers on the
# Stanford bunny and generated >= 1M-triangle binary PLY and OBJ files, in one
# run. Prints seconds, triangles/s and peak RSS (GNU time) per tool and file.
# Usage: bench/import/run_import_bench.sh BUILD_DIR [U V]   (default torus 1000 x 600 = 1.2M triangles)
set -eu
BUILD=${1:?usage: run_import_bench.sh BUILD_DIR [U V]}
U=${2:-1000}; V=${3:-600}
HERE=$(cd "$(dirname "$0")" && pwd)
ASSETS=${IRIS_ASSETS:-$HERE/../../../shared/assets}
TMP=$(mktemp -d); trap 'rm -rf "$TMP"' EXIT
"$BUILD/bench/import/iris_gen_mesh" "$U" "$V" "$TMP/torus.ply" "$TMP/torus.obj"
FILES="$ASSETS/ply/stanford-bunny/bun_zipper.ply $TMP/torus.ply $TMP/torus.obj"
TRIS_BUNNY=69451; TRIS_TORUS=$((2 * U * V))
tris() { case "$1" in *bun_zipper*) echo $TRIS_BUNNY;; *) echo $TRIS_TORUS;; esac; }
rss() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1"; }
printf '%-8s %-16s %10s %10s %12s %9s\n' tool file seconds Mtri/s peakRSS_MB B/tri
for f in $FILES; do
  n=$(tris "$f"); name=$(basename "$f")
  # iris: best of 3 inside one process (the import call only)
  /usr/bin/time -v "$BUILD/bench/import/iris_import_bench" --repeat 3 "$f" > "$TMP/out" 2> "$TMP/time"
  s=$(sed -n 's/.*\t\([0-9.]*\) s\t.*/\1/p' "$TMP/out")
  r=$(rss "$TMP/time")
  printf '%-8s %-16s %10s %10.2f %12.1f %9.0f\n' iris "$name" "$s" "$(echo "$n / $s / 1000000" | bc -l)" "$(echo "$r/1024" | bc -l)" "$(echo "$r*1024/$n" | bc -l)"
  # assimp info: whole process (load + its post-processing + printing)
  if command -v assimp > /dev/null; then
    /usr/bin/time -v assimp info "$f" > /dev/null 2> "$TMP/time" || true
    s=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): 0:\([0-9.]*\)/\1/p' "$TMP/time")
    r=$(rss "$TMP/time")
    printf '%-8s %-16s %10s %10.2f %12.1f %9.0f\n' assimp "$name" "$s" "$(echo "$n / $s / 1000000" | bc -l)" "$(echo "$r/1024" | bc -l)" "$(echo "$r*1024/$n" | bc -l)"
  fi
  # Blender: time of the import operator only (startup excluded), RSS of the whole process
  if command -v blender > /dev/null; then
    case "$f" in *.ply) op="bpy.ops.import_mesh.ply(filepath=f)";; *) op="bpy.ops.wm.obj_import(filepath=f)";; esac
    cat > "$TMP/b.py" <<PY
import bpy, time
bpy.ops.wm.read_factory_settings(use_empty=True)
f = "$f"
t = time.perf_counter(); $op; t = time.perf_counter() - t
print("BLENDER_IMPORT_SECONDS %.4f" % t)
PY
    /usr/bin/time -v blender -b --factory-startup -noaudio --python "$TMP/b.py" > "$TMP/out" 2> "$TMP/time" || true
    s=$(sed -n 's/^BLENDER_IMPORT_SECONDS //p' "$TMP/out")
    r=$(rss "$TMP/time")
    if [ -n "$s" ]; then
      printf '%-8s %-16s %10s %10.2f %12.1f %9.0f\n' blender "$name" "$s" "$(echo "$n / $s / 1000000" | bc -l)" "$(echo "$r/1024" | bc -l)" "$(echo "$r*1024/$n" | bc -l)"
    fi
  fi
done
