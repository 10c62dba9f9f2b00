/* Blender 3.4 exporter (exporters/blender.h, docs/export.md); the script for
 * Blender's own glTF importer is in blender_import.c.
 * The script is a fixed Python prelude (the functions that build a scene from
 * plain data tables and set the fair-comparison Cycles settings) followed by
 * the data tables of this scene and a call to main(). Mesh arrays are stored
 * once, little-endian, in a sidecar file (or a base64 blob in the script) and
 * read with numpy + foreach_set, the fast path for large meshes. */
#define _DEFAULT_SOURCE /* realpath */
#include "exporters/blender.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/log.h"
#include "exporters/blender_script.h"

/* clang-format off */
static const char *const PRELUDE[] = {
/* BEGIN PRELUDE */
    "import argparse",
    "import base64",
    "import math",
    "import os",
    "import sys",
    "import time",
    "",
    "import bpy",
    "import numpy as np",
    "from mathutils import Matrix, Vector",
    "",
    "HERE = os.path.dirname(os.path.abspath(__file__))",
    "",
    "",
    "def text(b):",
    "    return b.decode(\"utf-8\", \"replace\")",
    "",
    "",
    "def parse_args():",
    "    argv = sys.argv[sys.argv.index(\"--\") + 1:] if \"--\" in sys.argv else []",
    "    ap = argparse.ArgumentParser(prog=\"blender -b --factory-startup --python-exit-code 1 -P scene.py --\")",
    "    ap.add_argument(\"--output\", required=True, help=\"EXR file to write (float32 RGB)\")",
    "    ap.add_argument(\"--spp\", type=int, default=SETTINGS[\"spp\"])",
    "    ap.add_argument(\"--threads\", type=int, default=os.cpu_count() or 1)",
    "    ap.add_argument(\"--seed\", type=int, default=SETTINGS[\"seed\"])",
    "    ap.add_argument(\"--width\", type=int, default=SETTINGS[\"width\"])",
    "    ap.add_argument(\"--height\", type=int, default=SETTINGS[\"height\"])",
    "    ap.add_argument(\"--max-bounces\", type=int, default=SETTINGS[\"max_depth\"])",
    "    ap.add_argument(\"--adaptive-threshold\", type=float, default=0.0,",
    "                    help=\"Cycles' noise threshold (Blender's default 0.01); 0: fixed spp\")",
    "    ap.add_argument(\"--adaptive-min-samples\", type=int, default=0, help=\"0: automatic\")",
    "    ap.add_argument(\"--time-limit\", type=float, default=0.0, help=\"seconds; 0: none\")",
    "    ap.add_argument(\"--inventory\", default=None, help=\"JSON file: what Blender's glTF importer created\")",
    "    a = ap.parse_args(argv)",
    "    if a.spp < 1 or a.threads < 1 or a.width < 1 or a.height < 1 or a.max_bounces < 0:",
    "        ap.error(\"--spp, --threads, --width, --height must be >= 1 and --max-bounces >= 0\")",
    "    if not (a.adaptive_threshold >= 0 and a.time_limit >= 0 and a.adaptive_min_samples >= 0):",
    "        ap.error(\"--adaptive-threshold, --adaptive-min-samples and --time-limit must be >= 0\")",
    "    return a",
    "",
    "",
    "class MeshData:",
    "    \"\"\"Reads the arrays of one mesh from the sidecar file or the embedded blob.\"\"\"",
    "",
    "    def __init__(self):",
    "        if BLOB is not None:",
    "            self.buf = base64.b64decode(BLOB)",
    "        else:",
    "            with open(os.path.join(HERE, os.fsdecode(SIDECAR)), \"rb\") as f:",
    "                self.buf = f.read()",
    "",
    "    def array(self, offset, dtype, count):",
    "        if offset < 0:",
    "            return None",
    "        return np.frombuffer(self.buf, dtype=dtype, count=count, offset=offset)",
    "",
    "",
    "def build_mesh(data, m):",
    "    nv, nt = m[\"nv\"], m[\"nt\"]",
    "    pos = data.array(m[\"pos\"], \"<f4\", 3 * nv)",
    "    idx = data.array(m[\"idx\"], \"<u4\", 3 * nt).astype(np.int32)",
    "    me = bpy.data.meshes.new(text(m[\"name\"]))",
    "    me.vertices.add(nv)",
    "    me.vertices.foreach_set(\"co\", pos)",
    "    me.loops.add(3 * nt)",
    "    me.loops.foreach_set(\"vertex_index\", idx)",
    "    me.polygons.add(nt)",
    "    me.polygons.foreach_set(\"loop_start\", np.arange(0, 3 * nt, 3, dtype=np.int32))",
    "    me.polygons.foreach_set(\"loop_total\", np.full(nt, 3, dtype=np.int32))",
    "    uv = data.array(m[\"uv\"], \"<f4\", 2 * nv)",
    "    if uv is not None:",
    "        # iris (glTF) UVs have v down from the image's top; Blender's v goes up.",
    "        corner = uv.reshape(-1, 2)[idx].copy()",
    "        corner[:, 1] = 1.0 - corner[:, 1]",
    "        me.uv_layers.new(name=\"UVMap\").data.foreach_set(\"uv\", corner.ravel())",
    "    uv1 = data.array(m[\"uv1\"], \"<f4\", 2 * nv)",
    "    if uv1 is not None:  # glTF TEXCOORD_1",
    "        corner = uv1.reshape(-1, 2)[idx].copy()",
    "        corner[:, 1] = 1.0 - corner[:, 1]",
    "        if uv is None:",
    "            me.uv_layers.new(name=\"UVMap\").data.foreach_set(\"uv\", corner.ravel())",
    "        me.uv_layers.new(name=\"UV1\").data.foreach_set(\"uv\", corner.ravel())",
    "    alpha = data.array(m[\"alpha\"], \"<f4\", nv)",
    "    if alpha is not None:  # glTF COLOR_0 alpha, read by the Attribute node \"Alpha\"",
    "        me.attributes.new(\"Alpha\", \"FLOAT\", \"POINT\").data.foreach_set(\"value\", alpha)",
    "    col = data.array(m[\"col\"], \"<f4\", 3 * nv)",
    "    if col is not None:",
    "        rgba = np.ones((nv, 4), dtype=np.float32)",
    "        rgba[:, :3] = col.reshape(-1, 3)",
    "        attr = me.color_attributes.new(\"Col\", \"FLOAT_COLOR\", \"POINT\")",
    "        attr.data.foreach_set(\"color\", rgba.ravel())",
    "    me.update(calc_edges=True)",
    "    if m[\"validate\"]:",
    "        me.validate(clean_customdata=False)",
    "    nrm = data.array(m[\"nrm\"], \"<f4\", 3 * nv)",
    "    if nrm is not None:",
    "        me.polygons.foreach_set(\"use_smooth\", np.ones(len(me.polygons), dtype=bool))",
    "        # Custom split normals cost seconds per million triangles; skip them",
    "        # when Blender's own smooth vertex normals are the same directions.",
    "        own = np.empty(3 * len(me.vertices), dtype=np.float32)",
    "        me.vertices.foreach_get(\"normal\", own)",
    "        if len(me.vertices) != nv or np.abs(own - nrm).max(initial=0.0) > 1e-3:",
    "            me.use_auto_smooth = True",
    "            me.auto_smooth_angle = math.pi",
    "            me.normals_split_custom_set_from_vertices(nrm.reshape(-1, 3))",
    "    if m[\"material\"] >= 0:",
    "        me.materials.append(MATERIAL_BLOCKS[m[\"material\"]])",
    "    return me",
    "",
    "",
    "# ---- materials ------------------------------------------------------------",
    "",
    "IMAGES = {}",
    "",
    "",
    "def image(tex_index, colorspace):",
    "    key = (tex_index, colorspace)",
    "    if key not in IMAGES:",
    "        path = os.fsdecode(TEXTURES[tex_index][\"path\"])",
    "        if not os.path.isabs(path):",
    "            path = os.path.join(HERE, path)",
    "        img = bpy.data.images.load(path, check_existing=False)",
    "        img.colorspace_settings.name = colorspace",
    "        # iris reads colour and alpha independently (glTF: straight alpha); Cycles",
    "        # would associate the colour with the alpha when the Alpha output is unused",
    "        img.alpha_mode = \"CHANNEL_PACKED\"",
    "        IMAGES[key] = img",
    "    return IMAGES[key]",
    "",
    "",
    "def uv_source(nt, t):",
    "    \"\"\"The texture's placement: its UV map, then its KHR_texture_transform as a",
    "    Mapping node (scale, rotate about Z, translate, in Blender's v-up UVs).\"\"\"",
    "    uvmap = nt.nodes.new(\"ShaderNodeUVMap\")",
    "    uvmap.uv_map = t[\"uv_map\"]",
    "    if t[\"xf\"] is None:",
    "        return uvmap.outputs[\"UV\"]",
    "    ox, oy, rot, sx, sy = t[\"xf\"]",
    "    mp = nt.nodes.new(\"ShaderNodeMapping\")",
    "    mp.vector_type = \"POINT\"",
    "    mp.inputs[\"Scale\"].default_value = (sx, sy, 1.0)",
    "    mp.inputs[\"Rotation\"].default_value = (0.0, 0.0, rot)",
    "    mp.inputs[\"Location\"].default_value = (ox + math.sin(rot) * sy, 1.0 - math.cos(rot) * sy - oy, 0.0)",
    "    nt.links.new(uvmap.outputs[\"UV\"], mp.inputs[\"Vector\"])",
    "    return mp.outputs[\"Vector\"]",
    "",
    "",
    "def texture_node(nt, tex_index, colorspace):",
    "    t = TEXTURES[tex_index]",
    "    node = nt.nodes.new(\"ShaderNodeTexImage\")",
    "    node.image = image(tex_index, colorspace)",
    "    node.interpolation = \"Closest\" if t[\"nearest\"] else \"Linear\"",
    "    ws, wt = t[\"wrap_s\"], t[\"wrap_t\"]",
    "    placed = t[\"uv_map\"] != \"UVMap\" or t[\"xf\"] is not None",
    "    if ws == wt and ws in (\"REPEAT\", \"CLAMP\"):",
    "        node.extension = \"REPEAT\" if ws == \"REPEAT\" else \"EXTEND\"",
    "        if placed:",
    "            nt.links.new(uv_source(nt, t), node.inputs[\"Vector\"])",
    "        return node",
    "    # Per-axis wrap modes (and mirror, which Blender 3.4's Image Texture lacks)",
    "    # are applied to the UVs, then the image is sampled with EXTEND.",
    "    node.extension = \"EXTEND\"",
    "    sep = nt.nodes.new(\"ShaderNodeSeparateXYZ\")",
    "    comb = nt.nodes.new(\"ShaderNodeCombineXYZ\")",
    "    nt.links.new(uv_source(nt, t), sep.inputs[0])",
    "    for axis, mode in ((\"X\", ws), (\"Y\", wt)):",
    "        if mode == \"CLAMP\":",
    "            nt.links.new(sep.outputs[axis], comb.inputs[axis])",
    "            continue",
    "        op = nt.nodes.new(\"ShaderNodeMath\")",
    "        if mode == \"REPEAT\":",
    "            op.operation = \"FRACT\"",
    "        else:",
    "            op.operation = \"PINGPONG\"",
    "            op.inputs[1].default_value = 1.0",
    "        nt.links.new(sep.outputs[axis], op.inputs[0])",
    "        nt.links.new(op.outputs[0], comb.inputs[axis])",
    "    nt.links.new(comb.outputs[0], node.inputs[\"Vector\"])",
    "    return node",
    "",
    "",
    "def multiply(nt, a, b):",
    "    \"\"\"Product of two colour sockets (no clamping).\"\"\"",
    "    node = nt.nodes.new(\"ShaderNodeMixRGB\")",
    "    node.blend_type = \"MULTIPLY\"",
    "    node.use_clamp = False",
    "    node.inputs[\"Fac\"].default_value = 1.0",
    "    nt.links.new(a, node.inputs[\"Color1\"])",
    "    nt.links.new(b, node.inputs[\"Color2\"])",
    "    return node.outputs[\"Color\"]",
    "",
    "",
    "def color_socket(nt, rgb, tex_index, vertex_colors):",
    "    \"\"\"Returns a socket for rgb x texture x vertex colour, or None when constant.\"\"\"",
    "    sock = None",
    "    if tex_index >= 0:",
    "        sock = texture_node(nt, tex_index, \"sRGB\").outputs[\"Color\"]",
    "    if vertex_colors:",
    "        vc = nt.nodes.new(\"ShaderNodeVertexColor\")",
    "        vc.layer_name = \"Col\"",
    "        sock = vc.outputs[\"Color\"] if sock is None else multiply(nt, sock, vc.outputs[\"Color\"])",
    "    if sock is None or tuple(rgb) == (1.0, 1.0, 1.0):",
    "        return sock",
    "    const = nt.nodes.new(\"ShaderNodeRGB\")",
    "    const.outputs[0].default_value = (*rgb, 1.0)",
    "    return multiply(nt, const.outputs[0], sock)",
    "",
    "",
    "def set_color(nt, socket, rgb, tex_index, vertex_colors):",
    "    s = color_socket(nt, rgb, tex_index, vertex_colors)",
    "    if s is None:",
    "        socket.default_value = (*rgb, 1.0)",
    "    else:",
    "        nt.links.new(s, socket)",
    "",
    "",
    "def scalar(nt, socket, value, from_socket):",
    "    \"\"\"socket = value x from_socket (or the constant value).\"\"\"",
    "    if from_socket is None:",
    "        socket.default_value = value",
    "        return",
    "    mul = nt.nodes.new(\"ShaderNodeMath\")",
    "    mul.operation = \"MULTIPLY\"",
    "    mul.inputs[1].default_value = value",
    "    nt.links.new(from_socket, mul.inputs[0])",
    "    nt.links.new(mul.outputs[0], socket)",
    "",
    "",
    "def math_node(nt, op, a, b=None, c=None):",
    "    \"\"\"Math node op(a, b, c); each input a constant or a socket. No clamping.\"\"\"",
    "    node = nt.nodes.new(\"ShaderNodeMath\")",
    "    node.operation = op",
    "    node.use_clamp = False",
    "    for i, v in enumerate((a, b, c)):",
    "        if v is None:",
    "            continue",
    "        if isinstance(v, (int, float)):",
    "            node.inputs[i].default_value = float(v)",
    "        else:",
    "            nt.links.new(v, node.inputs[i])",
    "    return node.outputs[0]",
    "",
    "",
    "def num_or_node(nt, op, a, b):",
    "    \"\"\"op(a, b) computed here when both are constants, else a Math node.\"\"\"",
    "    if isinstance(a, (int, float)) and isinstance(b, (int, float)):",
    "        return {\"MULTIPLY\": a * b, \"ADD\": a + b, \"SUBTRACT\": a - b, \"DIVIDE\": a / b if b else 0.0,",
    "                \"POWER\": a ** b, \"MAXIMUM\": max(a, b), \"MINIMUM\": min(a, b)}[op]",
    "    return math_node(nt, op, a, b)",
    "",
    "",
    "def set_or_link(nt, socket, v):",
    "    if isinstance(v, (int, float)):",
    "        socket.default_value = v",
    "    else:",
    "        nt.links.new(v, socket)",
    "",
    "",
    "def anisotropy(nt, bsdf, m, rough):",
    "    \"\"\"KHR_materials_anisotropy on Principled v1 (docs/export.md). Cycles 3.4 makes",
    "    alpha_x = r^2 / a along the Tangent turned by Anisotropic Rotation x 2 pi and",
    "    alpha_y = r^2 a, a = sqrt(1 - 0.9 Anisotropic); glTF wants alpha_t = mix(alpha, 1, s^2)",
    "    along its direction and alpha_b = alpha. Roughness r = (alpha_t alpha_b)^(1/4) and",
    "    Anisotropic = (1 - alpha_b / alpha_t) / 0.9 give both exactly up to alpha_t / alpha_b = 10.\"\"\"",
    "    s = m[\"aniso\"]",
    "    r = m[\"roughness\"] if rough is None else math_node(nt, \"MULTIPLY\", rough, m[\"roughness\"])",
    "    geo = nt.nodes.new(\"ShaderNodeNewGeometry\")",
    "    tan = nt.nodes.new(\"ShaderNodeTangent\")",
    "    tan.direction_type = \"UV_MAP\"",
    "    tan.uv_map = TEXTURES[m[\"aniso_tex\"]][\"uv_map\"] if m[\"aniso_tex\"] >= 0 else \"UVMap\"",
    "    t_sock = tan.outputs[\"Tangent\"]",
    "    if m[\"aniso_tex\"] >= 0:",
    "        sep = nt.nodes.new(\"ShaderNodeSeparateColor\")",
    "        nt.links.new(texture_node(nt, m[\"aniso_tex\"], \"Non-Color\").outputs[\"Color\"], sep.inputs[0])",
    "        s = math_node(nt, \"MULTIPLY\", sep.outputs[\"Blue\"], s)",
    "        # direction: T (2R - 1) + (N x T) (2G - 1), bitangent sign taken as +1",
    "        dx = math_node(nt, \"MULTIPLY_ADD\", sep.outputs[\"Red\"], 2.0, -1.0)",
    "        dy = math_node(nt, \"MULTIPLY_ADD\", sep.outputs[\"Green\"], 2.0, -1.0)",
    "        b = nt.nodes.new(\"ShaderNodeVectorMath\")",
    "        b.operation = \"CROSS_PRODUCT\"",
    "        nt.links.new(geo.outputs[\"Normal\"], b.inputs[0])",
    "        nt.links.new(t_sock, b.inputs[1])",
    "        parts = []",
    "        for vec, k in ((t_sock, dx), (b.outputs[\"Vector\"], dy)):",
    "            sc = nt.nodes.new(\"ShaderNodeVectorMath\")",
    "            sc.operation = \"SCALE\"",
    "            nt.links.new(vec, sc.inputs[0])",
    "            nt.links.new(k, sc.inputs[\"Scale\"])",
    "            parts.append(sc.outputs[\"Vector\"])",
    "        add = nt.nodes.new(\"ShaderNodeVectorMath\")",
    "        add.operation = \"ADD\"",
    "        nt.links.new(parts[0], add.inputs[0])",
    "        nt.links.new(parts[1], add.inputs[1])",
    "        t_sock = add.outputs[\"Vector\"]",
    "    nt.links.new(t_sock, bsdf.inputs[\"Tangent\"])",
    "    a = num_or_node(nt, \"MULTIPLY\", r, r)",
    "    at = num_or_node(nt, \"ADD\", a, num_or_node(nt, \"MULTIPLY\", num_or_node(nt, \"SUBTRACT\", 1.0, a),",
    "                                                 num_or_node(nt, \"MULTIPLY\", s, s)))",
    "    ab = num_or_node(nt, \"MAXIMUM\", a, 1e-3)",
    "    set_or_link(nt, bsdf.inputs[\"Roughness\"], num_or_node(nt, \"POWER\", num_or_node(nt, \"MULTIPLY\", at, ab), 0.25))",
    "    an = num_or_node(nt, \"DIVIDE\", num_or_node(nt, \"SUBTRACT\", 1.0, num_or_node(nt, \"DIVIDE\", ab, at)), 0.9)",
    "    set_or_link(nt, bsdf.inputs[\"Anisotropic\"], num_or_node(nt, \"MINIMUM\", num_or_node(nt, \"MAXIMUM\", an, 0.0), 1.0))",
    "    bsdf.inputs[\"Anisotropic Rotation\"].default_value = (m[\"aniso_rot\"] / (2.0 * math.pi)) % 1.0",
    "",
    "",
    "def rgb_socket(nt, v):",
    "    \"\"\"A colour socket for a constant (r, g, b), a scalar constant or a socket.\"\"\"",
    "    if isinstance(v, (int, float)):",
    "        v = (float(v),) * 3",
    "    if isinstance(v, tuple):",
    "        const = nt.nodes.new(\"ShaderNodeRGB\")",
    "        const.outputs[0].default_value = (*v, 1.0)",
    "        return const.outputs[0]",
    "    return v",
    "",
    "",
    "def mix_rgb(nt, blend, fac, a, b):",
    "    \"\"\"MixRGB blend (MIX: (1-fac) a + fac b; MULTIPLY with fac 1: a b), no clamp.\"\"\"",
    "    node = nt.nodes.new(\"ShaderNodeMixRGB\")",
    "    node.blend_type = blend",
    "    node.use_clamp = False",
    "    if isinstance(fac, (int, float)):",
    "        node.inputs[\"Fac\"].default_value = float(fac)",
    "    else:",
    "        nt.links.new(fac, node.inputs[\"Fac\"])",
    "    nt.links.new(rgb_socket(nt, a), node.inputs[\"Color1\"])",
    "    nt.links.new(rgb_socket(nt, b), node.inputs[\"Color2\"])",
    "    return node.outputs[\"Color\"]",
    "",
    "",
    "def link_or_set(nt, socket, v):",
    "    if isinstance(v, (int, float)):",
    "        socket.default_value = float(v)",
    "    elif isinstance(v, tuple):",
    "        socket.default_value = (*v, 1.0)",
    "    else:",
    "        nt.links.new(v, socket)",
    "",
    "",
    "def add_shaders(nt, shaders):",
    "    shader = shaders[0]",
    "    for s in shaders[1:]:",
    "        add = nt.nodes.new(\"ShaderNodeAddShader\")",
    "        nt.links.new(shader, add.inputs[0])",
    "        nt.links.new(s, add.inputs[1])",
    "        shader = add.outputs[0]",
    "    return shader",
    "",
    "",
    "def gltf_nodes(nt, m, vc, normal=None):",
    "    \"\"\"glTF metallic-roughness as iris renders it (docs/materials.md), from",
    "    Cycles closures: Diffuse (roughness 0) x (1-m)(1-T)(1 - w max Fr) + Glossy",
    "    GGX x [w (1-m) Fr + m F_m] + Refraction GGX x (1-m) T (1 - w max Fr) base.",
    "    The Schlick terms are built at N.V (Layer Weight Facing = 1 - |N.I|, to the",
    "    5th power): exact for mirrors (and for every Lambert), where glTF's V.H is",
    "    N.V; for rough lobes the residual is measured (docs/export.md).\"\"\"",
    "    base = color_socket(nt, m[\"color\"], m[\"color_tex\"], vc)",
    "    if base is None:",
    "        base = tuple(m[\"color\"])",
    "    metal = rough = None",
    "    if m[\"mr_tex\"] >= 0:",
    "        sep = nt.nodes.new(\"ShaderNodeSeparateColor\")",
    "        nt.links.new(texture_node(nt, m[\"mr_tex\"], \"Non-Color\").outputs[\"Color\"], sep.inputs[0])",
    "        metal = math_node(nt, \"MULTIPLY\", sep.outputs[\"Blue\"], m[\"metallic\"])",
    "        rough = math_node(nt, \"MULTIPLY\", sep.outputs[\"Green\"], m[\"roughness\"])",
    "    if metal is None:",
    "        metal = m[\"metallic\"]",
    "    if rough is None:",
    "        rough = m[\"roughness\"]",
    "    w, T, f0, ior = m[\"specular\"], m[\"transmission\"], m[\"f0\"], m[\"ior\"]",
    "    f0max = max(f0)",
    "    # KHR_materials_transmission / _specular textures, per point as in iris:",
    "    # T x texture R, w x texture A (linear), f0 = min(f0(ior) x colour x RGB (sRGB), 1)",
    "    Ts, ws = T, w",
    "    if m[\"trans_tex\"] >= 0 and T > 0.0:",
    "        sep = nt.nodes.new(\"ShaderNodeSeparateColor\")",
    "        nt.links.new(texture_node(nt, m[\"trans_tex\"], \"Non-Color\").outputs[\"Color\"], sep.inputs[0])",
    "        Ts = math_node(nt, \"MULTIPLY\", sep.outputs[\"Red\"], T)",
    "    if m[\"spec_tex\"] >= 0 and w > 0.0:",
    "        ws = math_node(nt, \"MULTIPLY\", texture_node(nt, m[\"spec_tex\"], \"Non-Color\").outputs[\"Alpha\"], w)",
    "    if m[\"spec_color_tex\"] >= 0:",
    "        f0u = tuple(m[\"f0_ior\"] * c for c in m[\"specular_color\"])",
    "        tex = texture_node(nt, m[\"spec_color_tex\"], \"sRGB\").outputs[\"Color\"]",
    "        mul = nt.nodes.new(\"ShaderNodeMixRGB\")",
    "        mul.blend_type = \"MULTIPLY\"",
    "        mul.use_clamp = True  # min(..., 1): every factor is >= 0",
    "        mul.inputs[\"Fac\"].default_value = 1.0",
    "        nt.links.new(rgb_socket(nt, f0u), mul.inputs[\"Color1\"])",
    "        nt.links.new(tex, mul.inputs[\"Color2\"])",
    "        f0 = mul.outputs[\"Color\"]",
    "        sep = nt.nodes.new(\"ShaderNodeSeparateColor\")",
    "        nt.links.new(f0, sep.inputs[0])",
    "        f0max = math_node(nt, \"MAXIMUM\", math_node(nt, \"MAXIMUM\", sep.outputs[\"Red\"], sep.outputs[\"Green\"]),",
    "                          sep.outputs[\"Blue\"])",
    "    else:",
    "        f0 = tuple(f0)",
    "    lw = nt.nodes.new(\"ShaderNodeLayerWeight\")",
    "    lw.inputs[\"Blend\"].default_value = 0.5",
    "    s = math_node(nt, \"POWER\", lw.outputs[\"Facing\"], 5.0)  # (1 - N.V)^5",
    "    if isinstance(f0max, float):",
    "        fr_max = math_node(nt, \"MULTIPLY_ADD\", s, 1.0 - f0max, f0max)",
    "    else:",
    "        fr_max = math_node(nt, \"MULTIPLY_ADD\", s, math_node(nt, \"SUBTRACT\", 1.0, f0max), f0max)",
    "    neg_w = -ws if isinstance(ws, float) else math_node(nt, \"MULTIPLY\", ws, -1.0)",
    "    base_w = math_node(nt, \"MAXIMUM\", math_node(nt, \"MULTIPLY_ADD\", fr_max, neg_w, 1.0), 0.0)",
    "    one_minus_m = (1.0 - metal) if isinstance(metal, float) else math_node(nt, \"SUBTRACT\", 1.0, metal)",
    "    one_minus_T = (1.0 - Ts) if isinstance(Ts, float) else math_node(nt, \"SUBTRACT\", 1.0, Ts)",
    "    shaders = []",
    "    if one_minus_T != 0.0 and one_minus_m != 0.0:",
    "        kd = math_node(nt, \"MULTIPLY\", math_node(nt, \"MULTIPLY\", base_w, one_minus_m), one_minus_T)",
    "        d = nt.nodes.new(\"ShaderNodeBsdfDiffuse\")",
    "        d.inputs[\"Roughness\"].default_value = 0.0",
    "        link_or_set(nt, d.inputs[\"Color\"], mix_rgb(nt, \"MULTIPLY\", 1.0, base, kd))",
    "        shaders.append(d.outputs[0])",
    "        if normal is not None:",
    "            nt.links.new(normal, d.inputs[\"Normal\"])",
    "    if T > 0.0 and one_minus_m != 0.0:",
    "        kt = math_node(nt, \"MULTIPLY\", math_node(nt, \"MULTIPLY\", base_w, one_minus_m), Ts)",
    "        r = nt.nodes.new(\"ShaderNodeBsdfRefraction\")",
    "        r.distribution = \"GGX\"",
    "        link_or_set(nt, r.inputs[\"Roughness\"], rough)",
    "        r.inputs[\"IOR\"].default_value = ior",
    "        link_or_set(nt, r.inputs[\"Color\"], mix_rgb(nt, \"MULTIPLY\", 1.0, base, kt))",
    "        shaders.append(r.outputs[0])",
    "        if normal is not None:",
    "            nt.links.new(normal, r.inputs[\"Normal\"])",
    "    if w > 0.0 or metal != 0.0:",
    "        fr = mix_rgb(nt, \"MIX\", s, f0, (1.0, 1.0, 1.0))",
    "        fm = mix_rgb(nt, \"MIX\", s, base, (1.0, 1.0, 1.0))",
    "        diel = mix_rgb(nt, \"MULTIPLY\", 1.0, fr, ws)",
    "        g = nt.nodes.new(\"ShaderNodeBsdfGlossy\")",
    "        g.distribution = \"GGX\"",
    "        link_or_set(nt, g.inputs[\"Roughness\"], rough)",
    "        link_or_set(nt, g.inputs[\"Color\"], mix_rgb(nt, \"MIX\", metal, diel, fm))",
    "        shaders.append(g.outputs[0])",
    "        if normal is not None:",
    "            nt.links.new(normal, g.inputs[\"Normal\"])",
    "    return add_shaders(nt, shaders)",
    "",
    "",
    "def normal_map(nt, tex_index, strength):",
    "    \"\"\"Tangent-space Normal Map node on the texture's UV map (Blender computes",
    "    MikkTSpace tangents, as iris does when the file has none).\"\"\"",
    "    nm = nt.nodes.new(\"ShaderNodeNormalMap\")",
    "    nm.space = \"TANGENT\"",
    "    nm.uv_map = TEXTURES[tex_index][\"uv_map\"]",
    "    nm.inputs[\"Strength\"].default_value = strength",
    "    nt.links.new(texture_node(nt, tex_index, \"Non-Color\").outputs[\"Color\"], nm.inputs[\"Color\"])",
    "    return nm.outputs[\"Normal\"]",
    "",
    "",
    "def alpha_socket(nt, m, vertex_alpha):",
    "    \"\"\"alpha x colour-texture alpha x vertex alpha, thresholded for MASK.\"\"\"",
    "    sock = None",
    "    if m[\"color_tex\"] >= 0:",
    "        sock = texture_node(nt, m[\"color_tex\"], \"sRGB\").outputs[\"Alpha\"]",
    "    if m[\"vertex_alpha\"]:",
    "        at = nt.nodes.new(\"ShaderNodeAttribute\")",
    "        at.attribute_name = \"Alpha\"",
    "        if sock is None:",
    "            sock = at.outputs[\"Fac\"]",
    "        else:",
    "            mul = nt.nodes.new(\"ShaderNodeMath\")",
    "            mul.operation = \"MULTIPLY\"",
    "            nt.links.new(sock, mul.inputs[0])",
    "            nt.links.new(at.outputs[\"Fac\"], mul.inputs[1])",
    "            sock = mul.outputs[0]",
    "    if sock is not None and m[\"alpha\"] != 1.0:",
    "        mul = nt.nodes.new(\"ShaderNodeMath\")",
    "        mul.operation = \"MULTIPLY\"",
    "        mul.inputs[1].default_value = m[\"alpha\"]",
    "        nt.links.new(sock, mul.inputs[0])",
    "        sock = mul.outputs[0]",
    "    if m[\"alpha_mode\"] == \"mask\":",
    "        ge = nt.nodes.new(\"ShaderNodeMath\")  # alpha >= cutoff: 1 - (alpha < cutoff)",
    "        ge.operation = \"LESS_THAN\"",
    "        ge.inputs[1].default_value = m[\"alpha_cutoff\"]",
    "        if sock is None:",
    "            ge.inputs[0].default_value = m[\"alpha\"]",
    "        else:",
    "            nt.links.new(sock, ge.inputs[0])",
    "        inv = nt.nodes.new(\"ShaderNodeMath\")",
    "        inv.operation = \"SUBTRACT\"",
    "        inv.inputs[0].default_value = 1.0",
    "        nt.links.new(ge.outputs[0], inv.inputs[1])",
    "        sock = inv.outputs[0]",
    "    return sock",
    "",
    "",
    "def build_material(m):",
    "    mat = bpy.data.materials.new(text(m[\"name\"]))",
    "    mat.use_nodes = True",
    "    nt = mat.node_tree",
    "    nt.nodes.clear()",
    "    out = nt.nodes.new(\"ShaderNodeOutputMaterial\")",
    "    kind, vc = m[\"type\"], m[\"vertex_colors\"]",
    "    normal = normal_map(nt, m[\"normal_tex\"], m[\"normal_scale\"]) if m[\"normal_tex\"] >= 0 else None",
    "    if kind == \"diffuse\":",
    "        bsdf = nt.nodes.new(\"ShaderNodeBsdfDiffuse\")",
    "        bsdf.inputs[\"Roughness\"].default_value = 0.0",
    "        set_color(nt, bsdf.inputs[\"Color\"], m[\"color\"], m[\"color_tex\"], vc)",
    "    elif kind == \"glossy\":",
    "        bsdf = nt.nodes.new(\"ShaderNodeBsdfGlossy\")",
    "        bsdf.distribution = \"GGX\"",
    "        bsdf.inputs[\"Roughness\"].default_value = m[\"roughness\"]",
    "        set_color(nt, bsdf.inputs[\"Color\"], m[\"color\"], m[\"color_tex\"], vc)",
    "    elif kind == \"glass\":",
    "        bsdf = nt.nodes.new(\"ShaderNodeBsdfGlass\")",
    "        bsdf.distribution = \"GGX\"",
    "        bsdf.inputs[\"Roughness\"].default_value = m[\"roughness\"]",
    "        bsdf.inputs[\"IOR\"].default_value = m[\"ior\"]",
    "        set_color(nt, bsdf.inputs[\"Color\"], m[\"color\"], m[\"color_tex\"], vc)",
    "    elif m[\"principled\"] or m[\"clearcoat\"] > 0.0 or max(m[\"sheen\"]) > 0.0 or m[\"aniso\"] > 0.0:",
    "        # clearcoat, sheen and anisotropy exist only as Principled v1 inputs (approximate,",
    "        # docs/export.md); every other glTF material is the exact node tree",
    "        bsdf = nt.nodes.new(\"ShaderNodeBsdfPrincipled\")",
    "        bsdf.distribution = \"GGX\"",
    "        set_color(nt, bsdf.inputs[\"Base Color\"], m[\"color\"], m[\"color_tex\"], vc)",
    "        metal = rough = None",
    "        if m[\"mr_tex\"] >= 0:",
    "            sep = nt.nodes.new(\"ShaderNodeSeparateColor\")",
    "            nt.links.new(texture_node(nt, m[\"mr_tex\"], \"Non-Color\").outputs[\"Color\"], sep.inputs[0])",
    "            metal, rough = sep.outputs[\"Blue\"], sep.outputs[\"Green\"]",
    "        scalar(nt, bsdf.inputs[\"Metallic\"], m[\"metallic\"], metal)",
    "        scalar(nt, bsdf.inputs[\"Roughness\"], m[\"roughness\"], rough)",
    "        # Specular = F0 / 0.08 x specular (x texture A) x max(colour (x texture RGB))",
    "        spec = None",
    "        if m[\"spec_tex\"] >= 0:",
    "            spec = texture_node(nt, m[\"spec_tex\"], \"Non-Color\").outputs[\"Alpha\"]",
    "        if m[\"spec_color_tex\"] >= 0:",
    "            sep = nt.nodes.new(\"ShaderNodeSeparateColor\")",
    "            nt.links.new(texture_node(nt, m[\"spec_color_tex\"], \"sRGB\").outputs[\"Color\"], sep.inputs[0])",
    "            cmax = math_node(nt, \"MAXIMUM\", math_node(nt, \"MAXIMUM\", sep.outputs[\"Red\"], sep.outputs[\"Green\"]),",
    "                             sep.outputs[\"Blue\"])",
    "            spec = cmax if spec is None else math_node(nt, \"MULTIPLY\", spec, cmax)",
    "        scalar(nt, bsdf.inputs[\"Specular\"], m[\"principled_specular\"], spec)",
    "        bsdf.inputs[\"Specular Tint\"].default_value = 0.0",
    "        bsdf.inputs[\"IOR\"].default_value = m[\"ior\"]",
    "        # as Blender's glTF importer: Transmission = factor x texture R (Separate Color)",
    "        trans = None",
    "        if m[\"trans_tex\"] >= 0:",
    "            sep = nt.nodes.new(\"ShaderNodeSeparateColor\")",
    "            nt.links.new(texture_node(nt, m[\"trans_tex\"], \"Non-Color\").outputs[\"Color\"], sep.inputs[0])",
    "            trans = sep.outputs[\"Red\"]",
    "        scalar(nt, bsdf.inputs[\"Transmission\"], m[\"transmission\"], trans)",
    "        bsdf.inputs[\"Transmission Roughness\"].default_value = 0.0",
    "        if m[\"aniso\"] > 0.0:",
    "            anisotropy(nt, bsdf, m, rough)",
    "        if m[\"clearcoat\"] > 0.0:",
    "            cc = cr = None",
    "            if m[\"cc_tex\"] >= 0:",
    "                sep = nt.nodes.new(\"ShaderNodeSeparateColor\")",
    "                nt.links.new(texture_node(nt, m[\"cc_tex\"], \"Non-Color\").outputs[\"Color\"], sep.inputs[0])",
    "                cc = sep.outputs[\"Red\"]",
    "            if m[\"ccr_tex\"] >= 0:",
    "                sep = nt.nodes.new(\"ShaderNodeSeparateColor\")",
    "                nt.links.new(texture_node(nt, m[\"ccr_tex\"], \"Non-Color\").outputs[\"Color\"], sep.inputs[0])",
    "                cr = sep.outputs[\"Green\"]",
    "            scalar(nt, bsdf.inputs[\"Clearcoat\"], m[\"clearcoat\"], cc)",
    "            scalar(nt, bsdf.inputs[\"Clearcoat Roughness\"], m[\"clearcoat_roughness\"], cr)",
    "            if m[\"ccn_tex\"] >= 0:",
    "                nt.links.new(normal_map(nt, m[\"ccn_tex\"], m[\"ccn_scale\"]), bsdf.inputs[\"Clearcoat Normal\"])",
    "        if max(m[\"sheen\"]) > 0.0:",
    "            # Principled v1's sheen is not the Charlie lobe: amount = max(colour),",
    "            # white (Sheen Tint 0); docs/export.md gives the measured difference.",
    "            bsdf.inputs[\"Sheen\"].default_value = max(m[\"sheen\"])",
    "            bsdf.inputs[\"Sheen Tint\"].default_value = 0.0",
    "    else:",
    "        bsdf = None",
    "        shader = gltf_nodes(nt, m, vc, normal)",
    "    if bsdf is not None:",
    "        if normal is not None and \"Normal\" in bsdf.inputs:",
    "            nt.links.new(normal, bsdf.inputs[\"Normal\"])",
    "        shader = bsdf.outputs[0]",
    "    if m[\"alpha_mode\"] != \"opaque\":",
    "        # Coverage as a Transparent BSDF mix (Cycles' stochastic alpha, as iris's)",
    "        a = alpha_socket(nt, m, vc)",
    "        mix = nt.nodes.new(\"ShaderNodeMixShader\")",
    "        tr = nt.nodes.new(\"ShaderNodeBsdfTransparent\")",
    "        if a is None:",
    "            mix.inputs[\"Fac\"].default_value = m[\"alpha\"]",
    "        else:",
    "            nt.links.new(a, mix.inputs[\"Fac\"])",
    "        nt.links.new(tr.outputs[0], mix.inputs[1])",
    "        nt.links.new(shader, mix.inputs[2])",
    "        shader = mix.outputs[0]",
    "        mat.blend_method = \"CLIP\" if m[\"alpha_mode\"] == \"mask\" else \"BLEND\"",
    "    if m[\"attenuation\"] is not None:",
    "        # KHR_materials_volume: Cycles absorbs density (1 - colour) per unit length",
    "        sigma = [-math.log(max(c, 1e-30)) / m[\"attenuation\"][3] for c in m[\"attenuation\"][:3]]",
    "        rho = max(max(sigma), 1e-12)",
    "        vol = nt.nodes.new(\"ShaderNodeVolumeAbsorption\")",
    "        vol.inputs[\"Density\"].default_value = rho",
    "        vol.inputs[\"Color\"].default_value = (*[1.0 - s / rho for s in sigma], 1.0)",
    "        nt.links.new(vol.outputs[0], out.inputs[\"Volume\"])",
    "    if max(m[\"emission\"]) > 0.0:",
    "        em = nt.nodes.new(\"ShaderNodeEmission\")",
    "        em.inputs[\"Strength\"].default_value = 1.0",
    "        # KHR_materials_unlit (unlit): the emission is base colour x texture x vertex colour",
    "        set_color(nt, em.inputs[\"Color\"], m[\"emission\"], m[\"emission_tex\"], m[\"unlit\"] and vc)",
    "        emitted = em.outputs[0]",
    "        if not m[\"emission_two_sided\"]:",
    "            # Cycles emits from both faces; a back face gets a Mix Shader whose",
    "            # second input is left empty, i.e. no emission.",
    "            geo = nt.nodes.new(\"ShaderNodeNewGeometry\")",
    "            mix = nt.nodes.new(\"ShaderNodeMixShader\")",
    "            nt.links.new(geo.outputs[\"Backfacing\"], mix.inputs[\"Fac\"])",
    "            nt.links.new(emitted, mix.inputs[1])",
    "            emitted = mix.outputs[0]",
    "        add = nt.nodes.new(\"ShaderNodeAddShader\")",
    "        nt.links.new(shader, add.inputs[0])",
    "        nt.links.new(emitted, add.inputs[1])",
    "        shader = add.outputs[0]",
    "    nt.links.new(shader, out.inputs[\"Surface\"])",
    "    return mat",
    "",
    "",
    "# ---- lights, camera, world ------------------------------------------------",
    "",
    "def orient(obj, direction):",
    "    \"\"\"Rotates obj so that its local -Z points along direction.\"\"\"",
    "    obj.rotation_euler = Vector(direction).to_track_quat(\"-Z\", \"Y\").to_euler()",
    "",
    "",
    "def spot_falloff_nodes(light, cos_inner, cos_outer):",
    "    \"\"\"Cycles 3.4 spot lights multiply the intensity by cos(angle to the axis)",
    "    (measured); this node tree divides it out and applies the glTF falloff",
    "    t^2, t = clamp((cos - cos_outer) / (cos_inner - cos_outer)).\"\"\"",
    "    light.use_nodes = True",
    "    nt = light.node_tree",
    "    em = nt.nodes[\"Emission\"]",
    "    coord = nt.nodes.new(\"ShaderNodeTexCoord\")",
    "    sep = nt.nodes.new(\"ShaderNodeSeparateXYZ\")",
    "    nt.links.new(coord.outputs[\"Normal\"], sep.inputs[0])",
    "    cos = nt.nodes.new(\"ShaderNodeMath\")  # cos = -z of the light-local direction",
    "    cos.operation = \"MULTIPLY\"",
    "    cos.inputs[1].default_value = -1.0",
    "    nt.links.new(sep.outputs[\"Z\"], cos.inputs[0])",
    "    t = nt.nodes.new(\"ShaderNodeMapRange\")",
    "    t.clamp = True",
    "    t.inputs[\"From Min\"].default_value = cos_outer",
    "    t.inputs[\"From Max\"].default_value = max(cos_inner, cos_outer + 1e-6)",
    "    nt.links.new(cos.outputs[0], t.inputs[\"Value\"])",
    "    t2 = nt.nodes.new(\"ShaderNodeMath\")",
    "    t2.operation = \"POWER\"",
    "    t2.inputs[1].default_value = 2.0",
    "    nt.links.new(t.outputs[\"Result\"], t2.inputs[0])",
    "    div = nt.nodes.new(\"ShaderNodeMath\")",
    "    div.operation = \"DIVIDE\"",
    "    nt.links.new(t2.outputs[0], div.inputs[0])",
    "    safe = nt.nodes.new(\"ShaderNodeMath\")",
    "    safe.operation = \"MAXIMUM\"",
    "    safe.inputs[1].default_value = 1e-6",
    "    nt.links.new(cos.outputs[0], safe.inputs[0])",
    "    nt.links.new(safe.outputs[0], div.inputs[1])",
    "    nt.links.new(div.outputs[0], em.inputs[\"Strength\"])",
    "",
    "",
    "def build_light(sc, l):",
    "    light = bpy.data.lights.new(text(l[\"name\"]), l[\"type\"])",
    "    light.color = l[\"color\"]",
    "    light.energy = l[\"strength\"]",
    "    light.cycles.cast_shadow = True",
    "    if l[\"type\"] == \"SUN\":",
    "        light.angle = 0.0",
    "    else:",
    "        light.shadow_soft_size = 0.0",
    "    if l[\"type\"] == \"SPOT\":",
    "        light.spot_size = min(math.pi, 2.0 * math.acos(l[\"cos_outer\"]))",
    "        light.spot_blend = 0.0",
    "        light.show_cone = False",
    "        spot_falloff_nodes(light, l[\"cos_inner\"], l[\"cos_outer\"])",
    "    obj = bpy.data.objects.new(light.name, light)",
    "    obj.location = l[\"position\"]",
    "    if l[\"type\"] != \"POINT\":",
    "        orient(obj, l[\"direction\"])",
    "    sc.collection.objects.link(obj)",
    "",
    "",
    "def build_camera(sc):",
    "    cam = bpy.data.cameras.new(text(CAMERA[\"name\"]))",
    "    cam.type = \"PERSP\"",
    "    cam.sensor_fit = \"VERTICAL\"",
    "    cam.angle_y = CAMERA[\"yfov\"]",
    "    cam.clip_start = CAMERA[\"clip_start\"]",
    "    cam.clip_end = CAMERA[\"clip_end\"]",
    "    cam.shift_x = cam.shift_y = 0.0",
    "    obj = bpy.data.objects.new(cam.name, cam)",
    "    obj.matrix_world = Matrix(CAMERA[\"matrix\"])",
    "    sc.collection.objects.link(obj)",
    "    sc.camera = obj",
    "",
    "",
    "def build_world(sc, env, gltf_axes=True):",
    "    \"\"\"World from the environment: None (black), dict(color=...) or dict(map=...).",
    "    gltf_axes: the scene is in iris's Y-up axes (the export); False when Blender's",
    "    own glTF importer already turned it Z-up (--blender-import).\"\"\"",
    "    world = bpy.data.worlds.new(\"World\")",
    "    world.use_nodes = True",
    "    bg = world.node_tree.nodes[\"Background\"]",
    "    if env is None:",
    "        bg.inputs[\"Color\"].default_value = (0.0, 0.0, 0.0, 1.0)",
    "        bg.inputs[\"Strength\"].default_value = 0.0",
    "    elif \"map\" in env:",
    "        # iris looks a direction up in the map as Blender does for a glTF file",
    "        # imported by Blender (Z up; docs/format.md). The scene is exported Y-up",
    "        # as is, so the direction is turned by 90 deg about X, (x, y, z) ->",
    "        # (x, -z, y), then about Z by the map's rotation. Linear (bilinear, repeat),",
    "        # Blender's default, which iris's lookup reproduces (docs/rendering.md).",
    "        nt = world.node_tree",
    "        tc = nt.nodes.new(\"ShaderNodeTexCoord\")",
    "        mp = nt.nodes.new(\"ShaderNodeMapping\")",
    "        mp.vector_type = \"POINT\"",
    "        mp.inputs[\"Rotation\"].default_value = (0.5 * math.pi if gltf_axes else 0.0, 0.0,",
    "                                                  math.radians(env[\"rotation\"]))",
    "        tex = nt.nodes.new(\"ShaderNodeTexEnvironment\")",
    "        tex.image = bpy.data.images.load(text(env[\"map\"]), check_existing=True)",
    "        tex.image.colorspace_settings.name = \"Linear\"",
    "        tex.interpolation = \"Linear\"",
    "        tex.projection = \"EQUIRECTANGULAR\"",
    "        nt.links.new(tc.outputs[\"Generated\"], mp.inputs[\"Vector\"])",
    "        nt.links.new(mp.outputs[\"Vector\"], tex.inputs[\"Vector\"])",
    "        nt.links.new(tex.outputs[\"Color\"], bg.inputs[\"Color\"])",
    "        bg.inputs[\"Strength\"].default_value = env[\"strength\"]",
    "    else:",
    "        bg.inputs[\"Color\"].default_value = (*env[\"color\"], 1.0)",
    "        bg.inputs[\"Strength\"].default_value = 1.0",
    "    sc.world = world",
    "",
    "",
    "# ---- fair-comparison render settings (docs/export.md) ---------------------",
    "",
    "def configure(sc, a):",
    "    r, c = sc.render, sc.cycles",
    "    r.engine = \"CYCLES\"",
    "    c.device = \"CPU\"",
    "    c.feature_set = \"SUPPORTED\"",
    "    c.samples = a.spp",
    "    # adaptive sampling as Blender users run it (--adaptive-threshold 0.01), else fixed spp",
    "    c.use_adaptive_sampling = a.adaptive_threshold > 0",
    "    if a.adaptive_threshold > 0:",
    "        c.adaptive_threshold = a.adaptive_threshold",
    "        c.adaptive_min_samples = a.adaptive_min_samples",
    "    c.time_limit = a.time_limit",
    "    c.seed = a.seed",
    "    c.use_animated_seed = False",
    "    c.pixel_filter_type = \"BOX\"",
    "    c.max_bounces = a.max_bounces",
    "    c.diffuse_bounces = a.max_bounces",
    "    c.glossy_bounces = a.max_bounces",
    "    c.transmission_bounces = a.max_bounces",
    "    c.volume_bounces = a.max_bounces",
    "    c.transparent_max_bounces = a.max_bounces",
    "    c.min_light_bounces = 0",
    "    c.min_transparent_bounces = 0",
    "    c.light_sampling_threshold = 0.0",
    "    c.sample_clamp_direct = 0.0",
    "    c.sample_clamp_indirect = 0.0",
    "    c.blur_glossy = 0.0",
    "    c.caustics_reflective = True",
    "    c.caustics_refractive = True",
    "    c.use_fast_gi = False",
    "    c.use_denoising = False",
    "    c.use_preview_denoising = False",
    "    for vl in sc.view_layers:",
    "        vl.cycles.use_denoising = False",
    "    c.film_exposure = 1.0",
    "    r.film_transparent = False",
    "    sc.view_settings.view_transform = \"Standard\"",
    "    sc.view_settings.look = \"None\"",
    "    sc.view_settings.exposure = 0.0",
    "    sc.view_settings.gamma = 1.0",
    "    r.threads_mode = \"FIXED\"",
    "    r.threads = a.threads",
    "    r.resolution_x = a.width",
    "    r.resolution_y = a.height",
    "    r.resolution_percentage = 100",
    "    r.pixel_aspect_x = r.pixel_aspect_y = 1.0",
    "    r.use_border = False",
    "    r.use_compositing = False",
    "    r.use_sequencer = False",
    "    s = r.image_settings",
    "    s.file_format = \"OPEN_EXR\"",
    "    s.color_depth = \"32\"",
    "    s.color_mode = \"RGB\"",
    "    s.exr_codec = \"ZIP\"",
    "    r.use_file_extension = False",
    "    r.filepath = os.path.abspath(a.output)",
    "",
    "",
    "def main():",
    "    a = parse_args()",
    "    t0 = time.perf_counter()",
    "    bpy.ops.wm.read_factory_settings(use_empty=True)",
    "    sc = bpy.context.scene",
    "    build_world(sc, WORLD)",
    "    global MATERIAL_BLOCKS",
    "    MATERIAL_BLOCKS = [build_material(m) for m in MATERIALS]",
    "    t_data = time.perf_counter()",
    "    data = MeshData()",
    "    t_data = time.perf_counter() - t_data",
    "    blocks = [build_mesh(data, m) for m in MESHES]",
    "    del data",
    "    for i, (mesh, matrix) in enumerate(INSTANCES):",
    "        obj = bpy.data.objects.new(\"%s.%d\" % (blocks[mesh].name, i), blocks[mesh])",
    "        obj.matrix_world = Matrix(matrix)",
    "        sc.collection.objects.link(obj)",
    "    for l in LIGHTS:",
    "        build_light(sc, l)",
    "    build_camera(sc)",
    "    configure(sc, a)",
    "    t1 = time.perf_counter()",
    "    bpy.ops.render.render(write_still=True)",
    "    t2 = time.perf_counter()",
    "    if not os.path.isfile(sc.render.filepath):",
    "        print(\"iris-blender: error: Cycles wrote no image to %s\" % sc.render.filepath, file=sys.stderr)",
    "        sys.exit(1)",
    "    # One parseable line: scene building (of which reading the mesh data), and",
    "    # bpy.ops.render.render (Cycles' sync, BVH build, path tracing, EXR write).",
    "    c = sc.cycles  # the settings Cycles held, read back",
    "    print(\"IRIS_BLENDER build_seconds=%.3f render_seconds=%.3f spp=%d threads=%d width=%d height=%d \"",
    "          \"data_seconds=%.3f adaptive=%d adaptive_threshold=%g time_limit=%g\" % (",
    "              t1 - t0, t2 - t1, a.spp, a.threads, a.width, a.height, t_data,",
    "              c.use_adaptive_sampling, c.adaptive_threshold, c.time_limit), flush=True)",
    /* END PRELUDE */
};
/* clang-format on */

