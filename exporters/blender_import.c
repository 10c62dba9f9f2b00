/* The script for Blender's own glTF importer (exporters/blender.h,
 * iris_export_blender_import; docs/validation.md, --blender-import): the
 * common prelude of blender.c, then the functions below, which import the file
 * with bpy.ops.import_scene.gltf, record what the importer created and render
 * it under iris's camera and world. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "core/fileio.h"
#include "exporters/blender.h"
#include "exporters/blender_script.h"

/* clang-format off */
static const char *const IMPORT_PRELUDE[] = {
    "",
    "",
    "# ---- Blender's own glTF importer (iris validate --blender-import) ----------",
    "",
    "def to_gltf(v):",
    "    \"\"\"Blender's importer maps glTF (x, y, z) to Blender (x, -z, y); back again.\"\"\"",
    "    return [v[0], v[2], -v[1]]",
    "",
    "",
    "def socket_value(node, name):",
    "    s = node.inputs.get(name)",
    "    if s is None:",
    "        return None",
    "    if s.is_linked:",
    "        return \"linked:\" + s.links[0].from_node.bl_idname",
    "    v = s.default_value",
    "    try:",
    "        return [float(x) for x in v][:3]",
    "    except TypeError:",
    "        return float(v)",
    "",
    "",
    "def describe_import(sc):",
    "    \"\"\"What Blender's importer made of the file, in glTF's axes and units.\"\"\"",
    "    dg = bpy.context.evaluated_depsgraph_get()",
    "    out = dict(unit_system=sc.unit_settings.system, unit_scale=sc.unit_settings.scale_length,",
    "               triangles=0, meshes=0, meshes_with_colors=0, materials=[], cameras=[], lights=[],",
    "               bounds=None)",
    "    lo, hi = [math.inf] * 3, [-math.inf] * 3",
    "    for obj in sc.objects:",
    "        if obj.type == \"MESH\":",
    "            ev = obj.evaluated_get(dg)",
    "            me = ev.to_mesh()",
    "            me.calc_loop_triangles()",
    "            out[\"triangles\"] += len(me.loop_triangles)",
    "            out[\"meshes\"] += 1",
    "            if len(obj.data.color_attributes) > 0:",
    "                out[\"meshes_with_colors\"] += 1",
    "            mw = obj.matrix_world",
    "            for v in me.vertices:",
    "                p = to_gltf(mw @ v.co)",
    "                for k in range(3):",
    "                    lo[k] = min(lo[k], p[k])",
    "                    hi[k] = max(hi[k], p[k])",
    "            ev.to_mesh_clear()",
    "        elif obj.type == \"CAMERA\":",
    "            c = obj.data",
    "            out[\"cameras\"].append(dict(name=obj.name, type=c.type, sensor_fit=c.sensor_fit,",
    "                                       angle_y=c.angle_y, angle_x=c.angle_x,",
    "                                       position=to_gltf(obj.matrix_world.translation)))",
    "        elif obj.type == \"LIGHT\":",
    "            l = obj.data",
    "            d = dict(name=obj.name, type=l.type, color=list(l.color),",
    "                     position=to_gltf(obj.matrix_world.translation))",
    "            if l.type == \"SUN\":",
    "                d[\"strength\"] = l.energy",
    "            else:",
    "                d[\"power\"] = l.energy",
    "            if l.type == \"SPOT\":",
    "                d[\"spot_size\"] = l.spot_size",
    "                d[\"spot_blend\"] = l.spot_blend",
    "            out[\"lights\"].append(d)",
    "    if out[\"meshes\"]:",
    "        out[\"bounds\"] = [lo, hi]",
    "    for mat in bpy.data.materials:",
    "        d = dict(name=mat.name, nodes=[], blend_method=mat.blend_method)",
    "        if mat.use_nodes and mat.node_tree:",
    "            for n in mat.node_tree.nodes:",
    "                d[\"nodes\"].append(n.bl_idname)",
    "                if n.bl_idname in (\"ShaderNodeVertexColor\", \"ShaderNodeAttribute\"):",
    "                    d[\"uses_vertex_color\"] = True",
    "                if n.bl_idname == \"ShaderNodeBsdfPrincipled\":",
    "                    for key in (\"Base Color\", \"Metallic\", \"Roughness\", \"Specular\", \"Transmission\",",
    "                                \"IOR\", \"Emission\", \"Emission Strength\", \"Alpha\"):",
    "                        d[key] = socket_value(n, key)",
    "        out[\"materials\"].append(d)",
    "    return out",
    "",
    "",
    "def apply_variant():",
    "    \"\"\"KHR_materials_variants: show the variant iris imported the file with, as the",
    "    add-on's Display Variant button does (it stores the file's variants in",
    "    scene.gltf2_KHR_materials_variants_variants and each mesh's mappings in",
    "    mesh.gltf2_variant_mesh_data).\"\"\"",
    "    if VARIANT is None:",
    "        return",
    "    index, name = VARIANT[0], VARIANT[1].decode(\"utf-8\", \"replace\")",
    "    s0 = bpy.data.scenes[0]",
    "    found = [v for v in getattr(s0, \"gltf2_KHR_materials_variants_variants\", [])",
    "             if v.variant_idx == index and v.name == name]",
    "    if not found:",
    "        print(\"iris-blender: error: Blender's glTF import of %s has no material variant %d %r\"",
    "              % (os.fsdecode(IMPORT), index, name), file=sys.stderr)",
    "        sys.exit(1)",
    "    s0.gltf2_active_variant = index",
    "    if \"FINISHED\" not in bpy.ops.scene.gltf2_display_variant():",
    "        print(\"iris-blender: error: Display Variant failed for %r\" % name, file=sys.stderr)",
    "        sys.exit(1)",
    "    print(\"iris-blender: material variant %r displayed\" % name, flush=True)",
    "",
    "",
    "def main_import():",
    "    a = parse_args()",
    "    t0 = time.perf_counter()",
    "    bpy.ops.wm.read_factory_settings(use_empty=True)",
    "    # Debian 12's numpy 1.24 removed np.bool, which the 3.4 add-on still uses.",
    "    if not hasattr(np, \"bool\"):",
    "        np.bool = bool",
    "    sc = bpy.context.scene",
    "    path = os.fsdecode(IMPORT)",
    "    try:",
    "        res = bpy.ops.import_scene.gltf(filepath=path)",
    "    except Exception as e:  # the add-on raises on files it cannot read",
    "        print(\"iris-blender: error: Blender's glTF importer failed on %s: %s\" % (path, e), file=sys.stderr)",
    "        sys.exit(1)",
    "    if \"FINISHED\" not in res:",
    "        print(\"iris-blender: error: Blender's glTF importer did not finish on %s\" % path, file=sys.stderr)",
    "        sys.exit(1)",
    "    apply_variant()",
    "    inventory = describe_import(sc)",
    "    build_world(sc, WORLD, gltf_axes=False)",
    "    build_camera(sc)",
    "    configure(sc, a)",
    "    if a.inventory:",
    "        import json",
    "        with open(a.inventory, \"w\") as f:",
    "            json.dump(inventory, f, indent=1)",
    "    t1 = time.perf_counter()",
    "    bpy.ops.render.render(write_still=True)",
    "    t2 = time.perf_counter()",
    "    if not os.path.isfile(sc.render.filepath):",
    "        print(\"iris-blender: error: Cycles wrote no image to %s\" % sc.render.filepath, file=sys.stderr)",
    "        sys.exit(1)",
    "    print(\"IRIS_BLENDER build_seconds=%.3f render_seconds=%.3f spp=%d threads=%d width=%d height=%d \"",
    "          \"data_seconds=0.000\" % (t1 - t0, t2 - t1, a.spp, a.threads, a.width, a.height), flush=True)",
};
/* clang-format on */

