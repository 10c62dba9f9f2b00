/* Light through glass reaches the caches as it is.
 *
 * 1. Photons through glass keep their power: sky-room-glazed is sky-room with a
 * closed 2 cm glass slab in the window, so the caches inside must estimate
 * about the radiance of sky-room's (the slab passes ~85% of the light), as
 * the adjoint Russian roulette reads it. A delta lobe's f carries 1/|cos wi|
 * (bsdf.c); a photon weighted by f without the cosine gained that factor at
 * every glass interface, up to 10^9 for photons guided inside the slab at
 * grazing angles (docs/guiding.md, "Sky behind glass"), and fails here.
 * 2. The caches behind the slab know which of their light came straight
 *    through it from the sky (photons.h, sky_through): most of the sun's
 *    patch on the floor (sun direction (0.66, 0.58, 0.48) through the window
 *    y in [1, 2], z in [-0.6, 0.6] of the wall x = 2) more than half, none in
 *    sky-room (no glass: light sampling reaches the sky) or sky-room-pane
 *    (one refracting quad: the light no longer arrives from the map's
 *    direction). Fails when the flag is not set or set for any delta path. */
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

/* Whether floor point p is well inside the sun's patch: the ray towards the
 * sun passes the window opening with 10 cm to spare. */
static bool in_sun_patch(iris_vec3 p) {
  const iris_vec3 sun = iris_normalize(iris_v3(0.66f, 0.58f, 0.48f));
  float t = (2.0f - p.x) / sun.x, y = p.y + t * sun.y, z = p.z + t * sun.z;
  return t > 0.0f && y > 1.1f && y < 1.9f && z > -0.5f && z < 0.5f;
}

/* Median radiance estimate of the caches inside the room (the room is
 * x, z in [-2, 2], y in [0, 2.5]); -1 when the guide failed. Counts the
 * floor caches in the sun's patch and those of them with sky_through > 0.5,
 * and the caches with any sky_through. */
static float inside_median(const char *scene, int *patch, int *patch_through, int *any_through) {
  *patch = *patch_through = *any_through = 0;
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
      *any_through += c->sky_through > 0.0f;
      if (c->frame.n.y > 0.99f && fabsf(c->p.y) < 1e-3f && in_sun_patch(c->p)) {
        ++*patch;
        *patch_through += c->sky_through > 0.5f;
      }
    }
    if (CHECK(n >= 100)) {
      qsort(r, n, sizeof *r, cmp_float);
      median = r[n / 2];
    }
    printf("%s: %zu caches inside, median radiance estimate %g; %d floor caches in the sun's patch, %d of them with "
           "more than half their light straight through glass; %d caches with any\n",
           scene, n, (double)median, *patch, *patch_through, *any_through);
    free(r);
  }
  iris_guiding_destroy(g);
  iris_scene_destroy(s);
  return median;
}

int main(void) {
  int patch, through, any;
  float open = inside_median("sky-room", &patch, &through, &any);
  iris_check_record(any == 0, __FILE__, __LINE__, "sky-room: %d caches see the sky through glass", any);
  float glazed = inside_median("sky-room-glazed", &patch, &through, &any);
  iris_check_record(open > 0.0f && glazed > 0.0f && glazed > 0.5f * open && glazed < 1.2f * open, __FILE__, __LINE__,
                    "radiance behind the slab %g against %g without it", (double)glazed, (double)open);
  iris_check_record(patch >= 5 && through >= (3 * patch + 3) / 4, __FILE__, __LINE__,
                    "sky-room-glazed: %d of %d caches in the sun's patch see it through the slab", through, patch);
  inside_median("sky-room-pane", &patch, &through, &any);
  iris_check_record(any == 0, __FILE__, __LINE__, "sky-room-pane: %d caches see the sky straight through glass", any);
  return iris_check_summary("guiding.glazing");
}