void iris_blender_put_prelude(FILE *fp) {
  for (size_t i = 0; i < sizeof PRELUDE / sizeof PRELUDE[0]; i++) {
    fputs(PRELUDE[i], fp);
    fputc('\n', fp);
  }
}

/* ---- small writers --------------------------------------------------------- */

/* Python float literal: shortest round-trip form of a finite float. */
static void put_float(FILE *fp, float v) {
  if (!isfinite(v)) v = 0.0f; /* unreachable after validation; keeps the script valid */
  char buf[32];
  snprintf(buf, sizeof buf, "%.9g", (double)v);
  /* "1e+10" and "3" are valid Python floats/ints; make integers floats. */
  if (!strpbrk(buf, ".eEn")) strcat(buf, ".0");
  fputs(buf, fp);
}

void iris_blender_put_vec3(FILE *fp, const float *v) {
  fputc('(', fp);
  for (int i = 0; i < 3; i++) {
    if (i) fputs(", ", fp);
    put_float(fp, v[i]);
  }
  fputc(')', fp);
}

/* A Python bytes literal holding the exact bytes of s (NULL -> b""). Names are
 * decoded with errors="replace" by the prelude's text(); paths with os.fsdecode. */
void iris_blender_put_world(FILE *fp, const iris_scene *scene) {
  if (scene->has_environment && scene->environment_map.path) {
    char map[4096];
    char *abs = realpath(scene->environment_map.path, NULL);
    snprintf(map, sizeof map, "%s", abs ? abs : scene->environment_map.path);
    free(abs);
    fputs("WORLD = dict(map=", fp);
    iris_blender_put_bytes(fp, map);
    fputs(", strength=", fp);
    put_float(fp, scene->environment_map.strength);
    fputs(", rotation=", fp);
    put_float(fp, scene->environment_map.rotation);
    fputs(")\n", fp);
  } else if (scene->has_environment) {
    fputs("WORLD = dict(color=", fp);
    iris_blender_put_vec3(fp, scene->environment);
    fputs(")\n", fp);
  } else {
    fputs("WORLD = None\n", fp);
  }
}

