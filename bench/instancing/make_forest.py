#!/usr/bin/python3
"""A generated glTF forest for the instancing benchmark (docs/performance.md,
"Instancing"): one shrub of 20,480 triangles (an icosphere subdivided five
times, its radius displaced by a few sines so it is lumpy, smooth normals)
placed by N glTF nodes on a jittered grid with random yaw and scale (seeded:
the same N gives the same file), a ground plane under them and a camera
looking over the forest from one corner. No lights: render it with a sky
(`iris render --env`, Blender's world).

  make_forest.py N OUT.glb [--ext-instancing]

--ext-instancing places the shrubs with one node carrying EXT_mesh_gpu_instancing
(TRANSLATION, ROTATION, SCALE accessors) instead of N nodes.
"""
import json
import math
import struct
import sys

import numpy as np


def icosphere(level):
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
         (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(level):
        cache, nf = {}, []
        def mid(a, b):
            k = (min(a, b), max(a, b))
            if k not in cache:
                p = verts[a] + verts[b]
                verts.append(p / np.linalg.norm(p))
                cache[k] = len(verts) - 1
            return cache[k]
        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    return np.array(verts), np.array(f, dtype=np.uint32)


def shrub():
    v, f = icosphere(5)
    x, y, z = v[:, 0], v[:, 1], v[:, 2]
    r = 1.0 + 0.12 * np.sin(7 * x) * np.sin(6 * y + 1) + 0.08 * np.sin(11 * z + 2 * x)
    p = v * r[:, None]
    p[:, 1] = p[:, 1] * 0.8 + 0.8  # squat, sitting on the ground
    n = np.zeros_like(p)
    tri = p[f]
    fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    for k in range(3):
        np.add.at(n, f[:, k], fn)
    n /= np.linalg.norm(n, axis=1)[:, None]
    return p.astype(np.float32), n.astype(np.float32), f


def main():
    count = int(sys.argv[1])
    out = sys.argv[2]
    ext = "--ext-instancing" in sys.argv[3:]
    rng = np.random.default_rng(20)
    p, n, f = shrub()
    side = math.ceil(math.sqrt(count))
    spacing = 2.6
    half = side * spacing / 2
    ij = np.array([(i, j) for i in range(side) for j in range(side)][:count], float)
    pos = np.zeros((count, 3), np.float32)
    pos[:, 0] = (ij[:, 0] + 0.5 + rng.uniform(-0.3, 0.3, count)) * spacing - half
    pos[:, 2] = (ij[:, 1] + 0.5 + rng.uniform(-0.3, 0.3, count)) * spacing - half
    yaw = rng.uniform(0, 2 * math.pi, count)
    scale = rng.uniform(0.7, 1.3, count).astype(np.float32)
    quat = np.zeros((count, 4), np.float32)  # x, y, z, w about +Y
    quat[:, 1] = np.sin(yaw / 2)
    quat[:, 3] = np.cos(yaw / 2)
    g = half + spacing
    ground_p = np.array([[-g, 0, g], [g, 0, g], [g, 0, -g], [-g, 0, -g]], np.float32)
    ground_n = np.array([[0, 1, 0]] * 4, np.float32)
    ground_i = np.array([0, 1, 2, 0, 2, 3], np.uint32)

    blob = bytearray()
    views, accessors = [], []
    def add(arr, target, kind, comp, minmax=False):
        while len(blob) % 4:
            blob.append(0)
        data = arr.tobytes()
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), **({"target": target} if target else {})})
        blob.extend(data)
        acc = {"bufferView": len(views) - 1, "componentType": comp, "count": int(arr.shape[0]), "type": kind}
        if minmax:
            acc["min"] = [float(x) for x in arr.min(axis=0)]
            acc["max"] = [float(x) for x in arr.max(axis=0)]
        accessors.append(acc)
        return len(accessors) - 1
    FLOAT, UINT = 5126, 5125
    a_p = add(p, 34962, "VEC3", FLOAT, True)
    a_n = add(n, 34962, "VEC3", FLOAT)
    a_i = add(f.reshape(-1), 34963, "SCALAR", UINT)
    a_gp = add(ground_p, 34962, "VEC3", FLOAT, True)
    a_gn = add(ground_n, 34962, "VEC3", FLOAT)
    a_gi = add(ground_i, 34963, "SCALAR", UINT)
    doc = {
        "asset": {"version": "2.0", "generator": "iris bench/instancing/make_forest.py"},
        "materials": [
            {"name": "leaves", "pbrMetallicRoughness": {"baseColorFactor": [0.18, 0.42, 0.12, 1], "metallicFactor": 0,
                                                         "roughnessFactor": 0.8}},
            {"name": "ground", "pbrMetallicRoughness": {"baseColorFactor": [0.35, 0.3, 0.22, 1], "metallicFactor": 0,
                                                         "roughnessFactor": 0.9}}],
        "meshes": [
            {"name": "shrub", "primitives": [{"attributes": {"POSITION": a_p, "NORMAL": a_n}, "indices": a_i, "material": 0}]},
            {"name": "ground", "primitives": [{"attributes": {"POSITION": a_gp, "NORMAL": a_gn}, "indices": a_gi, "material": 1}]}],
        "cameras": [{"name": "view", "type": "perspective", "perspective": {"yfov": math.radians(45), "aspectRatio": 1.6,
                                                                             "znear": 0.1}}],
    }
    nodes = [{"name": "ground", "mesh": 1}]
    # camera over one corner, looking towards the middle and down 25 degrees
    cy, cyaw, cpitch = 6.0, math.radians(-45), math.radians(-25)
    qy = (0, math.sin(cyaw / 2), 0, math.cos(cyaw / 2))
    qx = (math.sin(cpitch / 2), 0, 0, math.cos(cpitch / 2))
    def qmul(a, b):
        ax, ay, az, aw = a
        bx, by, bz, bw = b
        return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)
    nodes.append({"name": "view", "camera": 0, "translation": [-half * 0.9, cy, half * 0.9],
                  "rotation": list(qmul(qy, qx))})
    if ext:
        doc["extensionsUsed"] = ["EXT_mesh_gpu_instancing"]
        a_t = add(pos, None, "VEC3", FLOAT)
        a_r = add(quat, None, "VEC4", FLOAT)
        a_s = add(np.repeat(scale[:, None], 3, axis=1).astype(np.float32), None, "VEC3", FLOAT)
        nodes.append({"name": "shrubs", "mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {
            "attributes": {"TRANSLATION": a_t, "ROTATION": a_r, "SCALE": a_s}}}})
    else:
        for k in range(count):
            s = float(scale[k])
            nodes.append({"mesh": 0, "translation": [float(x) for x in pos[k]],
                          "rotation": [float(x) for x in quat[k]], "scale": [s, s, s]})
    doc["nodes"] = nodes
    doc["scenes"] = [{"nodes": list(range(len(nodes)))}]
    doc["scene"] = 0
    doc["accessors"] = accessors
    doc["bufferViews"] = views
    while len(blob) % 4:
        blob.append(0)
    doc["buffers"] = [{"byteLength": len(blob)}]
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    with open(out, "wb") as fp:
        fp.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(blob)))
        fp.write(struct.pack("<II", len(js), 0x4E4F534A))
        fp.write(js)
        fp.write(struct.pack("<II", len(blob), 0x004E4942))
        fp.write(blob)


if __name__ == "__main__":
    main()
