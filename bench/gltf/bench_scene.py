#!/usr/bin/python3
"""Makes an iris scene for timing a glTF model: `iris import` of the model, a
constant white sky of radiance 1 and one camera (named "bench", the scene's
only camera) framing the model's bounding sphere from the front and slightly
above with a 40 degree vertical field of view: the set-up of
bench/gltf/blender_gltf_compare.py, so the timings of bench/render/cpu_ab.sh
on it are of the pixels that comparison looks at (docs/performance.md).

usage: bench/gltf/bench_scene.py --iris build/tools/iris MODEL.gltf|glb OUT.json
"""
import argparse
import json
import math
import subprocess
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--iris", required=True, help="the iris binary")
    ap.add_argument("model")
    ap.add_argument("out")
    a = ap.parse_args()
    subprocess.run([a.iris, "import", a.model, "-o", a.out, "--quiet"], check=True)
    info = json.loads(subprocess.run([a.iris, "info", a.out, "--json"], check=True,
                                     capture_output=True).stdout)
    lo, hi = info["bounds"]["min"], info["bounds"]["max"]
    centre = [(x + y) / 2 for x, y in zip(lo, hi)]
    radius = math.dist(lo, hi) / 2
    dist = radius / math.tan(math.radians(20.0)) * 1.1
    eye = [centre[0] + 0.3 * dist, centre[1] + 0.3 * dist, centre[2] + 0.9 * dist]
    with open(a.out) as f:
        scene = json.load(f)
    scene["environment"] = {"radiance": [1, 1, 1]}
    scene["cameras"] = [{"name": "bench", "position": eye, "target": centre, "up": [0, 1, 0],
                         "yfov_deg": 40.0, "aspect": 1}]
    with open(a.out, "w") as f:
        json.dump(scene, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
