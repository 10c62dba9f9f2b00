"""iris against Blender 3.4's own glTF import + Cycles on the glass-lamp room
(bench/gltf/glass_lamp.py; docs/import-gltf.md, "A glass lamp lighting a room").

  blender -b --factory-startup --python-exit-code 1 -P bench/gltf/glass_lamp_compare.py -- \
      --iris build/tools/iris --out /tmp/lamp --width 160 --height 120 \
      --iris-spp 1024 --cycles-spp 1024 --threads 2 /tmp/lamp/lamp-base.gltf ...

For each file: `iris render FILE --camera view --method M` and Blender's importer
(numpy.bool restored) with the file's own glTF camera "view", no world (black), Cycles CPU,
64 bounces, no clamping, caustics on, box filter, no denoising. Pixels are classified by a
ray cast through each pixel centre in Blender's scene (first surface, whatever its alpha):
"lamp" (any lamp object), "shade" (stainedglass, grill, bulbs), "walls" (the room), "table". Prints per-channel means over the
whole image and each class and the ratios iris / Blender; writes OUT/NAME-compare.json.
An existing OUT/NAME-iris.exr or OUT/NAME-blender.exr is reused with --reuse.
"""
import json
import os
import subprocess
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from blender_gltf_compare import cycles_settings  # noqa: E402 (the fair-comparison settings)


def args():
    import argparse
    ap = argparse.ArgumentParser()
    ap.add_argument("--iris", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--height", type=int, default=120)
    ap.add_argument("--iris-spp", type=int, default=1024)
    ap.add_argument("--cycles-spp", type=int, default=1024)
    ap.add_argument("--method", default="mis")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--reuse", action="store_true")
    ap.add_argument("--skip-iris", action="store_true")
    ap.add_argument("--skip-blender", action="store_true")
    ap.add_argument("--backfaces", choices=("cycles", "iris"), default="cycles",
                    help="iris: give Blender's import iris's back faces (opaque materials black and "
                         "not emitting behind, transmissive ones not emitting behind)")
    ap.add_argument("--lambert-room", action="store_true",
                    help="Blender's room and table materials replaced by Diffuse BSDF (Lambert) of the "
                         "same colour; use with the lambert-room variant (specularFactor 0: iris's Lambert)")
    ap.add_argument("files", nargs="+")
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    return ap.parse_args(argv)


def render_iris(a, path, exr):
    if a.reuse and os.path.exists(exr) or a.skip_iris:
        return
    subprocess.run([a.iris, "render", path, "-o", exr, "--png", exr[:-4] + ".png", "--camera", "view",
                    "--spp", str(a.iris_spp), "--width", str(a.width), "--height", str(a.height),
                    "--threads", str(a.threads), "--method", a.method, "--max-depth", "64"],
                   check=True)


def import_blender(path):
    if not hasattr(np, "bool"):
        np.bool = bool  # Blender 3.4's glTF add-on uses np.bool (removed in numpy 1.24)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)
    sc = bpy.context.scene
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0, 0, 0, 1)
    bg.inputs["Strength"].default_value = 0.0
    sc.world = world
    cams = [o for o in sc.objects if o.type == "CAMERA"]
    cam = next((o for o in cams if o.data.name == "view" or o.name == "view"), cams[0])
    sc.camera = cam
    return sc, cam


def lambert_room():
    for m in bpy.data.materials:
        if m.name.startswith("room_") and m.use_nodes:
            nt = m.node_tree
            p = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
            out = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeOutputMaterial")
            d = nt.nodes.new("ShaderNodeBsdfDiffuse")
            d.inputs["Color"].default_value = p.inputs["Base Color"].default_value
            d.inputs["Roughness"].default_value = 0.0
            nt.links.new(d.outputs[0], out.inputs["Surface"])


