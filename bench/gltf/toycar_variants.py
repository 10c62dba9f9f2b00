#!/usr/bin/python3
"""Writes the ToyCar files of docs/import-gltf.md ("Strong normal maps (ToyCar's
fabric)") next to Khronos's ToyCar.gltf (Models/ToyCar/glTF of the
glTF-Sample-Assets mirror; not in ../shared): the model without its normal
maps, and its fabric alone (the other nodes' meshes removed, since Blender's
importer also imports nodes outside the scene) with and without its normal
map and its sheen. Then compare them with bench/gltf/blender_gltf_compare.py:

  /usr/bin/python3 bench/gltf/toycar_variants.py /tmp/ToyCar/ToyCar.gltf
  blender -b --factory-startup --python-exit-code 1 -P bench/gltf/blender_gltf_compare.py -- \\
    --iris build/tools/iris --out /tmp/cmp --spp 128 --size 160 --threads 2 \\
    /tmp/ToyCar/ToyCar.gltf /tmp/ToyCar/ToyCarNoNormal.gltf /tmp/ToyCar/Fabric*.gltf
"""
import copy
import json
import os
import sys


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: toycar_variants.py ToyCar.gltf")
    src = sys.argv[1]
    with open(src) as f:
        g = json.load(f)
    fabric = next(i for i, m in enumerate(g["materials"]) if m.get("name") == "Fabric")
    fabric_node = next(i for i, n in enumerate(g["nodes"]) if n.get("name") == "Fabric")

    def only_fabric(h):
        h["scenes"] = [{"nodes": [fabric_node]}]
        for i, n in enumerate(h["nodes"]):
            if i != fabric_node:
                n.pop("mesh", None)

    def no_normal_maps(h):
        for m in h["materials"]:
            m.pop("normalTexture", None)

    def no_fabric_normal(h):
        h["materials"][fabric].pop("normalTexture", None)

    def no_fabric_sheen(h):
        h["materials"][fabric].get("extensions", {}).pop("KHR_materials_sheen", None)

    out = {
        "ToyCarNoNormal": [no_normal_maps],
        "Fabric": [only_fabric],
        "FabricNoNormal": [only_fabric, no_fabric_normal],
        "FabricNoSheen": [only_fabric, no_fabric_sheen],
        "FabricNoSheenNoNormal": [only_fabric, no_fabric_sheen, no_fabric_normal],
    }
    for name, edits in out.items():
        h = copy.deepcopy(g)
        for e in edits:
            e(h)
        path = os.path.join(os.path.dirname(os.path.abspath(src)), name + ".gltf")
        with open(path, "w") as f:
            json.dump(h, f)
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
