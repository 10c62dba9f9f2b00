/* bsdf.canonical: the glTF material classes of scene/material_class.h against
 * the renderer's own gltf BSDF. Every material that iris_material_canonicalize
 * rewrites must evaluate (f and the sampled weight) exactly like the original at
 * random direction pairs, and materials just outside the Lambert rule must not
 * be rewritten (their f differs measurably, so rewriting them would be a bug). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "renderer/bsdf.h"
#include "scene/material_class.h"

static double rnd(uint64_t *s) {
  *s = *s * 6364136223846793005ull + 1442695040888963407ull;
  return (double)(*s >> 11) / 9007199254740992.0;
}

static iris_vec3 rnd_dir(uint64_t *s) {
  double z = rnd(s), phi = 6.283185307179586 * rnd(s), r = sqrt(fmax(0.0, 1.0 - z * z));
  return iris_v3((float)(r * cos(phi)), (float)(r * sin(phi)), (float)z);
}

/* Largest relative difference of f between two materials over n pairs. */
static double max_rel_diff(const iris_material *a, const iris_material *b, int n, uint64_t seed) {
  iris_vec3 ca = iris_v3(a->color[0], a->color[1], a->color[2]);
  iris_vec3 cb = iris_v3(b->color[0], b->color[1], b->color[2]);
  iris_bsdf ba = iris_bsdf_from_material(a, ca, a->roughness, a->metallic);
  iris_bsdf bb = iris_bsdf_from_material(b, cb, b->roughness, b->metallic);
  double worst = 0.0;
  for (int i = 0; i < n; i++) {
    iris_vec3 wo = rnd_dir(&seed), wi = rnd_dir(&seed);
    iris_vec3 fa = iris_bsdf_eval(&ba, wo, wi), fb = iris_bsdf_eval(&bb, wo, wi);
    float da[3] = {fa.x, fa.y, fa.z}, db[3] = {fb.x, fb.y, fb.z};
    for (int k = 0; k < 3; k++) {
      double d = fabs((double)da[k] - (double)db[k]) / fmax(1e-12, fmax(fabs(da[k]), fabs(db[k])));
      if (da[k] == 0.0f && db[k] == 0.0f) d = 0.0;
      if (d > worst) worst = d;
    }
  }
  return worst;
}

static iris_material gltf(float r, float g, float b, float metallic, float rough, float spec,
                          float trans) {
  iris_material m = iris_material_default(IRIS_MATERIAL_GLTF);
  m.color[0] = r;
  m.color[1] = g;
  m.color[2] = b;
  m.metallic = metallic;
  m.roughness = rough;
  m.specular = spec;
  m.transmission = trans;
  return m;
}