def iris_backfaces():
    """Cycles emits from both faces of every surface; iris emits only from the front of a
    glTF material that is not doubleSided (both shade both faces of opaque surfaces alike).
    Rebuild that in Blender's imported materials: Emission Strength x (1 - Backfacing)."""
    for m in bpy.data.materials:
        if not m.use_nodes:
            continue
        nt = m.node_tree
        p = next((n for n in nt.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled"), None)
        if p is None:
            continue
        geo = nt.nodes.new("ShaderNodeNewGeometry")
        inv = nt.nodes.new("ShaderNodeMath")
        inv.operation = "SUBTRACT"
        inv.inputs[0].default_value = 1.0
        nt.links.new(geo.outputs["Backfacing"], inv.inputs[1])
        mul = nt.nodes.new("ShaderNodeMath")
        mul.operation = "MULTIPLY"
        mul.inputs[1].default_value = p.inputs["Emission Strength"].default_value
        nt.links.new(inv.outputs[0], mul.inputs[0])
        nt.links.new(mul.outputs[0], p.inputs["Emission Strength"])


def render_blender(a, sc, exr):
    if a.reuse and os.path.exists(exr) or a.skip_blender:
        return
    cycles_settings(sc, a.cycles_spp, a.threads, a.width, a.height, exr)
    bpy.ops.render.render(write_still=True)


SHADE = ("stainedglass", "grill", "bulbs")  # the lamp's emissive glass and what shines through it


def classes(a, sc, cam):
    """0 = nothing, 1 = the rest of the lamp, 2 = walls, 3 = table, 4 = shade (SHADE): the
    first surface through each pixel centre, whatever its alpha (geometry only, so the
    classes do not depend on either image's noise)."""
    from mathutils import Vector
    dg = bpy.context.evaluated_depsgraph_get()
    sc.render.resolution_x, sc.render.resolution_y = a.width, a.height
    frame = cam.data.view_frame(scene=sc)  # 4 corners in camera space (tr, br, bl, tl)
    tr, br, bl, tl = frame
    mw = cam.matrix_world
    o = mw.translation
    out = np.zeros((a.height, a.width), np.int8)
    for y in range(a.height):
        fy = (y + 0.5) / a.height
        for x in range(a.width):
            fx = (x + 0.5) / a.width
            p = tl + (tr - tl) * fx + (bl - tl) * fy
            d = (mw @ p - o).normalized()
            hit, _, _, _, ob, _ = sc.ray_cast(dg, o, d)
            if hit:
                n = ob.name.lower()
                out[y, x] = (2 if n.startswith("room") else 3 if n.startswith("table") else
                             4 if n.split(".")[0] in SHADE else 1)
    return out


def load(path, h, w):
    img = bpy.data.images.load(path, check_existing=False)
    px = np.array(img.pixels[:], dtype=np.float64).reshape(h, w, 4)[::-1, :, :3]
    bpy.data.images.remove(img)
    return px


def main():
    a = args()
    os.makedirs(a.out, exist_ok=True)
    f3 = lambda v: " ".join("%.4f" % x for x in v)
    rows = []
    for path in a.files:
        path = os.path.abspath(path)
        name = os.path.splitext(os.path.basename(path))[0]
        ie, be = (os.path.join(a.out, name + s) for s in ("-iris.exr", "-blender.exr"))
        render_iris(a, path, ie)
        sc, cam = import_blender(path)
        cls = classes(a, sc, cam)
        if a.lambert_room:
            lambert_room()
            be = be[:-4] + "-lambert.exr"
        if a.backfaces == "iris":
            iris_backfaces()
            be = be[:-4] + "-irisbf.exr"
        render_blender(a, sc, be)
        ia = load(ie, a.height, a.width) if os.path.exists(ie) else None
        ba = load(be, a.height, a.width) if os.path.exists(be) else None
        if ia is None:
            ia = ba
        if ba is None:  # one renderer only: its means, ratio 1
            ba = ia
        res = {"file": path, "iris_spp": a.iris_spp, "cycles_spp": a.cycles_spp, "method": a.method}
        for label, m in (("image", np.ones_like(cls, bool)), ("lamp", (cls == 1) | (cls == 4)),
                         ("shade", cls == 4), ("walls", cls == 2), ("table", cls == 3)):
            if not m.any():
                continue
            mi, mb = ia[m].mean(0), ba[m].mean(0)
            # relative standard error of each mean, from the spread of its pixels (an upper
            # bound: it counts the region's real variation as noise too)
            se = lambda img, mu: (img[m].std(0) / np.sqrt(m.sum()) / np.maximum(mu, 1e-12)).tolist()
            res[label] = {"share": float(m.mean()), "iris": mi.tolist(), "blender": mb.tolist(),
                          "ratio": (mi / np.maximum(mb, 1e-12)).tolist(), "iris_rel_se": se(ia, mi),
                          "blender_rel_se": se(ba, mb)}
        with open(os.path.join(a.out, name + "-compare.json"), "w") as f:
            json.dump(res, f, indent=1)
        line = "| %s |" % name + "".join(
            " %s / %s = %s |" % (f3(res[k]["iris"]), f3(res[k]["blender"]), f3(res[k]["ratio"]))
            for k in ("image", "lamp", "shade", "walls", "table") if k in res)
        line += " rel. s.e. walls iris %s, Blender %s |" % (
            " ".join("%.3f" % x for x in res["walls"]["iris_rel_se"]),
            " ".join("%.3f" % x for x in res["walls"]["blender_rel_se"])) if "walls" in res else ""
        rows.append(line)
        print(line)
        sys.stdout.flush()
    print("| file | image: iris / Blender = ratio R G B | lamp | shade (glass, grill, bulbs) | walls | table |")
    print("|---|---|---|---|---|---|")
    print("\n".join(rows))


main()