void iris_blender_put_bytes(FILE *fp, const char *s) {
  fputs("b\"", fp);
  for (const unsigned char *p = (const unsigned char *)(s ? s : ""); *p; p++) {
    if (*p == '"' || *p == '\\')
      fprintf(fp, "\\%c", *p);
    else if (*p < 0x20 || *p >= 0x7f)
      fprintf(fp, "\\x%02x", *p);
    else
      fputc(*p, fp);
  }
  fputc('"', fp);
}

static void put_matrix(FILE *fp, const iris_mat4 *m) {
  fputc('(', fp);
  for (int r = 0; r < 4; r++) {
    fputs(r ? ", (" : "(", fp);
    for (int c = 0; c < 4; c++) {
      if (c) fputs(", ", fp);
      put_float(fp, m->m[r][c]);
    }
    fputc(')', fp);
  }
  fputc(')', fp);
}

/* ---- mesh blob layout ------------------------------------------------------ */

typedef struct mesh_layout {
  int64_t pos, nrm, uv, col, idx; /* byte offsets, -1 when absent */
  int64_t uv1, alpha;
} mesh_layout;

static uint64_t align16(uint64_t v) { return (v + 15u) & ~(uint64_t)15u; }

static uint64_t layout_meshes(const iris_scene *scene, mesh_layout *lay) {
  uint64_t off = 0;
  for (size_t i = 0; i < scene->mesh_count; i++) {
    const iris_mesh *m = &scene->meshes[i];
    uint64_t nv = m->vertex_count, nt = m->triangle_count;
    lay[i].pos = (int64_t)off;
    off = align16(off + 12u * nv);
    lay[i].nrm = m->normals ? (int64_t)off : -1;
    if (m->normals) off = align16(off + 12u * nv);
    lay[i].uv = m->uvs ? (int64_t)off : -1;
    if (m->uvs) off = align16(off + 8u * nv);
    lay[i].col = m->colors ? (int64_t)off : -1;
    if (m->colors) off = align16(off + 12u * nv);
    lay[i].uv1 = m->uvs1 ? (int64_t)off : -1;
    if (m->uvs1) off = align16(off + 8u * nv);
    lay[i].alpha = m->alphas ? (int64_t)off : -1;
    if (m->alphas) off = align16(off + 4u * nv);
    lay[i].idx = (int64_t)off;
    off = align16(off + 12u * nt);
  }
  return off;
}

