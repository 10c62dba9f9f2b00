/* The sky's light through a window shared by MIS between the camera and the
 * connections to light vertices (renderer/vcache.h, iris_vcache_sky_weight):
 * on sky-room (one window) and sky-room-corner (two, each with its own
 * probability) guided-nee with the connections must agree with guided-nee
 * without them, per image and per block of a 6 x 4 grid (z-tests on the
 * variance of each pixel's mean, Bonferroni-corrected for a family-wise level
 * of 0.1%). The weights of the two sides must sum to one for every path: with
 * the connection's ratio rho taken twice what the camera takes (weights that
 * sum to up to 1.33) the image is 2% too bright on sky-room, up to 5% in a
 * block, which these renders show at |z| 6.3 and 10.3 (2.8 and 1.9 with the
 * weights right; seeds as here). Where the camera shares the map's light it
 * samples the map only with a probability from its share (at least
 * IRIS_VCACHE_SKY_MAP_MIN), which the densities of its light samples and of
 * its escapes must count: forced to 0.02 here (connect_sky_map_q), leaving it
 * out of either fails at |z| 9-16. With a lamp besides the sky (sky-room
 * with a ceiling lamp) the map's probability is the map's alone: a lamp's
 * light sample taken with it too (weighted back, but its density against the
 * camera's hits of the lamp without it) fails at |z| 24 and 80. That the
 * map's probability is known for an escape after a lamp was chosen (769ec48)
 * is not resolved here: without it these renders still agree (|z| 2.2, the
 * escapes through the window carrying a small share at these vertices).
 * The connections must also have run (their light paths' rays counted). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "film_stats.h"
#include "render_run.h"
#include "renderer/guiding/guiding.h"
#include "renderer/render.h"
#include "scenes/builtin.h"

static bool render(const iris_scene *s, bool connect, float map_q, int spp, uint64_t seed,
                   iris_render_result *r) {
  iris_render_params p = iris_test_params(54, 36, spp, IRIS_METHOD_GUIDED_NEE, seed);
  p.connect_sky_map_q = map_q;
  iris_guiding_params gp = iris_guiding_params_default();
  gp.force = true;
  p.connect = connect ? IRIS_CONNECT_ON : IRIS_CONNECT_OFF;
  iris_test_attach_guide(&p, &gp);
  return iris_test_render(s, &p, r);
}

/* sky-room with a 0.4 x 0.4 m lamp of radiance 30 under the ceiling, facing
 * down: a light besides the map that a vertex sharing the sky may choose. */
static bool add_lamp(iris_scene *s) {
  static const float white[3] = {1.0f, 1.0f, 1.0f};
  const int32_t m = iris_builtin_add_diffuse(s, "lamp", 0.8f, 0.8f, 0.8f, 30.0f, white);
  return m >= 0 && iris_builtin_add_quad(s, iris_v3(0.0f, 2.49f, 0.0f), iris_v3(0.2f, 0.0f, 0.0f),
                                         iris_v3(0.0f, 0.0f, 0.2f), 1, m, "lamp") >= 0;
}

int main(void) {
  static const char *scenes[] = {"sky-room", "sky-room-corner", "sky-room"};
  /* the connections with the camera's map sampling by its share (the
   * default), and with it forced rare where the camera shares the map's
   * light, so that its density's accounting weighs (a camera light sample
   * with map_q left out of its density: 1% too dark at the default, which
   * these renders do not resolve) */
  static const float map_q[] = {0.0f, 0.02f};
  enum { NQ = sizeof map_q / sizeof *map_q };
  const int bx = 6, by = 4, spp = 320;
  enum { NS = sizeof scenes / sizeof *scenes };
  const int n_tests = NS * NQ * 3 * (1 + bx * by);
  const double z_max = fmax(3.0, z_for_alpha(1e-3 / n_tests));
  for (size_t i = 0; i < NS; i++) {
    iris_scene *s = NULL;
    iris_error err;
    if (!CHECK(iris_builtin_create(scenes[i], &s, &err) == IRIS_OK)) continue;
    const bool lamp = i == 2;
    if (lamp && !CHECK(add_lamp(s))) {
      iris_scene_destroy(s);
      continue;
    }
    iris_render_result off;
    if (CHECK(render(s, false, 0.0f, spp, 31, &off))) {
      CHECK(off.connect_rays == 0);
      for (int q = 0; q < NQ; q++) {
        iris_render_result on;
        if (!CHECK(render(s, true, map_q[q], spp, 32 + (uint64_t)q, &on))) continue;
        CHECK(on.connect_rays > 0);
        char what[120];
        snprintf(what, sizeof what, "%s%s without vs with connections (map q %g)", scenes[i],
                 lamp ? " with a lamp" : "", (double)map_q[q]);
        const double worst = iris_test_z_compare(&off.film, &on.film, bx, by, z_max, z_max, what);
        printf("%s: worst |z| = %.2f (limit %.2f), light paths' rays %llu\n", what, worst, z_max,
               (unsigned long long)on.connect_rays);
        CHECK_EQ_INT(on.stats.nan_count, 0);
        iris_render_result_destroy(&on);
      }
      iris_render_result_destroy(&off);
    }
    iris_scene_destroy(s);
  }
  return iris_check_summary("guiding.sky_share");
}
