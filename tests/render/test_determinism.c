/* Random numbers are a pure function of (seed, pixel, sample, dimension): the
 * Cornell box rendered with 1 and with 2 threads must match bit for bit, and a
 * different seed must give a different image. */
#include <stdlib.h>

#include "check.h"
#include "renderer/render.h"
#include "scenes/builtin.h"

static bool render(const iris_scene *s, int threads, uint64_t seed, iris_method m,
                   iris_render_result *r) {
  iris_render_params p = iris_render_params_default();
  p.width = 40;
  p.height = 24; /* not a multiple of the 8-pixel tiles */
  p.spp = 12;
  p.threads = threads;
  p.seed = seed;
  p.method = m;
  iris_error err;
  iris_error_clear(&err);
  if (iris_render(s, &p, r, &err) != IRIS_OK) {
    fprintf(stderr, "render failed: %s\n", err.message);
    return false;
  }
  return true;
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
  if (!CHECK(iris_builtin_create("cornell-box", &s, &err) == IRIS_OK)) return iris_check_summary("render.determinism");
  static const iris_method methods[3] = {IRIS_METHOD_BSDF, IRIS_METHOD_NEE, IRIS_METHOD_MIS};
  for (int i = 0; i < 3; i++) {
    iris_render_result r1, r2, r3;
    if (!CHECK(render(s, 1, 42, methods[i], &r1))) continue;
    if (CHECK(render(s, 2, 42, methods[i], &r2))) {
      iris_check_record(same_film(&r1.film, &r2.film), __FILE__, __LINE__,
                        "%s: 1 and 2 threads differ", iris_method_name(methods[i]));
      CHECK_EQ_INT(r1.stats.rays, r2.stats.rays);
      CHECK_EQ_INT(r1.stats.shadow_rays, r2.stats.shadow_rays);
      iris_render_result_destroy(&r2);
    }
    if (CHECK(render(s, 2, 43, methods[i], &r3))) {
      iris_check_record(!same_film(&r1.film, &r3.film), __FILE__, __LINE__,
                        "%s: seeds 42 and 43 give the same image", iris_method_name(methods[i]));
      iris_render_result_destroy(&r3);
    }
    iris_render_result_destroy(&r1);
  }
  iris_scene_destroy(s);
  return iris_check_summary("render.determinism");
}
