#!/usr/bin/python3
"""The glass-lamp room of issue 30 item 4 (docs/import-gltf.md, "A glass lamp lighting a room").

Builds ONE glTF file that both iris's importer and Blender's own importer read: Khronos's
StainedGlassLamp (CC-BY 4.0 Wayfair; not in this repository, pass its folder) standing on a
table in a closed room of grey diffuse walls, with the lamp's bulbs made emissive by
KHR_materials_emissive_strength and a glTF camera that sees the lamp and the walls. The
room's geometry lives in a second buffer (OUT/room.bin); the lamp's buffer and images are
referenced by relative paths to the lamp's folder.

  /usr/bin/python3 bench/gltf/glass_lamp.py --lamp /tmp/assets/StainedGlassLamp --out /tmp/lamp \
      [--strength 100] [--variant NAME]...

Each --variant writes OUT/lamp-NAME.gltf, the same scene with one feature removed in the file
(so both renderers see the change alike); "base" is the scene itself. Known variants:
"""
import argparse
import copy
import json
import os
import sys

import numpy as np

WALL = {"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1], "metallicFactor": 0,
                                 "roughnessFactor": 1}, "name": "room_wall"}
TABLE = {"pbrMetallicRoughness": {"baseColorFactor": [0.35, 0.22, 0.12, 1], "metallicFactor": 0,
                                  "roughnessFactor": 1}, "name": "room_table"}


def box(lo, hi, inward):
    """12 triangles of an axis-aligned box, counter-clockwise seen from outside (or from
    inside when inward), with flat normals."""
    lo, hi = np.array(lo, float), np.array(hi, float)
    pos, nrm, idx = [], [], []
    for axis in range(3):
        for side in (0, 1):
            n = np.zeros(3)
            n[axis] = 1 if side else -1
            if inward:
                n = -n
            u, v = (axis + 1) % 3, (axis + 2) % 3
            c = []
            for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = np.where(np.arange(3) == axis, hi if side else lo, 0.0)
                p[u] = hi[u] if a else lo[u]
                p[v] = hi[v] if b else lo[v]
                c.append(p)
            base = len(pos)
            e = np.cross(c[1] - c[0], c[2] - c[0])
            order = (0, 1, 2, 0, 2, 3) if np.dot(e, n) > 0 else (0, 2, 1, 0, 3, 2)
            pos += c
            nrm += [n] * 4
            idx += [base + k for k in order]
    return np.array(pos, np.float32), np.array(nrm, np.float32), np.array(idx, np.uint32)


def add_mesh(g, blob, name, geom, material):
    pos, nrm, idx = geom
    buf = len(g["buffers"]) - 1
    views = []
    for arr, target in ((pos, 34962), (nrm, 34962), (idx, 34963)):
        while len(blob) % 4:
            blob.append(0)
        off = len(blob)
        blob.extend(arr.tobytes())
        g["bufferViews"].append({"buffer": buf, "byteOffset": off, "byteLength": arr.nbytes,
                                 "target": target})
        views.append(len(g["bufferViews"]) - 1)
    acc = len(g["accessors"])
    g["accessors"] += [
        {"bufferView": views[0], "componentType": 5126, "count": len(pos), "type": "VEC3",
         "min": pos.min(0).tolist(), "max": pos.max(0).tolist()},
        {"bufferView": views[1], "componentType": 5126, "count": len(nrm), "type": "VEC3"},
        {"bufferView": views[2], "componentType": 5125, "count": len(idx), "type": "SCALAR"}]
    g["materials"].append(material)
    g["meshes"].append({"name": name, "primitives": [
        {"attributes": {"POSITION": acc, "NORMAL": acc + 1}, "indices": acc + 2,
         "material": len(g["materials"]) - 1}]})
    g["nodes"].append({"name": name, "mesh": len(g["meshes"]) - 1})
    return len(g["nodes"]) - 1


def mat(g, name):
    return next(m for m in g["materials"] if m.get("name") == name)


def ext(m):
    return m.setdefault("extensions", {})


# --- the variants: each removes (or pins) one feature in the file, for both renderers ----
def v_no_emissive_textures(g):
    """the emissive textures and factors of grill/hardware/base/stainedglass (bulbs keep theirs)"""
    for m in g["materials"]:
        if m.get("name") in ("grill", "hardware", "base", "stainedglass"):
            m.pop("emissiveTexture", None)
            m.pop("emissiveFactor", None)


def v_no_transmission_texture(g):
    """stainedglass: transmissionTexture removed (transmissionFactor 1 everywhere)"""
    for m in g["materials"]:
        m.get("extensions", {}).get("KHR_materials_transmission", {}).pop("transmissionTexture", None)


def v_no_clearcoat(g):
    for m in g["materials"]:
        m.get("extensions", {}).pop("KHR_materials_clearcoat", None)


def v_no_mask(g):
    """alphaMode MASK -> OPAQUE (grill and shade)"""
    for m in g["materials"]:
        if m.get("alphaMode") == "MASK":
            m.pop("alphaMode")


def v_no_volume(g):
    for m in g["materials"]:
        m.get("extensions", {}).pop("KHR_materials_volume", None)


def v_no_normal_maps(g):
    for m in g["materials"]:
        m.pop("normalTexture", None)