/* Byte sink for the blob: raw into the sidecar, or base64 into the script. */
typedef struct blob_sink {
  FILE *fp;
  bool base64;
  uint64_t written;
  unsigned char carry[3];
  int carry_count;
} blob_sink;

static const char B64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static void b64_group(FILE *fp, const unsigned char *in, int n) {
  char out[4];
  uint32_t v = (uint32_t)in[0] << 16 | (uint32_t)(n > 1 ? in[1] : 0) << 8 | (uint32_t)(n > 2 ? in[2] : 0);
  out[0] = B64[(v >> 18) & 63];
  out[1] = B64[(v >> 12) & 63];
  out[2] = n > 1 ? B64[(v >> 6) & 63] : '=';
  out[3] = n > 2 ? B64[v & 63] : '=';
  fwrite(out, 1, 4, fp);
}

static void sink_write(blob_sink *s, const void *data, size_t size) {
  const unsigned char *p = data;
  s->written += size;
  if (!s->base64) {
    fwrite(p, 1, size, s->fp);
    return;
  }
  while (size > 0 && s->carry_count > 0 && s->carry_count < 3) {
    s->carry[s->carry_count++] = *p++;
    size--;
    if (s->carry_count == 3) {
      b64_group(s->fp, s->carry, 3);
      s->carry_count = 0;
    }
  }
  for (; size >= 3; size -= 3, p += 3) b64_group(s->fp, p, 3);
  for (; size > 0; size--) s->carry[s->carry_count++] = *p++;
}

