/* validate.gltf_canonical: canonicalisation at import, end to end from a real
 * .gltf file (no Blender): a material that is exactly Lambert (specularFactor 0,
 * metallic 0, no transmission) becomes `diffuse` with its colour and emission;
 * near misses and metals stay `gltf`; keep_materials keeps all of them. */
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "gltf_writer.h"
#include "importers/import.h"

int main(void) {
  char dir[512], path[700];
  if (iris_test_tmpdir(dir, sizeof dir, "gltf-canonical") != 0) return 1;
  gltf_writer w = {0};
  const char *mats[] = {
      "{\"name\":\"lambert\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.2,0.4,0.6,1],\"metallicFactor\":0,"
      "\"roughnessFactor\":0.3},\"emissiveFactor\":[0.5,0.25,0],\"extensions\":{\"KHR_materials_specular\":"
      "{\"specularFactor\":0}}}",
      "{\"name\":\"near\",\"pbrMetallicRoughness\":{\"metallicFactor\":0},\"extensions\":{"
      "\"KHR_materials_specular\":{\"specularFactor\":0.05}}}",
      "{\"name\":\"plastic\",\"pbrMetallicRoughness\":{\"metallicFactor\":0}}",
      "{\"name\":\"metal\",\"pbrMetallicRoughness\":{\"metallicFactor\":1,\"roughnessFactor\":0.2}}",
  };
  const int expect[] = {IRIS_MATERIAL_DIFFUSE, IRIS_MATERIAL_GLTF, IRIS_MATERIAL_GLTF, IRIS_MATERIAL_GLTF};
  for (int i = 0; i < 4; i++) {
    float p0[3] = {(float)i, 0, 0}, u[3] = {1, 0, 0}, v[3] = {0, 1, 0};
    gw_quad(&w, gw_mesh_begin(&w, gw_material(&w, mats[i])), p0, u, v, 1);
  }
  snprintf(path, sizeof path, "%s/mats.gltf", dir);
  CHECK(gw_write(&w, path) == 0);
  for (int keep = 0; keep < 2; keep++) {
    iris_import_options o = iris_import_options_default();
    o.keep_materials = keep;
    iris_scene *s = NULL;
    iris_error err;
    if (!CHECK(iris_import_file(path, &o, &s, &err) == IRIS_OK)) break;
    CHECK_EQ_INT(s->material_count, 4);
    for (size_t i = 0; i < s->material_count && i < 4; i++) {
      const iris_material *m = &s->materials[i];
      int k = !strcmp(m->name, "lambert") ? 0 : !strcmp(m->name, "near") ? 1 : !strcmp(m->name, "plastic") ? 2 : 3;
      CHECK_EQ_INT(m->type, keep ? IRIS_MATERIAL_GLTF : expect[k]);
      if (k == 0) {
        CHECK_NEAR(m->color[1], 0.4, 1e-6);
        CHECK_NEAR(m->emission[0], 0.5, 1e-6);
      }
    }
    iris_scene_destroy(s);
  }
  if (iris_check_failures == 0) iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