int main(void) {
  CHECK(fabsf(IRIS_SMOOTH_ROUGHNESS - IRIS_BSDF_MIN_ROUGHNESS) < 1e-5f);

  /* Lambert class: rewritten to diffuse, and f identical. */
  uint64_t s = 99;
  for (int i = 0; i < 50; i++) {
    iris_material m = gltf((float)rnd(&s), (float)rnd(&s), (float)rnd(&s), 0.0f, (float)rnd(&s),
                           0.0f, 0.0f);
    m.ior = 1.0f + 2.0f * (float)rnd(&s);
    m.specular_color[1] = 2.0f * (float)rnd(&s);
    m.emission[0] = (float)rnd(&s);
    m.color_texture = i % 3 - 1;
    iris_material c = m;
    CHECK_EQ_INT(iris_material_gltf_class(&m), IRIS_GLTF_LAMBERT);
    CHECK(iris_material_canonicalize(&c));
    CHECK_EQ_INT(c.type, IRIS_MATERIAL_DIFFUSE);
    CHECK_EQ_INT(c.color_texture, m.color_texture);
    CHECK(c.emission[0] == m.emission[0]);
    CHECK(max_rel_diff(&m, &c, 2000, 7 + (uint64_t)i) < 1e-5);
  }

  /* Just outside the rule: not rewritten, and f really differs from a Lambert of
   * the same colour (so the rule is not too loose either). */
  const iris_material near_misses[] = {
      gltf(0.5f, 0.5f, 0.5f, 0.0f, 1.0f, 0.05f, 0.0f), /* a little specular */
      gltf(0.5f, 0.5f, 0.5f, 0.05f, 1.0f, 0.0f, 0.0f), /* a little metal */
      gltf(0.5f, 0.5f, 0.5f, 0.0f, 1.0f, 0.0f, 0.3f),  /* transmission */
      gltf(0.5f, 0.5f, 0.5f, 0.0f, 1.0f, 1.0f, 0.0f),  /* glTF's default dielectric */
  };
  for (size_t i = 0; i < sizeof near_misses / sizeof *near_misses; i++) {
    iris_material m = near_misses[i], c = m;
    CHECK(iris_material_gltf_class(&m) != IRIS_GLTF_LAMBERT);
    CHECK(!iris_material_canonicalize(&c));
    CHECK_EQ_INT(c.type, IRIS_MATERIAL_GLTF);
    iris_material lambert = iris_material_default(IRIS_MATERIAL_DIFFUSE);
    for (int k = 0; k < 3; k++) lambert.color[k] = m.color[k];
    double d = max_rel_diff(&m, &lambert, 2000, 3);
    if (!CHECK(d > 1e-3)) printf("near miss %zu differs from Lambert by only %g\n", i, d);
  }

  /* The other classes. */
  iris_material metal = gltf(0.9f, 0.6f, 0.3f, 1.0f, 0.3f, 1.0f, 0.0f);
  CHECK_EQ_INT(iris_material_gltf_class(&metal), IRIS_GLTF_CONDUCTOR);
  metal.metallic_roughness_texture = 0; /* metallic = 1 x texture: not known to be 1 */
  CHECK_EQ_INT(iris_material_gltf_class(&metal), IRIS_GLTF_GENERAL);
  iris_material textured0 = gltf(0.9f, 0.6f, 0.3f, 0.0f, 0.3f, 0.0f, 0.0f);
  textured0.metallic_roughness_texture = 0; /* metallic = 0 x texture = 0 */
  CHECK_EQ_INT(iris_material_gltf_class(&textured0), IRIS_GLTF_LAMBERT);
  /* KHR_materials_transmission / _specular textures multiply their factors:
   * with factors 0 they change nothing (still a Lambert, rewritten, textures
   * dropped); with a factor above 0 they do not make a Lambert. */
  iris_material tex0 = gltf(0.9f, 0.6f, 0.3f, 0.0f, 0.3f, 0.0f, 0.0f);
  tex0.transmission_texture = tex0.specular_texture = tex0.specular_color_texture = 0;
  CHECK_EQ_INT(iris_material_gltf_class(&tex0), IRIS_GLTF_LAMBERT);
  CHECK(iris_material_canonicalize(&tex0));
  CHECK(tex0.transmission_texture < 0 && tex0.specular_texture < 0 && tex0.specular_color_texture < 0);
  iris_material spec_tex = gltf(0.9f, 0.6f, 0.3f, 0.0f, 0.3f, 0.5f, 0.0f);
  spec_tex.specular_texture = 0;
  CHECK(iris_material_gltf_class(&spec_tex) != IRIS_GLTF_LAMBERT);
  CHECK(!iris_material_canonicalize(&spec_tex));
  iris_material glass = gltf(1, 1, 1, 0.0f, 0.0f, 1.0f, 1.0f);
  CHECK_EQ_INT(iris_material_gltf_class(&glass), IRIS_GLTF_DIELECTRIC);
  glass.transmission_texture = 0; /* transmission = 1 x texture R: not known to be 1 */
  CHECK_EQ_INT(iris_material_gltf_class(&glass), IRIS_GLTF_GENERAL);
  glass.transmission_texture = -1;
  CHECK(iris_material_gltf_smooth(&glass));
  glass.roughness = 0.02f;
  CHECK(!iris_material_gltf_smooth(&glass));
  iris_material diffuse = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  CHECK_EQ_INT(iris_material_gltf_class(&diffuse), IRIS_GLTF_NOT_GLTF);
  CHECK(!iris_material_canonicalize(&diffuse));
  return TEST_SUMMARY();
}
