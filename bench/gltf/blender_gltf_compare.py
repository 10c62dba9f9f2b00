"""iris against Blender 3.4's own glTF import, rendered by Cycles (docs/import-gltf.md,
"Agreement with Blender's glTF import").

Run with Blender (its Python has bpy and numpy):
  blender -b --factory-startup --python-exit-code 1 -P bench/gltf/blender_gltf_compare.py -- \
      --iris build/tools/iris --out OUT_DIR --spp 128 --size 160 --threads 2 MODEL.gltf...

For each model: `iris import` it, add a constant white sky (environment radiance 1, the
"white sky" of the issue; HDR maps follow with the environment-map work) and a camera
framing the model's bounds from +Z (glTF's front), `iris render` it (mis); then import the
same file with bpy.ops.import_scene.gltf (numpy.bool restored first, as
../shared/reference/cycles-3.4.md says), give Cycles the same camera, a white world of
strength 1 and the fair-comparison settings of iris's Blender exporter (box filter, no
denoising or clamping, 64 bounces, caustics on), render, and compare: mean per channel
(relative difference) and the 8x8 block means (largest relative block difference among
blocks brighter than 5% of the image mean). Writes OUT_DIR/<model>-compare.json (and the scene OUT_DIR/<model>.json) and prints a
table row per model.
"""
import json
import math
import os
import subprocess
import sys

import bpy
import numpy as np


def args():
    import argparse
    ap = argparse.ArgumentParser()
    ap.add_argument("--iris", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--spp", type=int, default=128)
    ap.add_argument("--size", type=int, default=160)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("models", nargs="+")
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    return ap.parse_args(argv)


def camera_for(lo, hi, yfov):
    """A camera on +Z (glTF) looking at the bounds' centre, far enough that the
    bounding sphere fits the vertical field of view."""
    c = [(a + b) / 2 for a, b in zip(lo, hi)]
    r = 0.5 * math.sqrt(sum((b - a) ** 2 for a, b in zip(lo, hi)))
    d = r / math.sin(yfov / 2) * 1.02
    eye = [c[0], c[1] + 0.25 * d, c[2] + d]  # a little from above, as a viewer would
    return c, eye


def render_iris(a, model, work):
    name = os.path.splitext(os.path.basename(model))[0]
    js = os.path.join(work, name + ".json")
    subprocess.run([a.iris, "import", model, "-o", js, "--quiet"], check=True)
    info = json.loads(subprocess.run([a.iris, "info", js, "--json"], check=True, capture_output=True).stdout)
    lo, hi = info["bounds"]["min"], info["bounds"]["max"]
    yfov = math.radians(40.0)
    target, eye = camera_for(lo, hi, yfov)
    with open(js) as f:
        scene = json.load(f)
    scene["environment"] = {"radiance": [1, 1, 1]}
    scene["cameras"] = [{"name": "compare", "position": eye, "target": target, "up": [0, 1, 0],
                         "yfov_deg": 40.0, "aspect": 1}]
    with open(js, "w") as f:
        json.dump(scene, f, indent=1)
    exr = os.path.join(work, name + "-iris.exr")
    subprocess.run([a.iris, "render", js, "-o", exr, "--png", os.path.join(work, name + "-iris.png"),
                    "--spp", str(a.spp), "--width", str(a.size), "--height", str(a.size), "--threads",
                    str(a.threads), "--method", "mis", "--quiet", "--camera", "compare"], check=True)
    return exr, eye, target, yfov


def gltf_to_blender(p):
    return (p[0], -p[2], p[1])  # the add-on's +Y-up -> +Z-up


def cycles_settings(sc, spp, threads, width, height, exr):
    """The fair-comparison Cycles settings (docs/export.md): CPU, fixed spp, seed 1, box filter,
    64 bounces of every kind, no clamping, caustics, no denoising, Standard view, a 32-bit
    RGB EXR at `exr`. Also used by glass_lamp_compare.py."""
    r, c = sc.render, sc.cycles
    r.engine = "CYCLES"
    c.device = "CPU"
    c.feature_set = "SUPPORTED"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.seed = 1
    c.pixel_filter_type = "BOX"
    for k in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
              "volume_bounces", "transparent_max_bounces"):
        setattr(c, k, 64)
    c.min_light_bounces = 0
    c.light_sampling_threshold = 0.0
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    c.use_fast_gi = False
    c.use_denoising = False
    for vl in sc.view_layers:
        vl.cycles.use_denoising = False
    sc.view_settings.view_transform = "Standard"
    r.threads_mode = "FIXED"
    r.threads = threads
    r.resolution_x, r.resolution_y = width, height
    r.resolution_percentage = 100
    r.film_transparent = False
    st = r.image_settings
    st.file_format = "OPEN_EXR"
    st.color_depth = "32"
    st.color_mode = "RGB"
    r.filepath = exr


