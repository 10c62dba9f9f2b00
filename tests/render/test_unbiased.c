/* bsdf, nee and mis estimate the same integral: on the Cornell box, on the
 * Veach scene and on the Cornell box with glTF layers (every diffuse material
 * turned into glTF plastic with KHR_materials_clearcoat and _sheen, the last
 * box into alphaMode BLEND, alpha 0.5: stochastic pass-through) their images agree within 3 sigma per image and per 8x8 block
 * (Mitsuba test_renders.py style z-tests on the variance of each pixel's mean).
 * The threshold is the Bonferroni-corrected two-sided normal quantile for a
 * family-wise level of 0.1% over all tests of this file, so a correct renderer
 * fails with probability < 0.001; "3 sigma" is the per-test level when there
 * is a single test. Both samplers (sobol, independent) are checked. On the
 * Veach scene nee is compared over the whole image only: its blocks on the
 * sharpest plate depend on light samples that land in an alpha-0.005 lobe
 * about once in 10^5 (docs/stability.md, stress-veach-lights), so at 1024 spp
 * a block's sample variance says nothing (8192-spp runs of one such block
 * give var-of-mean 0.3 on a mean of 0.26). */
#include <stdlib.h>

#include "check.h"
#include "render_run.h"
#include "film_stats.h"
#include "renderer/render.h"
#include "scenes/builtin.h"


static bool render(const iris_scene *s, iris_method m, iris_sampler_kind k, int w, int h, int spp,
                   uint64_t seed, iris_render_result *r) {
  iris_render_params p = iris_test_params(w, h, spp, m, seed);
  p.sampler = k;
  return iris_test_render(s, &p, r);
}


/* The Cornell box with the glTF layers and a BLEND box (see the top). */
static void add_gltf_layers(iris_scene *s) {
  size_t n = s->material_count;
  for (size_t i = 0; i < n; i++) {
    iris_material *m = &s->materials[i];
    if (m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f) continue;
    iris_material g = iris_material_default(IRIS_MATERIAL_GLTF);
    memcpy(g.color, m->color, sizeof g.color);
    g.roughness = 0.6f;
    g.clearcoat = 0.8f, g.clearcoat_roughness = 0.2f;
    g.sheen_color[0] = 1.0f, g.sheen_color[1] = 0.8f, g.sheen_color[2] = 0.6f, g.sheen_roughness = 0.5f;
    g.name = m->name;
    m->name = NULL;
    *m = g;
  }
  /* the last mesh that is not an emitter gets its own BLEND copy of its material */
  for (size_t k = s->mesh_count; k-- > 0;) {
    int32_t mi = s->meshes[k].material;
    if (mi < 0 || s->materials[mi].type != IRIS_MATERIAL_GLTF) continue;
    iris_material b = s->materials[mi];
    b.name = iris_strdup("blend box");
    b.alpha_mode = IRIS_ALPHA_BLEND;
    b.alpha = 0.5f;
    s->meshes[k].material = iris_scene_add_material(s, &b);
    printf("cornell-box with glTF layers (the next three lines): mesh %zu is BLEND\n", k);
    break;
  }
}

typedef struct scene_case {
  const char *name;
  int w, h, spp;
} scene_case;

int main(void) {
  static const scene_case cases[3] = {
      {"cornell-box", 32, 32, 256}, {"veach-mis", 48, 32, 1024}, {"cornell-box", 32, 32, 256}};
  static const iris_method methods[3] = {IRIS_METHOD_BSDF, IRIS_METHOD_NEE, IRIS_METHOD_MIS};
  /* tests: per scene, 3 pairs x 3 channels x (1 image + blocks) */
  int n_tests = 0;
  /* cornell-box and veach-mis with both samplers, the glTF-layer box with sobol */
  for (int c = 0; c < 3; c++) n_tests += (c < 2 ? 2 : 1) * 3 * 3 * (1 + (cases[c].w / 8) * (cases[c].h / 8));
  double z_max = z_for_alpha(1e-3 / n_tests);
  printf("%d tests, |z| < %.2f\n", n_tests, z_max);
  for (int kc = 0; kc < 5; kc++) {
    const int c = kc < 3 ? kc : kc - 3;
    const iris_sampler_kind kind = kc < 3 ? IRIS_SAMPLER_SOBOL : IRIS_SAMPLER_INDEPENDENT;
    iris_scene *s = NULL;
    iris_error err;
    if (!CHECK(iris_builtin_create(cases[c].name, &s, &err) == IRIS_OK)) continue;
    if (c == 2) add_gltf_layers(s);
    iris_render_result r[3];
    bool ok[3];
    for (int m = 0; m < 3; m++)
      ok[m] = CHECK(render(s, methods[m], kind, cases[c].w, cases[c].h, cases[c].spp, 100 + (uint64_t)m, &r[m]));
    for (int a = 0; a < 3; a++)
      for (int b = a + 1; b < 3; b++) {
        if (!ok[a] || !ok[b]) continue;
        int bx = cases[c].w / 8, by = cases[c].h / 8;
        const bool image_only = c == 1 && (methods[a] == IRIS_METHOD_NEE || methods[b] == IRIS_METHOD_NEE);
        char pair[200];
        snprintf(pair, sizeof pair, "%s %s: %s vs %s", cases[c].name, iris_sampler_kind_name(kind),
                 iris_method_name(methods[a]), iris_method_name(methods[b]));
        double worst = iris_test_z_compare(&r[a].film, &r[b].film, image_only ? 0 : bx, by, z_max, z_max, pair);
        printf("%s%s %s: %s vs %s: worst |z| = %.2f\n", cases[c].name, c == 2 ? "+gltf" : "",
               iris_sampler_kind_name(kind), iris_method_name(methods[a]),
               iris_method_name(methods[b]), worst);
      }
    for (int m = 0; m < 3; m++) {
      if (!ok[m]) continue;
      CHECK_EQ_INT(r[m].stats.nan_count, 0);
      iris_render_result_destroy(&r[m]);
    }
    iris_scene_destroy(s);
  }
  return iris_check_summary("render.unbiased");
}
