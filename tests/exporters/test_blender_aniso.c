/* exporters.blender_aniso: KHR_materials_anisotropy in the Blender export.
 * The script carries the material's anisotropy and wires Principled v1's
 * Anisotropic, Anisotropic Rotation, Roughness and Tangent (a UV-map Tangent
 * node); run in Blender 3.4, the node values must give, through Cycles 3.4's
 * own formula (alpha_x = r^2 / a, alpha_y = r^2 a, a = sqrt(1 - 0.9 Anisotropic)),
 * the extension's alpha_t = mix(alpha, 1, s^2) and alpha_b = alpha, and the
 * rotation in turns. Beyond alpha_t / alpha_b = 10 Anisotropic is 1 (the
 * documented residual). The Blender part SKIPs (77) without blender. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/fileio.h"
#include "core/image.h"
#include "exporters/blender.h"
#include "fixture.h"

/* A 2x2 in-memory PNG (direction RG, strength B), as glTF-embedded images are held. */
static int32_t add_texture(iris_scene *s, const char *dir) {
  const float texel[4][3] = {{1, 0.5f, 1}, {0.5f, 1, 1}, {0.5f, 0.5f, 0.5f}, {0, 0.5f, 0.25f}};
  return fixture_add_png_texture(s, dir, "direction", texel, false);
}

static iris_scene *aniso_scene(const char *dir) {
  iris_scene *s = iris_scene_create();
  iris_material m = iris_material_default(IRIS_MATERIAL_GLTF);
  m.name = iris_strdup("brushed");
  m.metallic = 1.0f, m.roughness = 0.3f, m.anisotropy = 0.8f, m.anisotropy_rotation = 0.5f;
  iris_scene_add_material(s, &m);
  m = iris_material_default(IRIS_MATERIAL_GLTF);
  m.name = iris_strdup("smooth");
  m.metallic = 1.0f, m.roughness = 0.1f, m.anisotropy = 1.0f, m.anisotropy_rotation = -1.0f;
  iris_scene_add_material(s, &m);
  m = iris_material_default(IRIS_MATERIAL_GLTF);
  m.name = iris_strdup("plain");
  iris_scene_add_material(s, &m);
  m = iris_material_default(IRIS_MATERIAL_GLTF);
  m.name = iris_strdup("textured");
  m.metallic = 1.0f, m.roughness = 0.4f, m.anisotropy = 0.9f, m.anisotropy_texture = add_texture(s, dir);
  iris_scene_add_material(s, &m);
  for (int k = 0; k < 4; k++) {
    fixture_quad q = {(float)k - 1.5f, 0, 0, 0.4f, 0.4f, false, true, true, NULL, NULL, k};
    char name[16];
    snprintf(name, sizeof name, "q%d", k);
    int32_t mesh = fixture_add_quad(s, name, &q);
    fixture_add_instance(s, mesh, 0, 0, 0);
  }
  fixture_add_top_camera(s, 10.0f, 2.0f, 1.0f);
  const float env[3] = {1, 1, 1};
  iris_scene_set_environment_color(s, env);
  return s;
}

static const char *const INSPECT =
    "import bpy\n"
    "for mat in bpy.data.materials:\n"
    "    if not mat.use_nodes: continue\n"
    "    for n in mat.node_tree.nodes:\n"
    "        if n.type != 'BSDF_PRINCIPLED': continue\n"
    "        i = n.inputs\n"
    "        t = i['Tangent'].links[0].from_node if i['Tangent'].is_linked else None\n"
    "        print('IRIS_ANISO %s %.7f %.7f %.7f %s %s' % (mat.name, i['Roughness'].default_value,\n"
    "              i['Anisotropic'].default_value, i['Anisotropic Rotation'].default_value,\n"
    "              t.type if t else 'NONE', t.direction_type if t and t.type == 'TANGENT' else 'NONE'))\n"
    "        print('IRIS_ANISO_LINKS %s %d %d' % (mat.name, i['Anisotropic'].is_linked, i['Roughness'].is_linked))\n";