def v_no_transmission(g):
    """every KHR_materials_transmission removed (the shade becomes an opaque-but-masked plastic)"""
    for m in g["materials"]:
        m.get("extensions", {}).pop("KHR_materials_transmission", None)


def v_double_sided_bulbs(g):
    mat(g, "bulbs")["doubleSided"] = True


def keep_nodes(g, keep):
    """the other nodes lose their mesh (Blender's importer creates every node, whatever the
    scene lists, so removing a node from the scene is not enough)"""
    for n in g["nodes"]:
        if n.get("name") not in keep:
            n.pop("mesh", None)


def v_bulbs_only(g):
    """only the bulbs and the room: every other lamp node removed"""
    keep_nodes(g, {"bulbs", "room", "table", "camera"})


def v_bulbs_shade(g):
    """the bulbs, the shade (stainedglass) and the room"""
    keep_nodes(g, {"bulbs", "stainedglass", "room", "table", "camera"})


def v_double_sided(g):
    """every lamp material doubleSided (iris then emits from both faces, as Cycles always does)"""
    for m in g["materials"]:
        if not m.get("name", "").startswith("room_"):
            m["doubleSided"] = True


def v_lambert_room(g):
    """room and table given KHR_materials_specular specularFactor 0 (iris: exactly Lambert;
    glass_lamp_compare.py --lambert-room gives Blender's import a Diffuse BSDF there)"""
    for m in g["materials"]:
        if m.get("name", "").startswith("room_"):
            ext(m)["KHR_materials_specular"] = {"specularFactor": 0}
    g["extensionsUsed"] = sorted(set(g["extensionsUsed"]) | {"KHR_materials_specular"})


def v_plain(g):
    """every feature above removed at once: no emissive textures, transmission texture,
    clearcoat, MASK, volume or normal maps"""
    for f in (v_no_emissive_textures, v_no_transmission_texture, v_no_clearcoat, v_no_mask,
              v_no_volume, v_no_normal_maps):
        f(g)


VARIANTS = {k[2:].replace("_", "-"): f for k, f in list(globals().items()) if k.startswith("v_")}
__doc__ += "".join("  %s: %s\n" % (k, (f.__doc__ or k).strip().split("\n")[0]) for k, f in VARIANTS.items())


def build(lamp_dir, out, strength):
    with open(os.path.join(lamp_dir, "StainedGlassLamp.gltf")) as f:
        g = json.load(f)
    rel = os.path.relpath(os.path.abspath(lamp_dir), os.path.abspath(out))  # (tinygltf 2.7 joins even absolute URIs to the folder)
    for b in g["buffers"]:
        b["uri"] = os.path.join(rel, b["uri"])
    for im in g["images"]:
        im["uri"] = os.path.join(rel, im["uri"])
    bulbs = mat(g, "bulbs")
    ext(bulbs)["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
    g["extensionsUsed"] = sorted(set(g["extensionsUsed"]) | {"KHR_materials_emissive_strength"})
    blob = bytearray()
    g["buffers"].append({"uri": "room.bin", "byteLength": 0})
    # lamp stands on a table top at y = 0; room 4 x 2.7 x 4 m, floor at y = -0.75
    room = add_mesh(g, blob, "room", box([-2.0, -0.75, -2.0], [2.0, 1.95, 2.0], True), copy.deepcopy(WALL))
    table = add_mesh(g, blob, "table", box([-0.45, -0.75, -0.45], [0.45, 0.0, 0.45], False), copy.deepcopy(TABLE))
    g["buffers"][-1]["byteLength"] = len(blob)
    g.setdefault("cameras", []).append({"name": "view", "type": "perspective", "perspective": {
        "yfov": 0.9, "aspectRatio": 4 / 3, "znear": 0.01}})
    # camera at (0.3, 0.6, 1.15) looking at (0, 0.36, -0.2) (the lamp, the back wall behind)
    eye, target = np.array([0.3, 0.6, 1.15]), np.array([0.0, 0.36, -0.2])
    zc = eye - target
    zc /= np.linalg.norm(zc)
    xc = np.cross([0, 1, 0], zc)
    xc /= np.linalg.norm(xc)
    yc = np.cross(zc, xc)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = xc, yc, zc, eye
    g["nodes"].append({"name": "camera", "camera": len(g["cameras"]) - 1,
                       "matrix": m.T.reshape(-1).tolist()})
    g["scenes"][0]["nodes"] += [room, table, len(g["nodes"]) - 1]
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "room.bin"), "wb") as f:
        f.write(blob)
    return g


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lamp", required=True, help="folder with StainedGlassLamp.gltf")
    ap.add_argument("--out", required=True)
    ap.add_argument("--strength", type=float, default=100.0, help="the bulbs' emissiveStrength")
    ap.add_argument("--variant", action="append", default=[], help="base, a feature to remove, or a,b (both)")
    a = ap.parse_args()
    g = build(a.lamp, a.out, a.strength)
    for name in a.variant or ["base"]:
        v = copy.deepcopy(g)
        for part in name.split(","):
            if part != "base":
                if part not in VARIANTS:
                    sys.exit("unknown variant %s (known: %s)" % (part, ", ".join(VARIANTS)))
                VARIANTS[part](v)
        path = os.path.join(a.out, "lamp-%s.gltf" % name.replace(",", "+"))
        with open(path, "w") as f:
            json.dump(v, f, indent=1)
        print(path)


main()