static void sink_finish(blob_sink *s) {
  if (s->base64 && s->carry_count > 0) b64_group(s->fp, s->carry, s->carry_count);
  s->carry_count = 0;
}

static void sink_pad(blob_sink *s, uint64_t to) {
  static const unsigned char zeros[16] = {0};
  while (s->written < to) {
    uint64_t n = to - s->written;
    sink_write(s, zeros, n > 16 ? 16 : (size_t)n);
  }
}

static bool host_is_little_endian(void) {
  const uint32_t one = 1;
  unsigned char b;
  memcpy(&b, &one, 1);
  return b == 1;
}

/* 32-bit words written little-endian whatever the host. */
static void sink_words(blob_sink *s, const void *words, size_t count) {
  if (host_is_little_endian()) {
    sink_write(s, words, count * 4);
    return;
  }
  const unsigned char *p = words;
  for (size_t i = 0; i < count; i++, p += 4) {
    unsigned char w[4] = {p[3], p[2], p[1], p[0]};
    sink_write(s, w, 4);
  }
}

static void write_blob(blob_sink *s, const iris_scene *scene, const mesh_layout *lay) {
  for (size_t i = 0; i < scene->mesh_count; i++) {
    const iris_mesh *m = &scene->meshes[i];
    size_t nv = m->vertex_count, nt = m->triangle_count;
    sink_pad(s, (uint64_t)lay[i].pos);
    sink_words(s, m->positions, 3 * nv);
    if (m->normals) {
      sink_pad(s, (uint64_t)lay[i].nrm);
      sink_words(s, m->normals, 3 * nv);
    }
    if (m->uvs) {
      sink_pad(s, (uint64_t)lay[i].uv);
      sink_words(s, m->uvs, 2 * nv);
    }
    if (m->colors) {
      sink_pad(s, (uint64_t)lay[i].col);
      sink_words(s, m->colors, 3 * nv);
    }
    if (m->uvs1) {
      sink_pad(s, (uint64_t)lay[i].uv1);
      sink_words(s, m->uvs1, 2 * nv);
    }
    if (m->alphas) {
      sink_pad(s, (uint64_t)lay[i].alpha);
      sink_words(s, m->alphas, nv);
    }
    sink_pad(s, (uint64_t)lay[i].idx);
    sink_words(s, m->indices, 3 * nt);
  }
  sink_pad(s, align16(s->written));
  sink_finish(s);
}

