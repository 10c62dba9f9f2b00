/* Caustic photons reach the caches: on stress-caustic (a glass sphere on a
 * floor under a 10 cm light) the floor under the sphere is lit only through
 * two refractions. Its caches must point into the sphere: the cache density
 * towards the light's refracted image (straight up through the sphere) is many
 * times a uniform hemisphere's, and some of their texels are refined there.
 * Dropping the photons that passed a specular vertex (photons.c) leaves these
 * caches with only the walls' bounced light and fails this test.
 * The photons' caustic mark (iris_photon.caustic, which keeps `auto`'s guide
 * in a scene lit mostly directly): on stress-caustic the marked photons are
 * the ones under the sphere arriving from above it, indirect, and at least a
 * tenth of the indirect energy; the Cornell box (no glass) has none. */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "renderer/guiding/guiding.h"
#include "renderer/guiding/photons.h"
#include "scenes/builtin.h"
#include "guide_fixture.h"

/* Traces 65536 photon paths of the built-in scene `name` into *map. */
static bool trace(const char *name, iris_photon_map *map) {
  iris_scene *s = NULL;
  test_guide_scene t;
  memset(map, 0, sizeof *map);
  if (!test_guide_builtin_open(name, IRIS_METHOD_GUIDED_NEE, &s, &t)) return false;
  iris_error err;
  iris_error_clear(&err);
  iris_guide_setup gs = test_guide_setup(s, &t, 5, 2, 16);
  bool ok = CHECK(iris_photons_trace(&gs, IRIS_EMIT_BY_POWER, 65536, map, &err) == IRIS_OK);
  test_guide_scene_close(&t);
  iris_scene_destroy(s);
  return ok;
}

static void test_caustic_mark(void) {
  iris_photon_map m;
  if (trace("stress-caustic", &m)) {
    size_t n = 0, under = 0, direct = 0;
    double caustic = 0.0, indirect = 0.0;
    for (size_t i = 0; i < m.count; ++i) {
      const iris_photon *ph = &m.photons[i];
      if (ph->bounce > 0) indirect += ph->energy;
      if (!ph->caustic) continue;
      n++;
      caustic += ph->energy;
      direct += ph->bounce == 0;
      /* on the floor within the sphere's radius of its foot, from above */
      under += fabsf(ph->p.y) < 1e-3f && hypotf(ph->p.x, ph->p.z) < 0.5f && ph->wi.y > 0.5f;
    }
    printf("stress-caustic: %zu of %zu photons marked caustic (%zu under the sphere from above), %.2f of the indirect "
           "energy\n", n, m.count, under, indirect > 0.0 ? caustic / indirect : 0.0);
    iris_check_record(n >= 100, __FILE__, __LINE__, "only %zu caustic photons", n);
    CHECK_EQ_INT(direct, 0);
    iris_check_record(under >= (size_t)(0.9 * (double)n), __FILE__, __LINE__, "%zu of %zu caustic photons under the sphere",
                      under, n);
    iris_check_record(caustic >= 0.1 * indirect, __FILE__, __LINE__, "caustic share %.3f of the indirect energy",
                      indirect > 0.0 ? caustic / indirect : 0.0);
  }
  iris_photons_destroy(&m);
  if (trace("cornell-box", &m)) {
    size_t n = 0;
    for (size_t i = 0; i < m.count; ++i) n += m.photons[i].caustic;
    CHECK_EQ_INT(n, 0);
  }
  iris_photons_destroy(&m);
}

int main(void) {
  test_caustic_mark();
  iris_scene *s = NULL;
  iris_error err;
  if (!CHECK(iris_builtin_create("stress-caustic", &s, &err) == IRIS_OK)) return iris_check_summary("guiding.caustic");
  iris_guiding_params gp = iris_guiding_params_default();
  gp.photons = 200000;
  gp.train_spp = 0;
  gp.force = true;
  gp.refine = IRIS_REFINE_MAX; /* off by default (docs/guiding.md, "Refinement") */
  iris_guiding *g = test_guide_build(s, IRIS_METHOD_GUIDED_NEE, gp, 3, 2, 16);
  if (CHECK(g && !g->stats.skipped)) {
    /* Caches on the floor (normal up) within 12 cm of the contact point. */
    int n = 0, pointing = 0, refined = 0;
    for (size_t i = 0; i < g->cache_count; ++i) {
      const iris_cache *c = &g->caches[i];
      if (c->frame.n.y < 0.99f || fabsf(c->p.y) > 1e-3f || hypotf(c->p.x, c->p.z) > 0.12f) continue;
      uint32_t id = (uint32_t)i;
      /* up, and 15 degrees off it: inside the converging cone through the sphere */
      float up = iris_guiding_cache_pdf(g, &id, 1, iris_v3(0, 1, 0));
      float tilt = iris_guiding_cache_pdf(g, &id, 1, iris_normalize(iris_v3(0.27f, 1, 0)));
      float uniform = 1.0f / (2.0f * IRIS_PI);
      n++;
      pointing += up > 5.0f * uniform || tilt > 5.0f * uniform;
      const uint32_t texels = c->sphere ? g->sphere.texel_count : g->hemi.texel_count;
      int r = 0;
      for (uint32_t t = 0; g->refine_slot && t < texels; ++t) r += g->refine_slot[c->table + t] != 0;
      refined += r > 0;
    }
    printf("%d floor caches under the sphere: %d point into it, %d refined; %llu photons, %.0f%% indirect\n", n, pointing,
           refined, (unsigned long long)g->stats.photons_stored,
           100.0 * (double)g->stats.photons_indirect / (double)(g->stats.photons_stored ? g->stats.photons_stored : 1));
    iris_check_record(n >= 3, __FILE__, __LINE__, "caches under the sphere: %d", n);
    iris_check_record(pointing >= (3 * n + 3) / 4, __FILE__, __LINE__, "%d of %d caches point into the sphere", pointing, n);
    iris_check_record(refined >= (n + 1) / 2, __FILE__, __LINE__, "%d of %d caches refined", refined, n);
  }
  iris_guiding_destroy(g);
  iris_scene_destroy(s);
  return iris_check_summary("guiding.caustic");
}
