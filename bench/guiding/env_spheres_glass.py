#!/usr/bin/python3
"""env-spheres with a glass sphere (issue 31 names "spheres (metal, glass) on a
ground under an HDR sky with a sun"; the built-in env-spheres has a diffuse
sphere where this one has clear glass, ior 1.5). Writes OUTDIR/spheres.obj and
.mtl (ground 20 x 20 m, Kd 0.5; four UV spheres of radius 0.6 at x = -2.1,
-0.7, 0.7, 2.1: glass, then metals 0.95 / 0.9 / 0.8 of roughness 0.05 / 0.2 /
0.5 through the MTL PBR keys Pm/Pr), imports them with the env-spheres map
and adds env-spheres' camera: OUTDIR/esg.json. docs/benchmarks.md, "The window
rooms and the spheres at the present build", has the run beside Cycles.

usage: bench/guiding/env_spheres_glass.py IRIS OUTDIR SHARED_DIR
  e.g. bench/guiding/env_spheres_glass.py build/tools/iris /tmp/esg ../shared
"""
import json
import math
import os
import subprocess
import sys


def write_obj(path_obj, path_mtl):
    with open(path_mtl, "w") as mtl:
        mtl.write("newmtl ground\nKd 0.5 0.5 0.5\n\n")
        mtl.write("newmtl glass\nKd 1 1 1\nNi 1.5\nillum 7\n\n")
        for name, c, r in (("metal05", 0.95, 0.05), ("metal20", 0.9, 0.2), ("metal50", 0.8, 0.5)):
            mtl.write(f"newmtl {name}\nKd {c} {c} {c}\nPm 1\nPr {r}\n\n")
    with open(path_obj, "w") as out:
        out.write(f"mtllib {os.path.basename(path_mtl)}\no ground\nusemtl ground\n")
        for x, z in ((-10, -10), (10, -10), (10, 10), (-10, 10)):
            out.write(f"v {x} 0 {z}\nvn 0 1 0\n")
        out.write("f 1//1 4//4 3//3\nf 1//1 3//3 2//2\n")
        v, nu, nv, radius = 5, 96, 48, 0.6
        for cx, mat in ((-2.1, "glass"), (-0.7, "metal05"), (0.7, "metal20"), (2.1, "metal50")):
            out.write(f"o sphere_{mat}\nusemtl {mat}\n")
            for j in range(nv + 1):
                th = math.pi * j / nv
                for i in range(nu):
                    ph = 2 * math.pi * i / nu
                    n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
                    out.write(f"v {cx + radius * n[0]:.6f} {0.6 + radius * n[1]:.6f} {radius * n[2]:.6f}\n"
                              f"vn {n[0]:.6f} {n[1]:.6f} {n[2]:.6f}\n")

            def idx(j, i, base=v):
                return base + j * nu + (i % nu)

            # counter-clockwise seen from outside: the glass's front faces out
            for j in range(nv):
                for i in range(nu):
                    a, b, c, d = idx(j, i), idx(j, i + 1), idx(j + 1, i + 1), idx(j + 1, i)
                    if j != 0:
                        out.write(f"f {a}//{a} {b}//{b} {c}//{c}\n")
                    if j != nv - 1:
                        out.write(f"f {a}//{a} {c}//{c} {d}//{d}\n")
            v += (nv + 1) * nu


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    iris, outdir, shared = sys.argv[1:]
    env = os.path.join(shared, "assets", "env", "immenstadter_horn_1k.hdr")
    if not os.path.isfile(env):  # before anything is written
        sys.exit(f"env_spheres_glass.py: {env}: no such environment map (SHARED_DIR is the shared folder)")
    os.makedirs(outdir, exist_ok=True)
    obj, mtl, scene = (os.path.join(outdir, n) for n in ("spheres.obj", "spheres.mtl", "esg.json"))
    write_obj(obj, mtl)
    if subprocess.run([iris, "import", obj, "-o", scene, "--env", env]).returncode != 0:
        for f in (obj, mtl):
            os.remove(f)
        sys.exit(f"env_spheres_glass.py: {iris} import failed (its message above); nothing written")
    with open(scene) as f:
        s = json.load(f)
    s["cameras"] = [{"name": "camera", "position": [0, 1.4, 6.5], "target": [0, 0.7, 0], "up": [0, 1, 0],
                     "yfov_deg": 35, "aspect": 1.5}]
    with open(scene, "w") as f:
        json.dump(s, f, indent=1)
    print(f"wrote {scene}")


if __name__ == "__main__":
    main()