/* ---- materials ------------------------------------------------------------- */

/* A Blender material is one iris material with or without vertex colours
 * multiplied in (vertex colours are a mesh attribute in iris). */
typedef struct material_variant {
  int32_t material; /* -1 = iris's default material */
  bool vertex_colors;
  bool vertex_alpha; /* the mesh has alphas (read by MASK/BLEND materials) */
} material_variant;

static const char *wrap_name(iris_wrap w) {
  switch (w) {
    case IRIS_WRAP_CLAMP: return "CLAMP";
    case IRIS_WRAP_MIRROR: return "MIRROR";
    default: return "REPEAT";
  }
}

static const char *material_type_name(iris_material_type t) {
  switch (t) {
    case IRIS_MATERIAL_GLOSSY: return "glossy";
    case IRIS_MATERIAL_GLASS: return "glass";
    case IRIS_MATERIAL_GLTF: return "gltf";
    default: return "diffuse";
  }
}

/* Principled BSDF (v1) "Specular" gives a dielectric F0 of 0.08 * Specular;
 * glTF's is ((ior-1)/(ior+1))^2 * specular * specularColor (KHR_materials_specular,
 * colour approximated by its maximum). */
static float principled_specular(const iris_material *m) {
  float f0 = iris_sqr((m->ior - 1.0f) / (m->ior + 1.0f));
  float col = fmaxf(m->specular_color[0], fmaxf(m->specular_color[1], m->specular_color[2]));
  return f0 / 0.08f * m->specular * col;
}

