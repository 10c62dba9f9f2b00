#!/usr/bin/python3
"""A Tiffany-style lamp as an artist would hand it over: one glTF 2.0 file
(issue 31 names "a Tiffany lamp lit by its own bulbs through the stained glass
shade, in a dark room"; the built-in lamp-shade is a box of iris glass slabs).
Here the shade is a dome of stained glass tiles in four colours, each tile a
closed 3 mm shell (outer, inner and side faces), as glTF
materials with KHR_materials_transmission (1), KHR_materials_ior (1.5) and
KHR_materials_volume (thickness 3 mm), the colour in baseColorFactor as the
specification tints transmitted light; three 2 cm bulbs
(KHR_materials_emissive_strength) hang inside it, open below over a table, on
a bronze stem, in a 4 x 3 x 4 m room of grey walls and no other light.
Blender's glTF importer reads every one of these extensions.

usage: bench/guiding/tiffany_lamp.py OUT.gltf [ROUGHNESS [single]]
  ROUGHNESS: the glass tiles' roughness (default 0: clear glass)
  single: each tile one surface (its outer face) instead of a closed shell, as
          a shade is often modelled (every ray through it refracts once)
Then `iris import OUT.gltf -o DIR/tiffany.json` and render or bench that.
docs/benchmarks.md, "A Tiffany lamp from glTF", has the run beside Cycles.
"""
import base64
import json
import math
import struct
import sys


class Builder:
    def __init__(self):
        self.bin = bytearray()
        self.accessors, self.views, self.meshes, self.nodes = [], [], [], []

    def _view(self, data, target):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.views.append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data), "target": target})
        self.bin += data
        return len(self.views) - 1

    def primitive(self, pos, nrm, tris, material):
        """pos, nrm: lists of 3-tuples; tris: list of index triples (counter-clockwise seen from the normals)."""
        pv = self._view(b"".join(struct.pack("<3f", *p) for p in pos), 34962)
        nv = self._view(b"".join(struct.pack("<3f", *n) for n in nrm), 34962)
        iv = self._view(b"".join(struct.pack("<3I", *t) for t in tris), 34963)
        lo = [min(p[k] for p in pos) for k in range(3)]
        hi = [max(p[k] for p in pos) for k in range(3)]
        self.accessors += [
            {"bufferView": pv, "componentType": 5126, "count": len(pos), "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": nv, "componentType": 5126, "count": len(nrm), "type": "VEC3"},
            {"bufferView": iv, "componentType": 5125, "count": 3 * len(tris), "type": "SCALAR"},
        ]
        a = len(self.accessors) - 3
        return {"attributes": {"POSITION": a, "NORMAL": a + 1}, "indices": a + 2, "material": material}

    def mesh(self, name, prims):
        self.meshes.append({"name": name, "primitives": prims})
        self.nodes.append({"name": name, "mesh": len(self.meshes) - 1})


def quad(b, c, u, v, mat):
    """The rectangle c +- u +- v, its normal u x v."""
    n = cross(u, v)
    ln = math.sqrt(dot(n, n))
    n = tuple(x / ln for x in n)
    pts = [add(c, add(scale(u, su), scale(v, sv))) for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return b.primitive(pts, [n] * 4, [(0, 1, 2), (0, 2, 3)], mat)


def box(b, c, h, mat):
    X, Y, Z = (h[0], 0, 0), (0, h[1], 0), (0, 0, h[2])
    faces = [(X, Y, Z), (scale(X, -1), Z, Y), (Y, Z, X), (scale(Y, -1), X, Z), (Z, X, Y), (scale(Z, -1), Y, X)]
    return [quad(b, add(c, f), u, v, mat) for f, u, v in faces]


def cylinder(b, c, r, y0, y1, mat, n=48):
    pos, nrm, tris = [], [], []
    for i in range(n + 1):
        ph = 2 * math.pi * i / n
        d = (math.cos(ph), 0.0, math.sin(ph))
        pos += [(c[0] + r * d[0], y0, c[2] + r * d[2]), (c[0] + r * d[0], y1, c[2] + r * d[2])]
        nrm += [d, d]
    for i in range(n):
        a = 2 * i
        tris += [(a, a + 1, a + 3), (a, a + 3, a + 2)]
    prims = [b.primitive(pos, nrm, tris, mat)]
    # caps
    for y, up in ((y1, 1.0), (y0, -1.0)):
        cp = [(c[0], y, c[2])] + [(c[0] + r * math.cos(2 * math.pi * i / n), y, c[2] + r * math.sin(2 * math.pi * i / n)) for i in range(n)]
        ct = [(0, 1 + (i + 1) % n, 1 + i) if up > 0 else (0, 1 + i, 1 + (i + 1) % n) for i in range(n)]
        prims.append(b.primitive(cp, [(0.0, up, 0.0)] * len(cp), ct, mat))
    return prims


def sphere(b, c, r, mat, nu=24, nv=12):
    pos, nrm, tris = [], [], []
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu + 1):
            ph = 2 * math.pi * i / nu
            d = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            pos.append(add(c, scale(d, r)))
            nrm.append(d)
    for j in range(nv):
        for i in range(nu):
            a, bb = j * (nu + 1) + i, (j + 1) * (nu + 1) + i
            if j:
                tris.append((a, a + 1, bb + 1))
            if j != nv - 1:
                tris.append((a, bb + 1, bb))
    return b.primitive(pos, nrm, tris, mat)