/* Checks one material's Principled values against the extension. */
static void check_values(const char *log, const char *name, float roughness, float strength, float rotation) {
  char key[64];
  snprintf(key, sizeof key, "IRIS_ANISO %s ", name);
  const char *line = strstr(log, key);
  if (!CHECK(line != NULL)) return;
  double r, an, rot;
  char node[32], dir[32];
  if (!CHECK(sscanf(line + strlen(key), "%lf %lf %lf %31s %31s", &r, &an, &rot, node, dir) == 5)) return;
  double alpha = (double)roughness * roughness, s = strength;
  double at = alpha + (1.0 - alpha) * s * s, ab = alpha;
  double aspect = sqrt(1.0 - 0.9 * an); /* Cycles 3.4 svm_closure.h, Principled v1 */
  double ax = r * r / aspect, ay = r * r * aspect;
  if (at / ab <= 10.0) {
    CHECK(fabs(ax - at) < 1e-4 * at);
    CHECK(fabs(ay - ab) < 1e-4 * ab);
  } else { /* the residual: Cycles' largest ratio, 10, with the same alpha_x alpha_y */
    CHECK(fabs(an - 1.0) < 1e-6);
    CHECK(fabs(ax * ay - at * ab) < 1e-4 * at * ab);
  }
  double turns = fmod(rotation / (2.0 * 3.14159265358979323846) + 1.0, 1.0);
  CHECK(fabs(rot - turns) < 1e-5);
  CHECK_EQ_STR(node, "TANGENT");
  CHECK_EQ_STR(dir, "UV_MAP");
}

int main(void) {
  char dir[1024], script[1200], inspect[1200], exr[1200], log[1200], blender[1024];
  if (iris_test_tmpdir(dir, sizeof dir, "export-blender-aniso") != 0) return TEST_SKIP("no temporary folder");
  iris_scene *s = aniso_scene(dir);
  iris_export_params p = iris_export_params_default();
  p.width = 8, p.height = 8, p.max_depth = 2;
  snprintf(script, sizeof script, "%s/aniso.py", dir);
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_export_blender(s, script, &p, &err), &err);
  iris_scene_destroy(s);
  char *text = fixture_read_text(script);
  CHECK(text != NULL);
  if (text) { /* the material table carries the values; the builder wires them */
    CHECK(strstr(text, "aniso=0.800000012, aniso_rot=0.5, aniso_tex=-1") != NULL);
    CHECK(strstr(text, "aniso=0.0, aniso_rot=0.0, aniso_tex=-1") != NULL);
    CHECK(strstr(text, "anisotropy(nt, bsdf, m, rough)") != NULL);
    CHECK(strstr(text, "bsdf.inputs[\"Anisotropic Rotation\"]") != NULL);
    CHECK(strstr(text, "nt.links.new(t_sock, bsdf.inputs[\"Tangent\"])") != NULL);
  }
  free(text);
  if (!fixture_find_tool("blender", blender, sizeof blender)) {
    if (iris_check_failures) return iris_check_summary("exporters.blender_aniso");
    return TEST_SKIP("blender is not installed");
  }
  snprintf(inspect, sizeof inspect, "%s/inspect.py", dir);
  FILE *f = fopen(inspect, "w");
  if (!CHECK(f != NULL)) return 1;
  fputs(INSPECT, f);
  fclose(f);
  snprintf(exr, sizeof exr, "%s/aniso.exr", dir);
  snprintf(log, sizeof log, "%s/aniso.log", dir);
  char cmd[5000];
  snprintf(cmd, sizeof cmd,
           "'%s' -b --factory-startup --python-exit-code 1 -P '%s' -P '%s' -- --output '%s' --spp 1 --threads 2",
           blender, script, inspect, exr);
  int rc = fixture_run(cmd, log);
  char *out = fixture_read_text(log);
  if (!CHECK(rc == 0 && out)) fprintf(stderr, "blender failed (%d):\n%s\n", rc, out ? out : "(no log)");
  if (out) {
    check_values(out, "brushed", 0.3f, 0.8f, 0.5f);
    check_values(out, "smooth", 0.1f, 1.0f, -1.0f);
    /* textured: strength x B and the direction T (2R - 1) + (N x T) (2G - 1) are node graphs */
    CHECK(strstr(out, "IRIS_ANISO textured ") && strstr(strstr(out, "IRIS_ANISO textured "), " VECT_MATH NONE"));
    CHECK(strstr(out, "IRIS_ANISO_LINKS textured 1 1") != NULL);
    CHECK(strstr(out, "IRIS_ANISO_LINKS brushed 0 0") != NULL);
  }
  free(out);
  if (!iris_check_failures) iris_test_rmtree(dir);
  else printf("files kept in %s\n", dir);
  return iris_check_summary("exporters.blender_aniso");
}