static void put_material(FILE *fp, const iris_scene *scene, material_variant v, bool principled) {
  iris_material def = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  const iris_material *m = v.material >= 0 ? &scene->materials[v.material] : &def;
  fputs("    dict(name=", fp);
  iris_blender_put_bytes(fp, v.material >= 0 ? (m->name ? m->name : "material") : "iris-default");
  fprintf(fp, ", type=\"%s\", color=", material_type_name(m->type));
  iris_blender_put_vec3(fp, m->color);
  fprintf(fp, ", color_tex=%d, roughness=", (int)m->color_texture);
  put_float(fp, m->roughness);
  fputs(", ior=", fp);
  put_float(fp, m->ior);
  fputs(", metallic=", fp);
  put_float(fp, m->metallic);
  fprintf(fp, ", mr_tex=%d, principled_specular=", (int)m->metallic_roughness_texture);
  put_float(fp, principled_specular(m));
  fputs(", transmission=", fp);
  put_float(fp, m->transmission);
  /* glTF dielectric F0 per channel, as renderer/bsdf.c: min(((ior-1)/(ior+1))^2 s, 1). */
  float f0 = iris_sqr((m->ior - 1.0f) / (m->ior + 1.0f)), f0c[3];
  for (int k = 0; k < 3; k++) f0c[k] = fminf(f0 * m->specular_color[k], 1.0f);
  fputs(", specular=", fp);
  put_float(fp, m->specular);
  fputs(", f0=", fp);
  iris_blender_put_vec3(fp, f0c);
  fputs(", f0_ior=", fp);
  put_float(fp, f0);
  fputs(", specular_color=", fp);
  iris_blender_put_vec3(fp, m->specular_color);
  fprintf(fp, ", trans_tex=%d, spec_tex=%d, spec_color_tex=%d", (int)m->transmission_texture,
          (int)m->specular_texture, (int)m->specular_color_texture);
  fprintf(fp, ", principled=%s", principled ? "True" : "False");
  fputs(", emission=", fp);
  iris_blender_put_vec3(fp, m->emission);
  fprintf(fp, ", emission_tex=%d, emission_two_sided=%s, unlit=%s, vertex_colors=%s",
          (int)m->emission_texture, m->emission_two_sided ? "True" : "False", m->unlit ? "True" : "False",
          v.vertex_colors ? "True" : "False");
  static const char *const ALPHA[] = {"opaque", "mask", "blend"};
  fprintf(fp, ", normal_tex=%d, normal_scale=", (int)m->normal_texture);
  put_float(fp, m->normal_scale);
  fprintf(fp, ", alpha_mode=\"%s\", vertex_alpha=%s, alpha=", ALPHA[m->alpha_mode <= IRIS_ALPHA_BLEND ? m->alpha_mode : 0],
          v.vertex_alpha ? "True" : "False");
  put_float(fp, m->alpha);
  fputs(", alpha_cutoff=", fp);
  put_float(fp, m->alpha_cutoff);
  fputs(", clearcoat=", fp);
  put_float(fp, m->clearcoat);
  fputs(", clearcoat_roughness=", fp);
  put_float(fp, m->clearcoat_roughness);
  fprintf(fp, ", cc_tex=%d, ccr_tex=%d, ccn_tex=%d, ccn_scale=", (int)m->clearcoat_texture,
          (int)m->clearcoat_roughness_texture, (int)m->clearcoat_normal_texture);
  put_float(fp, m->clearcoat_normal_scale);
  fputs(", sheen=", fp);
  iris_blender_put_vec3(fp, m->sheen_color);
  fputs(", aniso=", fp);
  put_float(fp, m->type == IRIS_MATERIAL_GLTF ? m->anisotropy : 0.0f);
  fputs(", aniso_rot=", fp);
  put_float(fp, m->anisotropy_rotation);
  fprintf(fp, ", aniso_tex=%d", (int)m->anisotropy_texture);
  fputs(", attenuation=", fp);
  if (m->attenuation_distance > 0.0f) {
    fputs("(", fp);
    for (int k = 0; k < 3; k++) put_float(fp, m->attenuation_color[k]), fputs(", ", fp);
    put_float(fp, m->attenuation_distance);
    fputs(")", fp);
  } else {
    fputs("None", fp);
  }
  fputs("),\n", fp);
}

/* ---- textures -------------------------------------------------------------- */

static void put_texture(FILE *fp, const iris_scene *scene, size_t index, const char *script_path) {
  const iris_texture *t = &scene->textures[index];
  char path[2048];
  iris_export_texture_file(scene, index, script_path, false, path, sizeof path);
  fputs("    dict(path=", fp);
  iris_blender_put_bytes(fp, path);
  fprintf(fp, ", wrap_s=\"%s\", wrap_t=\"%s\", nearest=%s, uv_map=\"%s\", xf=", wrap_name(t->wrap_s),
          wrap_name(t->wrap_t), t->nearest ? "True" : "False", t->uv_set ? "UV1" : "UVMap");
  if (t->has_transform) {
    const float v[5] = {t->offset[0], t->offset[1], t->rotation, t->scale[0], t->scale[1]};
    fputc('(', fp);
    for (int k = 0; k < 5; k++) {
      if (k) fputs(", ", fp);
      put_float(fp, v[k]);
    }
    fputc(')', fp);
  } else {
    fputs("None", fp);
  }
  fputs("),\n", fp);
}

/* ---- lights and camera ----------------------------------------------------- */

static void put_light(FILE *fp, const iris_light *l, size_t index) {
  static const char *const TYPES[] = {"POINT", "SPOT", "SUN"};
  char name[32];
  snprintf(name, sizeof name, "light.%zu", index);
  /* Cycles 3.4 (measured, docs/export.md): a point or spot light of power P W
   * has radiant intensity P/(4 pi) W/sr; a sun of strength S gives irradiance
   * S W/m^2 on a surface facing it. */
  float strength = l->type == IRIS_LIGHT_DIRECTIONAL ? l->intensity : 4.0f * IRIS_PI * l->intensity;
  float outer = iris_clampf(l->outer_cone, 1e-4f, 0.5f * IRIS_PI);
  float inner = iris_clampf(l->inner_cone, 0.0f, outer);
  if (l->range > 0.0f)
    iris_warnf("light '%s': range %g ignored (Cycles lights have no range)", l->name ? l->name : name,
               (double)l->range);
  fputs("    dict(name=", fp);
  iris_blender_put_bytes(fp, l->name ? l->name : name);
  fprintf(fp, ", type=\"%s\", color=", TYPES[l->type <= IRIS_LIGHT_DIRECTIONAL ? l->type : 0]);
  iris_blender_put_vec3(fp, l->color);
  fputs(", strength=", fp);
  put_float(fp, strength);
  fputs(", position=", fp);
  iris_blender_put_vec3(fp, l->position);
  fputs(", direction=", fp);
  iris_blender_put_vec3(fp, l->direction);
  fputs(", cos_inner=", fp);
  put_float(fp, cosf(inner));
  fputs(", cos_outer=", fp);
  put_float(fp, cosf(outer));
  fputs("),\n", fp);
}

