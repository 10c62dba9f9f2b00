/* Photons through glass keep their power: sky-room-glazed is sky-room with a
 * closed 2 cm glass slab in the window, so the caches inside must estimate
 * about the radiance of sky-room's (the slab passes ~85% of the light), as
 * the adjoint Russian roulette reads it. A delta lobe's f carries 1/|cos wi|
 * (bsdf.c); a photon weighted by f without the cosine gained that factor at
 * every glass interface, up to 10^9 for photons guided inside the slab at
 * grazing angles (docs/guiding.md, "Sky behind glass"), and fails here. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "renderer/guiding/guiding.h"
#include "scenes/builtin.h"
#include "guide_fixture.h"

static int cmp_float(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

/* Median radiance estimate of the caches inside the room (the room is
 * x, z in [-2, 2], y in [0, 2.5]); -1 when the guide failed. */
static float inside_median(const char *scene) {
  iris_scene *s = NULL;
  iris_error err;
  if (!CHECK(iris_builtin_create(scene, &s, &err) == IRIS_OK)) return -1.0f;
  iris_guiding_params gp = iris_guiding_params_default();
  gp.train_spp = 0; /* the photons' estimate alone */
  gp.force = true;
  iris_guiding *g = test_guide_build(s, IRIS_METHOD_GUIDED_NEE, gp, 3, 2, 16);
  float median = -1.0f;
  if (CHECK(g && !g->stats.skipped)) {
    float *r = malloc(sizeof(float) * (g->cache_count ? g->cache_count : 1));
    size_t n = 0;
    for (size_t i = 0; r && i < g->cache_count; ++i) {
      const iris_cache *c = &g->caches[i];
      if (fabsf(c->p.x) < 1.98f && fabsf(c->p.z) < 1.98f && c->p.y > -1e-3f && c->p.y < 2.48f) r[n++] = c->radiance;
    }
    if (CHECK(n >= 100)) {
      qsort(r, n, sizeof *r, cmp_float);
      median = r[n / 2];
    }
    printf("%s: %zu caches inside, median radiance estimate %g\n", scene, n, (double)median);
    free(r);
  }
  iris_guiding_destroy(g);
  iris_scene_destroy(s);
  return median;
}

int main(void) {
  float open = inside_median("sky-room"), glazed = inside_median("sky-room-glazed");
  iris_check_record(open > 0.0f && glazed > 0.0f && glazed > 0.5f * open && glazed < 1.2f * open, __FILE__, __LINE__,
                    "radiance behind the slab %g against %g without it", (double)glazed, (double)open);
  return iris_check_summary("guiding.glazing");
}
