"""Blender 3.4's own glTF import + Cycles on a forest from make_forest.py, as a
user would: import, an HDR sky, the file's camera, 64 spp (bench/instancing/forest.sh).

  blender -b --factory-startup --python-exit-code 1 -P bench/instancing/blender_forest.py -- \
      FOREST.glb SKY.hdr OUT.exr SPP WIDTH HEIGHT THREADS

Fair-comparison settings as iris's Blender exporter (box filter, no denoising, no
clamping, no adaptive sampling, 64 bounces). The sky is an Environment Texture
with default mapping: for a glTF that Blender imported, that is the direction
iris looks up (docs/format.md, "environment").
"""
import sys

import numpy

if not hasattr(numpy, "bool"):  # Blender 3.4's glTF add-on uses np.bool (../shared/reference/cycles-3.4.md)
    numpy.bool = bool
import bpy

glb, sky, out, spp, width, height, threads = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=glb)
sc = bpy.context.scene
cams = [o for o in sc.objects if o.type == "CAMERA"]
sc.camera = cams[0]
world = bpy.data.worlds.new("World")
world.use_nodes = True
nt = world.node_tree
tex = nt.nodes.new("ShaderNodeTexEnvironment")
tex.image = bpy.data.images.load(sky)
nt.links.new(tex.outputs["Color"], nt.nodes["Background"].inputs["Color"])
sc.world = world
r, c = sc.render, sc.cycles
r.engine = "CYCLES"
c.device = "CPU"
c.samples = int(spp)
c.use_adaptive_sampling = False
c.pixel_filter_type = "BOX"
for k in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces",
          "transparent_max_bounces"):
    setattr(c, k, 64)
c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
c.use_denoising = False
for vl in sc.view_layers:
    vl.cycles.use_denoising = False
r.threads_mode = "FIXED"
r.threads = int(threads)
r.resolution_x, r.resolution_y, r.resolution_percentage = int(width), int(height), 100
r.image_settings.file_format = "OPEN_EXR"
r.filepath = out
bpy.ops.render.render(write_still=True)
