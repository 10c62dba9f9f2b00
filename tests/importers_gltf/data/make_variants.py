#!/usr/bin/env python3
"""Regenerates variants-quads.gltf for tests/importers_gltf/test_variants.c.

    python3 tests/importers_gltf/data/make_variants.py

Three unit quads side by side in the z = 0 plane (x centres -1.2, 0, 1.2),
one mesh with one primitive per quad, a camera on +z, and KHR_materials_variants
with three variants. Materials are plain colours (metallic 0, roughness 1, KHR_materials_specular specularFactor 0:
exactly Lambert, so iris stores them as diffuse and a diffuse quad under a white
sky of radiance 1 shows exactly its colour):

    primitive   default   "sunset"   "forest"   "ocean"
    left        grey      red        grey       blue
    middle      grey      grey       green      blue
    right       yellow    green      yellow     yellow

(left maps red to sunset and blue to ocean; middle green to forest and blue to
ocean; right green to sunset). Material "unused" is referenced by nothing.
Output is deterministic.
"""
import base64, json, os, struct

HERE = os.path.dirname(os.path.abspath(__file__))

COLOURS = [("grey", (0.5, 0.5, 0.5)), ("red", (0.8, 0.1, 0.1)), ("green", (0.1, 0.7, 0.2)),
           ("blue", (0.1, 0.2, 0.9)), ("yellow", (0.9, 0.8, 0.1)), ("unused", (0.3, 0.3, 0.3))]
GREY, RED, GREEN, BLUE, YELLOW = range(5)
SUNSET, FOREST, OCEAN = range(3)


def main():
    data = b""
    accessors, views = [], []
    for cx in (-1.2, 0.0, 1.2):
        pos = [(cx - 0.5, -0.5, 0), (cx + 0.5, -0.5, 0), (cx + 0.5, 0.5, 0), (cx - 0.5, 0.5, 0)]
        views.append({"buffer": 0, "byteOffset": len(data), "byteLength": 48})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": 4, "type": "VEC3",
                          "min": [cx - 0.5, -0.5, 0], "max": [cx + 0.5, 0.5, 0]})
        data += b"".join(struct.pack("<3f", *p) for p in pos)
    views.append({"buffer": 0, "byteOffset": len(data), "byteLength": 12})
    accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": 6, "type": "SCALAR"})
    data += struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    idx = len(accessors) - 1

    def prim(i, material, mappings):
        return {"attributes": {"POSITION": i}, "indices": idx, "material": material,
                "extensions": {"KHR_materials_variants": {"mappings": [
                    {"material": m, "variants": v} for m, v in mappings]}}}

    primitives = [prim(0, GREY, [(RED, [SUNSET]), (BLUE, [OCEAN])]),
                  prim(1, GREY, [(GREEN, [FOREST]), (BLUE, [OCEAN])]),
                  prim(2, YELLOW, [(GREEN, [SUNSET])])]
    doc = {
        "asset": {"version": "2.0", "generator": "iris tests/importers_gltf/data/make_variants.py"},
        "extensionsUsed": ["KHR_materials_variants", "KHR_materials_specular"],
        "extensions": {"KHR_materials_variants": {"variants": [
            {"name": "sunset"}, {"name": "forest"}, {"name": "ocean"}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0, "name": "quads"},
                  {"camera": 0, "translation": [0, 0, 5], "name": "front"}],
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": 0.5, "aspectRatio": 2.0, "znear": 0.1}}],
        "meshes": [{"name": "quads", "primitives": primitives}],
        "materials": [{"name": n, "pbrMetallicRoughness": {"baseColorFactor": list(c) + [1.0],
                                                           "metallicFactor": 0.0, "roughnessFactor": 1.0},
                       "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}
                      for n, c in COLOURS],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    }
    with open(os.path.join(HERE, "variants-quads.gltf"), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
