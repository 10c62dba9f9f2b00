#!/usr/bin/python3
"""Rooms lit by the sky through openings the built-in sky-room does not have,
for the sky visibility's windows and the connections through them
(docs/guiding.md, "Sky visibility", "Connections with the sky through a
window"): each is sky-room's 4 x 2.5 x 4 m room, walls of Kd 0.75, a floor of
Kd 0.6 0.45 0.3, a diffuse box and sphere, the env-spheres map, but other
openings:

  two-windows  sky-room's 1.2 x 1 m window in the +x wall and a 1 x 1 m one
               in the -z wall
  skylight     no wall window; a 1 x 1 m opening in the ceiling
  open-wall    the +x wall open over 3 x 1.8 m
  two-sunny    two 1 x 1 m windows side by side in the +x wall (the sun's)
  corner-sunny 1 x 1 m windows in the +x and the +z wall, both facing the sun

Writes OUTDIR/VARIANT.obj, .mtl and .json (imported by IRIS with the map and
a camera in the corner by the +x wall, looking in).

usage: bench/guiding/sky_room_variants.py IRIS OUTDIR SHARED_DIR
"""
import json
import math
import os
import subprocess
import sys

X, Y, Z = 2.0, 2.5, 2.0
STEP = 0.1  # the walls are grids of STEP x STEP quads, an opening leaves its cells out

VARIANTS = {
    # wall -> list of openings (a0, a1, b0, b1) in the wall's own (a, b) coordinates
    "two-windows": {"+x": [(-0.6, 0.6, 1.0, 2.0)], "-z": [(-0.5, 0.5, 1.0, 2.0)]},
    "skylight": {"ceiling": [(-0.5, 0.5, -0.5, 0.5)]},
    "open-wall": {"+x": [(-1.5, 1.5, 0.3, 2.1)]},
    "two-sunny": {"+x": [(-1.5, -0.5, 1.0, 2.0), (0.5, 1.5, 1.0, 2.0)]},
    "corner-sunny": {"+x": [(0.5, 1.5, 1.0, 2.0)], "+z": [(-1.5, -0.5, 1.0, 2.0)]},
}


def wall_frame(name):
    """origin, a axis, b axis, a range, b range; the front face (a x b) faces into the room"""
    return {
        "floor": ((0, 0, 0), (1, 0, 0), (0, 0, -1), (-X, X), (-Z, Z)),
        "ceiling": ((0, Y, 0), (1, 0, 0), (0, 0, 1), (-X, X), (-Z, Z)),
        "+x": ((X, 0, 0), (0, 0, -1), (0, 1, 0), (-Z, Z), (0, Y)),
        "-x": ((-X, 0, 0), (0, 0, 1), (0, 1, 0), (-Z, Z), (0, Y)),
        "+z": ((0, 0, Z), (1, 0, 0), (0, 1, 0), (-X, X), (0, Y)),
        "-z": ((0, 0, -Z), (-1, 0, 0), (0, 1, 0), (-X, X), (0, Y)),
    }[name]


class Obj:
    def __init__(self):
        self.lines, self.v = [], 0

    def quad(self, p0, p1, p2, p3):
        for p in (p0, p1, p2, p3):
            self.lines.append("v %.5f %.5f %.5f" % p)
        b = self.v
        self.lines.append(f"f {b + 1} {b + 2} {b + 3}")
        self.lines.append(f"f {b + 1} {b + 3} {b + 4}")
        self.v += 4

    def wall(self, name, openings):
        o, a, b, (a0, a1), (b0, b1) = wall_frame(name)
        na, nb = round((a1 - a0) / STEP), round((b1 - b0) / STEP)

        def at(u, w):
            return tuple(o[k] + u * a[k] + w * b[k] for k in range(3))

        for i in range(na):
            for j in range(nb):
                u, w = a0 + (i + 0.5) * STEP, b0 + (j + 0.5) * STEP
                if any(p0 < u < p1 and q0 < w < q1 for p0, p1, q0, q1 in openings):
                    continue
                ua, ub, wa, wb = a0 + i * STEP, a0 + (i + 1) * STEP, b0 + j * STEP, b0 + (j + 1) * STEP
                self.quad(at(ua, wa), at(ub, wa), at(ub, wb), at(ua, wb))

    def box(self, lo, hi):
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        c = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
             (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
        for f in ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)):
            self.quad(*(c[k] for k in f))

    def sphere(self, centre, r, nu=32, nv=16):
        for j in range(nv):
            for i in range(nu):
                def p(jj, ii):
                    th, ph = math.pi * jj / nv, 2 * math.pi * ii / nu
                    return (centre[0] + r * math.sin(th) * math.cos(ph), centre[1] + r * math.cos(th),
                            centre[2] + r * math.sin(th) * math.sin(ph))
                self.quad(p(j, i), p(j, i + 1), p(j + 1, i + 1), p(j + 1, i))


def write(outdir, variant, openings):
    obj, mtl = os.path.join(outdir, variant + ".obj"), os.path.join(outdir, variant + ".mtl")
    with open(mtl, "w") as f:
        f.write("newmtl wall\nKd 0.75 0.75 0.72\n\nnewmtl floor\nKd 0.6 0.45 0.3\n\n"
                "newmtl box\nKd 0.3 0.5 0.7\n\nnewmtl ball\nKd 0.8 0.8 0.8\n")
    o = Obj()
    o.lines.append(f"mtllib {os.path.basename(mtl)}")
    for name in ("floor", "ceiling", "+x", "-x", "+z", "-z"):
        o.lines.append(f"o {name}\nusemtl {'floor' if name == 'floor' else 'wall'}")
        o.wall(name, openings.get(name, []))
    o.lines.append("o box\nusemtl box")
    o.box((-1.0, 0.0, 0.6), (-0.6, 0.6, 1.4))
    o.lines.append("o ball\nusemtl ball")
    o.sphere((-0.8, 0.5, -0.9), 0.5)
    with open(obj, "w") as f:
        f.write("\n".join(o.lines) + "\n")
    return obj, mtl


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    iris, outdir, shared = sys.argv[1:]
    env = os.path.join(shared, "assets", "env", "immenstadter_horn_1k.hdr")
    if not os.path.isfile(env):
        sys.exit(f"sky_room_variants.py: {env}: no such environment map (SHARED_DIR is the shared folder)")
    os.makedirs(outdir, exist_ok=True)
    for variant, openings in VARIANTS.items():
        obj, mtl = write(outdir, variant, openings)
        scene = os.path.join(outdir, variant + ".json")
        if subprocess.run([iris, "import", obj, "-o", scene, "--env", env]).returncode != 0:
            sys.exit(f"sky_room_variants.py: {iris} import {obj} failed (its message above)")
        with open(scene) as f:
            s = json.load(f)
        s["cameras"] = [{"name": "camera", "position": [1.8, 1.4, 1.8], "target": [-1.0, 0.6, -1.0],
                         "up": [0, 1, 0], "yfov_deg": 60, "aspect": 1.5}]
        with open(scene, "w") as f:
            json.dump(s, f, indent=1)
        print(f"wrote {scene}")


if __name__ == "__main__":
    main()