void iris_blender_put_camera(FILE *fp, const iris_scene *scene, const iris_export_view *view) {
  /* Cycles starts camera rays at clip_start: keep it far below any feature
   * size. clip_end must reach past everything. */
  iris_vec3 lo, hi, eye = iris_v3(view->to_world.m[0][3], view->to_world.m[1][3], view->to_world.m[2][3]);
  float far = 1.0f, diag = 1.0f;
  if (iris_scene_bounds(scene, &lo, &hi)) {
    diag = fmaxf(iris_length(iris_sub(hi, lo)), 1e-6f);
    iris_vec3 c = iris_scale(iris_add(lo, hi), 0.5f);
    far = iris_length(iris_sub(c, eye)) + diag;
  }
  fputs("CAMERA = dict(name=", fp);
  iris_blender_put_bytes(fp, view->camera >= 0 && scene->cameras[view->camera].name ? scene->cameras[view->camera].name
                                                                       : "camera");
  fputs(", yfov=", fp);
  put_float(fp, view->yfov);
  fputs(", clip_start=", fp);
  put_float(fp, fmaxf(1e-6f, 1e-7f * diag));
  fputs(", clip_end=", fp);
  put_float(fp, 2.0f * far + 1.0f);
  fputs(",\n              matrix=", fp);
  put_matrix(fp, &view->to_world);
  fputs(")\n", fp);
}

/* ---- the script ------------------------------------------------------------ */

void iris_blender_sidecar_path(const char *script_path, char *out, size_t size) {
  char dir[1024], stem[256], name[300];
  iris_path_dir(script_path, dir, sizeof dir);
  iris_path_stem(script_path, stem, sizeof stem);
  snprintf(name, sizeof name, "%s.meshes.bin", stem);
  iris_path_join(dir, name, out, size);
}

static bool mesh_has_degenerate(const iris_mesh *m) {
  for (size_t t = 0; t < m->triangle_count; t++) {
    const uint32_t *i = m->indices + 3 * t;
    if (i[0] == i[1] || i[1] == i[2] || i[0] == i[2]) return true;
  }
  return false;
}

static iris_status write_script(FILE *fp, const iris_scene *scene, const char *script_path,
                                const iris_export_params *params, const iris_export_view *view,
                                const mesh_layout *lay, uint64_t blob_size, int32_t *mesh_variant,
                                const material_variant *variants, size_t variant_count) {
  char stem[256], sidecar[1300];
  iris_path_stem(script_path, stem, sizeof stem);
  iris_blender_sidecar_path(script_path, sidecar, sizeof sidecar);
  char sidecar_name[300];
  snprintf(sidecar_name, sizeof sidecar_name, "%s.meshes.bin", stem);

  fprintf(fp,
          "# Blender 3.4 scene written by iris %s from ",
          IRIS_VERSION_STRING);
  iris_blender_put_bytes(fp, scene->source_path ? scene->source_path : "(memory)");
  if (scene->variants.count && scene->variants.applied >= 0) { /* its materials are the scene's */
    fputs("\n# with the glTF material variant ", fp);
    iris_blender_put_bytes(fp, scene->variants.names[scene->variants.applied]);
    fputs(" (KHR_materials_variants) applied", fp);
  }
  fputs("\n# Builds the scene from an empty file and renders it with Cycles using the\n"
        "# fair-comparison settings of iris's docs/export.md. Usage:\n"
        "#   blender -b --factory-startup --python-exit-code 1 -P THIS.py -- --output OUT.exr\n"
        "#           [--spp N] [--threads T] [--seed S] [--width W --height H] [--max-bounces B]\n"
        "#           [--adaptive-threshold T [--adaptive-min-samples N]] [--time-limit SECONDS]\n",
        fp);
  iris_blender_put_prelude(fp);

  fputs("\n\n# ---- this scene ----------------------------------------------------------\n\n", fp);
  fprintf(fp, "SETTINGS = dict(width=%d, height=%d, spp=%d, max_depth=%d, seed=%llu)\n", view->width,
          view->height, view->spp, view->max_depth, (unsigned long long)(view->seed & 0x7fffffffu));
  iris_blender_put_world(fp, scene);

  fputs("TEXTURES = [\n", fp);
  for (size_t i = 0; i < scene->texture_count; i++) put_texture(fp, scene, i, script_path);
  fputs("]\nMATERIALS = [\n", fp);
  for (size_t i = 0; i < variant_count; i++) put_material(fp, scene, variants[i], params->gltf_principled);
  fputs("]\nMESHES = [\n", fp);
  for (size_t i = 0; i < scene->mesh_count; i++) {
    const iris_mesh *m = &scene->meshes[i];
    char name[32];
    snprintf(name, sizeof name, "mesh.%zu", i);
    fputs("    dict(name=", fp);
    iris_blender_put_bytes(fp, m->name ? m->name : name);
    fprintf(fp,
            ", nv=%u, nt=%u, pos=%lld, nrm=%lld, uv=%lld, col=%lld, idx=%lld, material=%d, "
            "validate=%s, uv1=%lld, alpha=%lld),\n",
            m->vertex_count, m->triangle_count, (long long)lay[i].pos, (long long)lay[i].nrm,
            (long long)lay[i].uv, (long long)lay[i].col, (long long)lay[i].idx, (int)mesh_variant[i],
            mesh_has_degenerate(m) ? "True" : "False", (long long)lay[i].uv1, (long long)lay[i].alpha);
  }
  fputs("]\nINSTANCES = [\n", fp);
  for (size_t i = 0; i < scene->instance_count; i++) {
    fprintf(fp, "    (%u, ", scene->instances[i].mesh);
    put_matrix(fp, &scene->instances[i].transform);
    fputs("),\n", fp);
  }
  fputs("]\nLIGHTS = [\n", fp);
  for (size_t i = 0; i < scene->light_count; i++) put_light(fp, &scene->lights[i], i);
  fputs("]\n", fp);
  iris_blender_put_camera(fp, scene, view);

  fprintf(fp, "BLOB_SIZE = %llu\n", (unsigned long long)blob_size);
  if (params->embed_meshes) {
    fputs("SIDECAR = None\nBLOB = b\"", fp);
    blob_sink sink = {fp, true, 0, {0}, 0};
    write_blob(&sink, scene, lay);
    fputs("\"\n", fp);
  } else {
    fputs("SIDECAR = ", fp);
    iris_blender_put_bytes(fp, sidecar_name);
    fputs("\nBLOB = None\n", fp);
  }
  fputs("\nmain()\n", fp);
  return IRIS_OK;
}

iris_status iris_export_blender(const iris_scene *scene, const char *script_path,
                                const iris_export_params *params, iris_error *err) {
  const char *file = scene->source_path ? scene->source_path : script_path;
  iris_status st = iris_scene_validate(scene, file, err);
  if (st != IRIS_OK) return st;
  iris_export_view view;
  st = iris_export_resolve_view(scene, params, file, &view, err);
  if (st != IRIS_OK) return st;

  size_t nm = scene->mesh_count;
  mesh_layout *lay = calloc(nm ? nm : 1, sizeof *lay);
  int32_t *mesh_variant = calloc(nm ? nm : 1, sizeof *mesh_variant);
  material_variant *variants = calloc(nm ? nm : 1, sizeof *variants);
  if (!lay || !mesh_variant || !variants) {
    st = iris_error_set(err, IRIS_ERR_NOMEM, script_path, 0, NULL, "out of memory");
    goto done;
  }
  /* Variants in order of first use, so equal scenes give equal scripts. */
  size_t variant_count = 0;
  for (size_t i = 0; i < nm; i++) {
    material_variant v = {scene->meshes[i].material, scene->meshes[i].colors != NULL,
                          scene->meshes[i].alphas != NULL};
    size_t k = 0;
    while (k < variant_count && !(variants[k].material == v.material && variants[k].vertex_colors == v.vertex_colors &&
                                    variants[k].vertex_alpha == v.vertex_alpha)) k++;
    if (k == variant_count) variants[variant_count++] = v;
    mesh_variant[i] = (int32_t)k;
  }
  uint64_t blob_size = layout_meshes(scene, lay);

  st = iris_export_write_textures(scene, script_path, err);
  if (st != IRIS_OK) goto done;
  if (!params->embed_meshes) {
    char sidecar[1300];
    iris_blender_sidecar_path(script_path, sidecar, sizeof sidecar);
    iris_atomic_file af;
    st = iris_atomic_open(&af, sidecar, err);
    if (st != IRIS_OK) goto done;
    blob_sink sink = {af.fp, false, 0, {0}, 0};
    write_blob(&sink, scene, lay);
    if (ferror(af.fp)) {
      iris_atomic_abort(&af);
      st = iris_error_set(err, IRIS_ERR_IO, sidecar, 0, NULL, "write failed: %s", strerror(errno));
      goto done;
    }
    st = iris_atomic_commit(&af, err);
    if (st != IRIS_OK) goto done;
  }

  iris_atomic_file af;
  st = iris_atomic_open(&af, script_path, err);
  if (st != IRIS_OK) goto done;
  st = write_script(af.fp, scene, script_path, params, &view, lay, blob_size, mesh_variant, variants,
                    variant_count);
  if (st == IRIS_OK && ferror(af.fp))
    st = iris_error_set(err, IRIS_ERR_IO, script_path, 0, NULL, "write failed: %s", strerror(errno));
  if (st != IRIS_OK)
    iris_atomic_abort(&af);
  else
    st = iris_atomic_commit(&af, err);

done:
  free(lay);
  free(mesh_variant);
  free(variants);
  return st;
}