iris_status iris_export_blender_import(const iris_scene *scene, const char *import_path,
                                       const char *script_path, const iris_export_params *params,
                                       iris_error *err) {
  const char *file = scene->source_path ? scene->source_path : script_path;
  iris_status st = iris_scene_validate(scene, file, err);
  if (st != IRIS_OK) return st;
  iris_export_view view;
  st = iris_export_resolve_view(scene, params, file, &view, err);
  if (st != IRIS_OK) return st;
  if (!iris_path_exists(import_path))
    return iris_error_set(err, IRIS_ERR_USAGE, import_path, 0, NULL, "no such file");
  char abs_import[4096], cwd[2048];
  if (import_path[0] == '/' || !getcwd(cwd, sizeof cwd))
    snprintf(abs_import, sizeof abs_import, "%s", import_path);
  else
    iris_path_join(cwd, import_path, abs_import, sizeof abs_import);
  /* Blender's importer turns glTF's +Y up into +Z up: glTF (x, y, z) lands at
   * Blender (x, -z, y). iris keeps glTF's axes, so the camera is rotated the same way. */
  iris_export_view bview = view;
  for (int c = 0; c < 4; c++) {
    float y = view.to_world.m[1][c], z = view.to_world.m[2][c];
    bview.to_world.m[1][c] = -z;
    bview.to_world.m[2][c] = y;
  }
  iris_atomic_file af;
  st = iris_atomic_open(&af, script_path, err);
  if (st != IRIS_OK) return st;
  FILE *fp = af.fp;
  fprintf(fp, "# Blender 3.4 script written by iris %s: imports ", IRIS_VERSION_STRING);
  iris_blender_put_bytes(fp, abs_import);
  fputs("\n# with Blender's own glTF importer and renders it with Cycles under iris's camera and\n"
        "# world with the fair-comparison settings (docs/validation.md, --blender-import). Usage:\n"
        "#   blender -b --factory-startup --python-exit-code 1 -P THIS.py -- --output OUT.exr\n"
        "#           [--spp N] [--threads T] [--seed S] [--width W --height H] [--max-bounces B]\n"
        "#           [--adaptive-threshold T [--adaptive-min-samples N]] [--time-limit SECONDS]\n"
        "#           [--inventory FILE.json]\n",
        fp);
  iris_blender_put_prelude(fp);
  for (size_t i = 0; i < sizeof IMPORT_PRELUDE / sizeof IMPORT_PRELUDE[0]; i++) {
    fputs(IMPORT_PRELUDE[i], fp);
    fputc('\n', fp);
  }
  fputs("\n\n# ---- this scene ----------------------------------------------------------\n\n", fp);
  fprintf(fp, "SETTINGS = dict(width=%d, height=%d, spp=%d, max_depth=%d, seed=%llu)\n", view.width,
          view.height, view.spp, view.max_depth, (unsigned long long)(view.seed & 0x7fffffffu));
  iris_blender_put_world(fp, scene);
  fputs("TEXTURES = []\nMATERIALS = []\nMESHES = []\nINSTANCES = []\nLIGHTS = []\n", fp);
  iris_blender_put_camera(fp, scene, &bview);
  fputs("BLOB_SIZE = 0\nSIDECAR = None\nBLOB = None\nIMPORT = ", fp);
  iris_blender_put_bytes(fp, abs_import);
  /* The variant iris applied (the scene's materials are its): Blender's import shows it too. */
  const iris_material_variants *v = &scene->variants;
  if (v->count && v->applied >= 0) {
    fprintf(fp, "\nVARIANT = (%d, ", (int)v->applied);
    iris_blender_put_bytes(fp, v->names[v->applied]);
    fputs(")", fp);
  } else {
    fputs("\nVARIANT = None", fp);
  }
  fputs("\n\nmain_import()\n", fp);
  if (ferror(fp)) {
    iris_atomic_abort(&af);
    return iris_error_set(err, IRIS_ERR_IO, script_path, 0, NULL, "write failed: %s", strerror(errno));
  }
  return iris_atomic_commit(&af, err);
}

