/* The guide and the guided image do not depend on the thread count (with the
 * training samples kept in the image and without): photons,
 * cache placement, filling and the cache tables built with 1 and 2 threads are
 * identical byte for byte, and guided-nee renders of the door scene with 1 and
 * 2 threads match bit for bit (preprocessing included), as do those of the
 * sky-room (light sampling of the map from the caches' sky visibility); the
 * door's renders connect to light-vertex caches (vcache.h), whose pools are
 * built in parallel too. A
 * different seed gives different caches (the test can fail). */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "render_run.h"
#include "renderer/accel.h"
#include "renderer/guiding/guiding.h"
#include "renderer/lights.h"
#include "renderer/render.h"
#include "renderer/texture.h"
#include "scenes/builtin.h"
#include "guide_fixture.h"

static iris_guiding *build(const iris_scene *s, int threads, uint64_t seed) {
  iris_guiding_params gp = iris_guiding_params_default();
  gp.photons = 60000;
  gp.train_spp = 7; /* three training passes (1 + 2 + 4 spp) */
  gp.refine = IRIS_REFINE_MAX; /* refinement too (off by default), trained */
  return test_guide_build(s, IRIS_METHOD_GUIDED_NEE, gp, seed, threads, 64);
}

static size_t table_floats(const iris_guiding *g) {
  size_t n = 0;
  for (size_t i = 0; i < g->cache_count; ++i) {
    size_t end = g->caches[i].table + (g->caches[i].sphere ? g->sphere.texel_count : g->hemi.texel_count);
    if (end > n) n = end;
  }
  return n;
}

static bool same_guide(const iris_guiding *a, const iris_guiding *b) {
  if (a->cache_count != b->cache_count || a->stats.photons_stored != b->stats.photons_stored) return false;
  size_t n = table_floats(a);
  if ((a->refine_slot == NULL) != (b->refine_slot == NULL)) return false;
  if (a->refine_slot && (memcmp(a->refine_slot, b->refine_slot, n) != 0 ||
                         memcmp(a->refine_sub, b->refine_sub,
                                sizeof(float) * IRIS_REFINE_MAX * IRIS_REFINE_SUB * (n / a->hemi.texel_count)) != 0))
    return false; /* refinement (refine.h) */
  return n == table_floats(b) && memcmp(a->caches, b->caches, a->cache_count * sizeof(iris_cache)) == 0 &&
         memcmp(a->pdf, b->pdf, n * sizeof(float)) == 0 && memcmp(a->alias, b->alias, n * sizeof(iris_cache_alias)) == 0;
}

static bool render(const iris_scene *s, int threads, bool keep, iris_render_result *r) {
  /* 40 x 30: not a multiple of the 8-pixel tiles */
  iris_render_params p = iris_test_params(40, 30, 6, IRIS_METHOD_GUIDED_NEE, 5);
  p.keep_training = keep; /* the training samples in the image, or not */
  p.connect = IRIS_CONNECT_ON; /* the door's connections to light paths (vcache.h) too */
  iris_guiding_params gp = iris_guiding_params_default();
  gp.photons = 60000;
  gp.train_spp = 3; /* the render trains its guide too */
  gp.refine = IRIS_REFINE_MAX;
  p.threads = threads;
  iris_test_attach_guide(&p, &gp);
  return iris_test_render(s, &p, r);
}

static bool same_film(const iris_film *a, const iris_film *b) {
  size_t n = (size_t)a->width * (size_t)a->height;
  return a->width == b->width && a->height == b->height &&
         memcmp(a->sum, b->sum, 3 * n * sizeof(double)) == 0 &&
         memcmp(a->sum2, b->sum2, 3 * n * sizeof(double)) == 0 &&
         memcmp(a->count, b->count, n * sizeof(uint32_t)) == 0;
}

int main(void) {
  iris_scene *s = NULL;
  iris_error err;
  if (!CHECK(iris_builtin_create("door", &s, &err) == IRIS_OK)) return iris_check_summary("guiding.determinism");
  iris_guiding *g1 = build(s, 1, 3), *g2 = build(s, 2, 3), *g3 = build(s, 2, 4);
  if (CHECK(g1 && g2 && g3)) {
    CHECK(!g1->stats.skipped && g1->cache_count > 100);
    CHECK(same_guide(g1, g2));
    CHECK(!same_guide(g1, g3));
    printf("guide: %zu caches, identical for 1 and 2 threads\n", g1->cache_count);
  }
  iris_guiding_destroy(g1);
  iris_guiding_destroy(g2);
  iris_guiding_destroy(g3);
  for (int keep = 0; keep < 2; keep++) {
    iris_render_result r1, r2;
    if (CHECK(render(s, 1, keep, &r1))) {
      CHECK_EQ_INT(r1.train_spp, keep ? 3 : 0);
      CHECK_EQ_INT((int)r1.film.count[0], keep ? 9 : 6);
      CHECK(r1.connect_rays > 0); /* the connections ran */
      if (CHECK(render(s, 2, keep, &r2))) {
        CHECK(same_film(&r1.film, &r2.film));
        CHECK(r1.connect_rays == r2.connect_rays);
        iris_render_result_destroy(&r2);
      }
      iris_render_result_destroy(&r1);
    }
  }
  iris_scene_destroy(s);
  s = NULL;
  if (CHECK(iris_builtin_create("sky-room", &s, &err) == IRIS_OK)) {
    iris_render_result r1, r2;
    if (CHECK(render(s, 1, true, &r1))) {
      if (CHECK(render(s, 2, true, &r2))) {
        CHECK(same_film(&r1.film, &r2.film));
        iris_render_result_destroy(&r2);
      }
      iris_render_result_destroy(&r1);
    }
    iris_scene_destroy(s);
  }
  return iris_check_summary("guiding.determinism");
}
