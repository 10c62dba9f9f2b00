#!/bin/bash
# Ray rate of `iris render --method mis` against the raw Embree loop, each the
# best of REPS runs taken back to back (the machine is shared: the best run is
# the one least disturbed), plus 1 -> 2 thread scaling of iris from the best
# wall times. docs/performance.md, "Rendering".
# usage: bench/render/best_of.sh BUILD_DIR OUT_DIR [REPS [SPP [HEIGHT]]]
set -eu
B=$1; O=$2; R=${3:-5}; SPP=${4:-32}; H=${5:-128}
HERE=$(cd "$(dirname "$0")" && pwd)
ASSETS=${IRIS_ASSETS:-$HERE/../../../shared/assets}
IRIS=${IRIS:-$B/tools/iris}
BENCH=$B/bench/render/bench_render
mkdir -p "$O"
"$BENCH" write-bunny-box "$ASSETS/ply/stanford-bunny/bun_zipper.ply" "$O/bunny-box.json" 2>/dev/null
echo "loadavg $(cut -d' ' -f1-3 /proc/loadavg), $R runs each, best taken"
echo "| scene | size, spp | threads | iris Mrays/s | raw Embree Mrays/s | iris/raw | rays, shadow rays per path (iris / raw) |"
echo "|---|---|---|---|---|---|---|"
for scene in cornell-box veach-mis "$O/bunny-box.json"; do
  name=$(basename "$scene" .json)
  W=$H; [ "$name" = veach-mis ] && W=$((H * 3 / 2))
  for t in 1 2; do
    bi=0; br=0; wall=1e9
    for r in $(seq "$R"); do
      "$IRIS" render "$scene" -o "$O/$name.exr" --spp "$SPP" --width "$W" --height "$H" --threads "$t" --json --quiet > "$O/$name.t$t.json"
      read -r ir sec rpp spp_ < <(/usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['rays_per_second'], d['seconds'], d['rays']/d['samples'], d['shadow_rays']/d['samples'])" "$O/$name.t$t.json")
      "$BENCH" raw "$scene" "$t" "$SPP" "$W" "$H" "$rpp" "$spp_" > "$O/$name.raw.t$t.json" 2>/dev/null
      read -r rr rrpp rspp < <(/usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['rays_per_second'], d['rays_per_path'], d['shadow_per_path'])" "$O/$name.raw.t$t.json")
      bi=$(/usr/bin/python3 -c "print(max($bi, $ir))"); br=$(/usr/bin/python3 -c "print(max($br, $rr))")
      wall=$(/usr/bin/python3 -c "print(min($wall, $sec))")
    done
    eval "wall_$t=$wall"
    /usr/bin/python3 -c "print('| %s | %dx%d, %d | %d | %.3f | %.3f | %.2f | %.2f, %.2f / %.2f, %.2f |' % ('$name', $W, $H, $SPP, $t, $bi / 1e6, $br / 1e6, $bi / $br, $rpp, $spp_, $rrpp, $rspp))"
  done
  /usr/bin/python3 -c "print('| %s | | 1 -> 2 | iris scaling %.2fx (best wall %.3f s -> %.3f s) | | | |' % ('$name', $wall_1 / $wall_2, $wall_1, $wall_2))"
done
