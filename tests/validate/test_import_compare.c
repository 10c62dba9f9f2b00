/* validate.import_compare: validate/import_compare.c against hand-written
 * inventories (what the Blender script writes), no Blender needed: agreement
 * gives only the material-model note; a different triangle count or bounds
 * off by > 2% of the diagonal are geometry differences (the run fails); a 1%
 * offset, a light in photometric units, a different camera angle, other unit
 * settings and a different base colour are reported, not fatal. The features measured on
 * the glass lamp (docs/import-gltf.md) are named for a material that has them: one-sided
 * emission, MASK against Blender's stochastic Alpha, Blender's textured Transmission, and
 * the clearcoat layering; a material without them gets none of these notes. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "validate/import_compare.h"

static iris_scene *scene(void) {
  iris_scene *s = iris_scene_create();
  iris_material m = iris_material_default(IRIS_MATERIAL_GLTF);
  m.name = iris_strdup("paint");
  m.color[0] = m.color[1] = m.color[2] = 0.5f;
  m.metallic = 0.0f;
  m.roughness = 0.5f;
  int32_t mat = iris_scene_add_material(s, &m);
  iris_mesh me;
  memset(&me, 0, sizeof me);
  me.name = iris_strdup("quad");
  me.vertex_count = 4;
  me.triangle_count = 2;
  me.positions = malloc(12 * sizeof(float));
  me.indices = malloc(6 * sizeof(uint32_t));
  const float p[12] = {0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 1, 0};
  const uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
  memcpy(me.positions, p, sizeof p);
  memcpy(me.indices, ix, sizeof ix);
  me.material = mat;
  me.owned = true;
  iris_instance inst = {(uint32_t)iris_scene_add_mesh(s, &me), iris_mat4_identity()};
  iris_scene_add_instance(s, &inst);
  iris_camera c;
  memset(&c, 0, sizeof c);
  c.name = iris_strdup("cam");
  c.to_world = iris_mat4_identity();
  c.yfov = 0.8f;
  c.aspect = 1.5f;
  iris_scene_add_camera(s, &c);
  iris_light l;
  memset(&l, 0, sizeof l);
  l.name = iris_strdup("bulb");
  l.type = IRIS_LIGHT_POINT;
  l.color[0] = l.color[1] = l.color[2] = 1.0f;
  l.intensity = 10.0f;
  iris_scene_add_light(s, &l);
  return s;
}

static void inventory(const char *path, int triangles, double hi_x, double power, double angle_y,
                      double scale, double base) {
  FILE *f = fopen(path, "w");
  fprintf(f,
          "{\"unit_system\": \"METRIC\", \"unit_scale\": %g, \"triangles\": %d, \"meshes\": 1,"
          " \"meshes_with_colors\": 0, \"bounds\": [[0, 0, 0], [%.9g, 1, 0]],"
          " \"cameras\": [{\"name\": \"cam\", \"type\": \"PERSP\", \"sensor_fit\": \"VERTICAL\","
          " \"angle_y\": %.9g, \"angle_x\": 1.1, \"position\": [0, 0, 0]}],"
          " \"lights\": [{\"name\": \"bulb\", \"type\": \"POINT\", \"color\": [1, 1, 1], \"power\": %.9g,"
          " \"position\": [0, 0, 0]}],"
          " \"materials\": [{\"name\": \"paint\", \"nodes\": [\"ShaderNodeBsdfPrincipled\"], \"blend_method\": \"OPAQUE\","
          " \"Base Color\": [%g, %g, %g], \"Metallic\": 0.0, \"Roughness\": 0.5, \"Specular\": 0.5,"
          " \"Transmission\": 0.0, \"IOR\": 1.5, \"Emission\": [0, 0, 0], \"Emission Strength\": 1.0, \"Alpha\": 1.0}]}",
          scale, triangles, hi_x, angle_y, power, base, base, base);
  fclose(f);
}

static int count_topic(const iris_import_diff *d, const char *topic, const char *needle) {
  int n = 0;
  for (int i = 0; i < d->note_count; i++)
    if (!strcmp(d->notes[i].topic, topic) && (!needle || strstr(d->notes[i].text, needle))) n++;
  return n;
}

int main(void) {
  char dir[512], path[700];
  if (iris_test_tmpdir(dir, sizeof dir, "import-compare") != 0) return 1;
  snprintf(path, sizeof path, "%s/inv.json", dir);
  iris_scene *s = scene();
  const double want_power = 4.0 * 3.14159265358979 * 10.0;
  iris_import_diff d;
  iris_error err;

  inventory(path, 2, 2.0, want_power, 0.8, 1.0, 0.5); /* agreement */
  CHECK(iris_import_compare(s, path, &d, &err) == IRIS_OK);
  CHECK(!d.geometry_differs);
  CHECK_EQ_INT(d.total, 1); /* only "iris renders ..., Blender ... Principled" */
  CHECK_EQ_INT(count_topic(&d, "material", "Principled"), 1);

  inventory(path, 4, 2.0, want_power, 0.8, 1.0, 0.5); /* another triangle count */
  CHECK(iris_import_compare(s, path, &d, &err) == IRIS_OK);
  CHECK(d.geometry_differs);
  CHECK_EQ_INT(count_topic(&d, "geometry", "triangles"), 1);

  inventory(path, 2, 2.02, want_power, 0.8, 1.0, 0.5); /* 0.9% of the diagonal: reported */
  CHECK(iris_import_compare(s, path, &d, &err) == IRIS_OK);
  CHECK(!d.geometry_differs);
  CHECK_EQ_INT(count_topic(&d, "geometry", "bounds"), 1);

  inventory(path, 2, 2.1, want_power, 0.8, 1.0, 0.5); /* 4.5%: another scene */
  CHECK(iris_import_compare(s, path, &d, &err) == IRIS_OK);
  CHECK(d.geometry_differs);

  /* photometric light (Blender's importer: W = cd x 4 pi / 683), wider camera,
   * centimetres, another base colour: four notes, none fatal */
  inventory(path, 2, 2.0, want_power / 683.0, 0.9, 0.01, 0.6);
  CHECK(iris_import_compare(s, path, &d, &err) == IRIS_OK);
  CHECK(!d.geometry_differs);
  CHECK_EQ_INT(count_topic(&d, "light", "ratio 0.001464"), 1);
  CHECK_EQ_INT(count_topic(&d, "camera", "yfov"), 1);
  CHECK_EQ_INT(count_topic(&d, "units", NULL), 1);
  CHECK_EQ_INT(count_topic(&d, "material", "base colour"), 1);
  CHECK_EQ_INT(d.total, 5);

  /* the glass lamp's shade: emissive, MASK, transmission 1 (textured in Blender), clearcoat */
  iris_material *g = &s->materials[0];
  g->emission[0] = g->emission[1] = g->emission[2] = 1.0f;
  g->emission_two_sided = false; /* glTF, not doubleSided */
  g->alpha_mode = IRIS_ALPHA_MASK;
  g->transmission = 1.0f;
  g->clearcoat = 1.0f;
  FILE *f = fopen(path, "w");
  fputs("{\"unit_system\": \"METRIC\", \"unit_scale\": 1, \"triangles\": 2, \"meshes\": 1,"
        " \"meshes_with_colors\": 0, \"bounds\": [[0, 0, 0], [2, 1, 0]], \"cameras\": [{\"name\": \"cam\","
        " \"angle_y\": 0.8}], \"lights\": [{\"name\": \"bulb\", \"type\": \"POINT\", \"power\": 125.66370614},"
        " {\"name\": \"x\"}],"
        " \"materials\": [{\"name\": \"paint\", \"blend_method\": \"CLIP\", \"Base Color\": [0.5, 0.5, 0.5],"
        " \"Metallic\": 0.0, \"Roughness\": 0.5, \"Specular\": 0.5, \"Transmission\": \"linked:ShaderNodeSeparateColor\","
        " \"IOR\": 1.5, \"Emission\": [1, 1, 1], \"Emission Strength\": 1.0,"
        " \"Alpha\": \"linked:ShaderNodeTexImage\"}]}", f);
  fclose(f);
  CHECK(iris_import_compare(s, path, &d, &err) == IRIS_OK);
  CHECK_EQ_INT(count_topic(&d, "material", "front face only"), 1);
  CHECK_EQ_INT(count_topic(&d, "material", "stochastic transparency"), 1);
  CHECK_EQ_INT(count_topic(&d, "material", "textures Transmission"), 1);
  CHECK_EQ_INT(count_topic(&d, "material", "Clearcoat lobe"), 1);
  for (int i = 0; i < d.note_count; i++) printf("  %s: %s\n", d.notes[i].topic, d.notes[i].text);
  g->transmission_texture = 0; /* iris reads the transmission texture too: nothing to name */
  CHECK(iris_import_compare(s, path, &d, &err) == IRIS_OK);
  CHECK_EQ_INT(count_topic(&d, "material", "textures Transmission"), 0);
  g->transmission_texture = -1;
  g->emission_two_sided = true; /* doubleSided: emits from both faces in both */
  g->alpha_mode = IRIS_ALPHA_OPAQUE;
  g->clearcoat = 0.0f;
  CHECK(iris_import_compare(s, path, &d, &err) == IRIS_OK);
  CHECK_EQ_INT(count_topic(&d, "material", "front face only"), 0);
  CHECK_EQ_INT(count_topic(&d, "material", "stochastic transparency"), 0);
  CHECK_EQ_INT(count_topic(&d, "material", "Clearcoat lobe"), 0);

  f = fopen(path, "w");
  fputs("not json", f);
  fclose(f);
  CHECK(iris_import_compare(s, path, &d, &err) != IRIS_OK);
  snprintf(path, sizeof path, "%s/missing.json", dir);
  CHECK(iris_import_compare(s, path, &d, &err) != IRIS_OK);

  iris_scene_destroy(s);
  if (iris_check_failures == 0) iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