def render_blender(a, model, work, eye, target, yfov):
    if not hasattr(np, "bool"):
        np.bool = bool  # Blender 3.4's glTF add-on uses np.bool (removed in numpy 1.24)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=model)
    sc = bpy.context.scene
    world = bpy.data.worlds.new("white")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (1, 1, 1, 1)
    bg.inputs["Strength"].default_value = 1.0
    sc.world = world
    cam_data = bpy.data.cameras.new("compare")
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = yfov
    cam = bpy.data.objects.new("compare", cam_data)
    sc.collection.objects.link(cam)
    from mathutils import Vector
    e, t = Vector(gltf_to_blender(eye)), Vector(gltf_to_blender(target))
    cam.location = e
    cam.rotation_euler = (t - e).to_track_quat("-Z", "Z").to_euler()
    sc.camera = cam
    name = os.path.splitext(os.path.basename(model))[0]
    exr = os.path.join(work, name + "-blender.exr")
    cycles_settings(sc, a.spp, a.threads, a.size, a.size, exr)
    bpy.ops.render.render(write_still=True)
    return exr


def load(path, size):
    img = bpy.data.images.load(path, check_existing=False)
    px = np.array(img.pixels[:], dtype=np.float64).reshape(size, size, 4)[::-1, :, :3]
    bpy.data.images.remove(img)
    return px


def compare(ia, ba):
    mi, mb = ia.reshape(-1, 3).mean(0), ba.reshape(-1, 3).mean(0)
    rel = (mi - mb) / np.maximum(mb, 1e-12)
    n = ia.shape[0] // 8
    bi = ia[:8 * n, :8 * n].reshape(8, n, 8, n, 3).mean((1, 3))
    bb = ba[:8 * n, :8 * n].reshape(8, n, 8, n, 3).mean((1, 3))
    lum_i, lum_b = bi.mean(2), bb.mean(2)
    bright = lum_b > 0.05 * lum_b.mean()
    brel = np.abs(lum_i - lum_b) / np.maximum(lum_b, 1e-12)
    worst = np.unravel_index(np.argmax(np.where(bright, brel, 0)), brel.shape)
    # the model's own pixels: where either image differs from the white sky
    obj = (np.abs(ia - 1.0).max(2) > 1e-3) | (np.abs(ba - 1.0).max(2) > 1e-3)
    oi, ob = ia[obj].mean(0), ba[obj].mean(0)
    return {"iris_mean": mi.tolist(), "blender_mean": mb.tolist(), "rel_mean": rel.tolist(),
            "object_fraction": float(obj.mean()), "iris_object_mean": oi.tolist(),
            "blender_object_mean": ob.tolist(), "rel_object_mean": ((oi - ob) / np.maximum(ob, 1e-12)).tolist(),
            "block_max_rel": float(brel[bright].max()) if bright.any() else 0.0,
            "block_median_rel": float(np.median(brel[bright])) if bright.any() else 0.0,
            "worst_block": [int(worst[0]), int(worst[1])]}


def main():
    a = args()
    os.makedirs(a.out, exist_ok=True)
    print("| model | iris mean R G B | Blender mean R G B | rel. diff R G B | model pixels: share, rel. diff R G B | 8x8 blocks: median, max rel. diff |")
    print("|---|---|---|---|---|---|")
    for model in a.models:
        model = os.path.abspath(model)
        ie, eye, target, yfov = render_iris(a, model, a.out)
        be = render_blender(a, model, a.out, eye, target, yfov)
        res = compare(load(ie, a.size), load(be, a.size))
        res.update({"model": model, "spp": a.spp, "size": a.size})
        name = os.path.splitext(os.path.basename(model))[0]
        with open(os.path.join(a.out, name + "-compare.json"), "w") as f:  # (name.json is the iris scene)
            json.dump(res, f, indent=1)
        f3 = lambda v: " ".join("%.4f" % x for x in v)
        pct = lambda v: " ".join("%+.1f%%" % (100 * x) for x in v)
        print("| %s | %s | %s | %s | %.0f%%, %s | %.3f, %.3f |" % (
            name, f3(res["iris_mean"]), f3(res["blender_mean"]), pct(res["rel_mean"]),
            100 * res["object_fraction"], pct(res["rel_object_mean"]), res["block_median_rel"],
            res["block_max_rel"]))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