def tile(b, centre, R, t, th0, th1, ph0, ph1, single, mat, m=6):
    """One tile of the dome: the sphere shell between radii R - t and R over
    polar [th0, th1] and azimuth [ph0, ph1], closed on all four sides, normals
    out of the glass."""
    pos, nrm, tris = [], [], []

    def d_of(th, ph):
        return (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))

    def grid(radius, sign):
        base = len(pos)
        for j in range(m + 1):
            th = th0 + (th1 - th0) * j / m
            for i in range(m + 1):
                ph = ph0 + (ph1 - ph0) * i / m
                d = d_of(th, ph)
                pos.append(add(centre, scale(d, radius)))
                nrm.append(scale(d, sign))
        for j in range(m):
            for i in range(m):
                a, c = base + j * (m + 1) + i, base + (j + 1) * (m + 1) + i
                # with d outward, (th, ph) increasing is counter-clockwise seen
                # from outside (y up: ph turns from +x to +z)
                tri = [(a, a + 1, c + 1), (a, c + 1, c)]
                if sign < 0:
                    tri = [(x, z, y) for x, y, z in tri]
                tris.extend(tri)

    grid(R, 1.0)
    if single:
        return b.primitive(pos, nrm, tris, mat)
    grid(R - t, -1.0)

    def side(points_out, points_in, n):
        base = len(pos)
        k = len(points_out)
        pos.extend(points_out + points_in)
        nrm.extend([n] * (2 * k))
        for i in range(k - 1):
            tris.extend([(base + i, base + i + 1, base + k + i + 1), (base + i, base + k + i + 1, base + k + i)])

    # the four sides, flat strips whose normals point away from the tile's
    # middle (tiles sit edge to edge: only the rim and the top show them)
    mid = add(centre, scale(d_of(0.5 * (th0 + th1), 0.5 * (ph0 + ph1)), R - 0.5 * t))
    for which in ("th0", "th1", "ph0", "ph1"):
        if which == "th0" and th0 == 0.0:
            continue  # the apex: the strip is a point
        pts_o, pts_i = [], []
        for s in range(m + 1):
            f = s / m
            if which in ("th0", "th1"):
                th, ph = (th0 if which == "th0" else th1), ph0 + (ph1 - ph0) * f
            else:
                th, ph = th0 + (th1 - th0) * f, (ph0 if which == "ph0" else ph1)
            d = d_of(th, ph)
            pts_o.append(add(centre, scale(d, R)))
            pts_i.append(add(centre, scale(d, R - t)))
        e1, e2 = sub(pts_o[-1], pts_o[0]), sub(pts_i[0], pts_o[0])
        n = cross(e1, e2)
        smid = scale(add(pts_o[m // 2], pts_i[m // 2]), 0.5)
        if dot(n, sub(smid, mid)) < 0:
            n = scale(n, -1.0)
            pts_o, pts_i = pts_i, pts_o  # the winding follows n
        ln = math.sqrt(dot(n, n))
        side(pts_o, pts_i, scale(n, 1.0 / ln))
    return b.primitive(pos, nrm, tris, mat)


def add(a, c):
    return (a[0] + c[0], a[1] + c[1], a[2] + c[2])


def sub(a, c):
    return (a[0] - c[0], a[1] - c[1], a[2] - c[2])


def scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, c):
    return a[0] * c[0] + a[1] * c[1] + a[2] * c[2]


def cross(a, c):
    return (a[1] * c[2] - a[2] * c[1], a[2] * c[0] - a[0] * c[2], a[0] * c[1] - a[1] * c[0])


def main():
    if len(sys.argv) not in (2, 3, 4) or (len(sys.argv) == 4 and sys.argv[3] != "single"):
        sys.exit(__doc__)
    out = sys.argv[1]
    rough = float(sys.argv[2]) if len(sys.argv) >= 3 else 0.0
    single = len(sys.argv) == 4
    glass_colours = {"amber": (0.95, 0.65, 0.25), "green": (0.45, 0.8, 0.35), "red": (0.9, 0.3, 0.25),
                     "blue": (0.35, 0.55, 0.9)}
    materials = [
        {"name": "wall", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.58, 1], "metallicFactor": 0, "roughnessFactor": 1}},
        {"name": "wood", "pbrMetallicRoughness": {"baseColorFactor": [0.35, 0.2, 0.1, 1], "metallicFactor": 0, "roughnessFactor": 0.6}},
        {"name": "bronze", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.45, 0.25, 1], "metallicFactor": 1, "roughnessFactor": 0.35}},
        {"name": "bulb", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 1},
         "emissiveFactor": [1.0, 0.85, 0.6], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 300.0}}},
    ]
    glass = {}
    for name, c in glass_colours.items():
        glass[name] = len(materials)
        materials.append({"name": "glass-" + name,
                          "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1], "metallicFactor": 0, "roughnessFactor": rough},
                          "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                         "KHR_materials_ior": {"ior": 1.5}}})
        if not single:  # a closed shell is a volume; one surface is thin-walled
            materials[-1]["extensions"]["KHR_materials_volume"] = {"thicknessFactor": 0.003}
    b = Builder()
    X, Y, Z = 2.0, 3.0, 2.0
    room = [quad(b, (0, 0, 0), (0, 0, Z), (X, 0, 0), 0), quad(b, (0, Y, 0), (X, 0, 0), (0, 0, Z), 0),
            quad(b, (-X, Y / 2, 0), (0, Y / 2, 0), (0, 0, Z), 0), quad(b, (X, Y / 2, 0), (0, 0, Z), (0, Y / 2, 0), 0),
            quad(b, (0, Y / 2, -Z), (X, 0, 0), (0, Y / 2, 0), 0), quad(b, (0, Y / 2, Z), (0, Y / 2, 0), (X, 0, 0), 0)]
    b.mesh("room", room)
    table = box(b, (0, 0.73, 0), (0.6, 0.02, 0.4), 1)
    for lx in (-0.55, 0.55):
        for lz in (-0.35, 0.35):
            table += box(b, (lx, 0.355, lz), (0.025, 0.355, 0.025), 1)
    b.mesh("table", table)
    b.mesh("stand", cylinder(b, (0, 0, 0), 0.09, 0.75, 0.77, 2) + cylinder(b, (0, 0, 0), 0.012, 0.77, 1.30, 2))
    centre, R, t, thmax = (0.0, 1.12, 0.0), 0.3, 0.003, math.radians(68)
    names = list(glass_colours)
    shade = []
    bands, sectors = 3, 12
    for j in range(bands):
        th0, th1 = thmax * j / bands, thmax * (j + 1) / bands
        for i in range(sectors):
            ph0, ph1 = 2 * math.pi * i / sectors, 2 * math.pi * (i + 1) / sectors
            shade.append(tile(b, centre, R, t, th0, th1, ph0, ph1, single, glass[names[(i + j) % 4]]))
    b.mesh("shade", shade)
    bulbs = [sphere(b, (0.06 * math.cos(a), 1.24, 0.06 * math.sin(a)), 0.02, 3)
             for a in (0.0, 2 * math.pi / 3, 4 * math.pi / 3)]
    b.mesh("bulbs", bulbs)
    # camera: a node at (1.7, 1.45, 1.9) looking at (0, 1.0, 0) (glTF cameras look down -z)
    eye, at = (1.7, 1.45, 1.9), (0.0, 1.0, 0.0)
    f = sub(at, eye)
    lf = math.sqrt(dot(f, f))
    f = scale(f, 1 / lf)
    r = cross(f, (0, 1, 0))
    lr = math.sqrt(dot(r, r))
    r = scale(r, 1 / lr)
    u = cross(r, f)
    zc = scale(f, -1)
    m = [r[0], r[1], r[2], 0, u[0], u[1], u[2], 0, zc[0], zc[1], zc[2], 0, eye[0], eye[1], eye[2], 1]
    b.nodes.append({"name": "camera", "camera": 0, "matrix": m})
    doc = {
        "asset": {"version": "2.0", "generator": "iris bench/guiding/tiffany_lamp.py"},
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume",
                           "KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": list(range(len(b.nodes)))}],
        "nodes": b.nodes,
        "meshes": b.meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": math.radians(50), "aspectRatio": 1.5,
                                                            "znear": 0.05, "zfar": 100}}],
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": len(b.bin),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(b.bin)).decode()}],
    }
    with open(out, "w") as fh:
        json.dump(doc, fh)


if __name__ == "__main__":
    main()
