/* guiding.light_skip: light sampling where no light arrives (docs/guiding.md,
 * "Light sampling where no light arrives").
 *  - learned on lamp-shade (a bulb inside a glass shade open below, shadow
 *    rays cannot cross the glass): a cache whose own position sees the bulb
 *    by at least half of 64 light samples keeps light sampling (probability
 *    1), and most caches that see it by none of them sample lights with
 *    probability light_min, and no other value occurs; the values are the
 *    same for 1 and 2 threads and absent with light_min 1 or without
 *    training; on door-shielded (the lamp faces away: its light samples cost
 *    no shadow ray) none;
 *  - unbiased: on the Cornell box, where light sampling carries most of the
 *    image, on veach-mis, where BSDF samples of the glossy plates hit the
 *    large lights, and in the white furnace (a constant sky), a guided-nee estimate with every cache's probability forced to
 *    0.1 agrees with the same guide at 1, per image and per 12 x 12 block
 *    (z-tests on the samples' variance, 4 sigma). Fails when the light
 *    sample is not divided by the probability or when an emitter hit's MIS
 *    weight leaves the probability out. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/rng.h"
#include "guide_fixture.h"
#include "renderer/accel.h"
#include "scenes/builtin.h"

/* Share of 64 light samples from p (normal n) that reach a light unblocked. */
static double seen_share(const test_guide_scene *t, iris_vec3 p, iris_vec3 n) {
  int seen = 0;
  for (int i = 0; i < 64; ++i) {
    float u = (float)iris_u64_to_unit(iris_hash4(7, (uint64_t)i, 0, 0)),
          u0 = (float)iris_u64_to_unit(iris_hash4(7, (uint64_t)i, 1, 0)),
          u1 = (float)iris_u64_to_unit(iris_hash4(7, (uint64_t)i, 2, 0));
    iris_light_choice c;
    iris_light_sample ls;
    iris_lights_choose(&t->lights, p, n, u, &c);
    if (!iris_lights_sample_choice(&t->lights, p, &c, u0, u1, &ls) || !(iris_max3(ls.L) > 0.0f)) continue;
    if (iris_dot(ls.wi, n) <= 0.0f) continue;
    iris_ray r = iris_spawn_ray_to(p, n, ls.p, ls.n);
    seen += !iris_accel_occluded(t->acc, &r);
  }
  return seen / 64.0;
}

typedef struct learned {
  int caches, optional, other_value, seeing, seeing_optional, dark, dark_optional;
  float *light; /* per cache */
} learned;

static learned learn(const char *scene, float light_min, int train_spp, int threads) {
  learned l;
  memset(&l, 0, sizeof l);
  iris_scene *sc = NULL;
  test_guide_scene t;
  if (!test_guide_builtin_open(scene, IRIS_METHOD_GUIDED_NEE, &sc, &t)) return l;
  iris_guiding_params gp = iris_guiding_params_default();
  gp.force = true;
  gp.train_spp = train_spp;
  gp.light_min = light_min;
  iris_guiding *g = test_guide_build_in(sc, &t, gp, 3, threads, 128);
  if (CHECK(g && !g->stats.skipped)) {
    l.caches = (int)g->cache_count;
    l.light = malloc(sizeof(float) * (g->cache_count ? g->cache_count : 1));
    for (size_t i = 0; i < g->cache_count; ++i) {
      const iris_cache *c = &g->caches[i];
      bool optional = c->light < 1.0f;
      if (l.light) l.light[i] = c->light;
      l.optional += optional;
      l.other_value += c->light != 1.0f && c->light != light_min;
      if (c->sphere) continue; /* the shade's glass: both sides */
      iris_vec3 p = iris_madd(c->p, c->frame.n, 1e-4f);
      double s = seen_share(&t, p, c->frame.n);
      if (s >= 0.5) l.seeing++, l.seeing_optional += optional;
      if (s == 0.0) l.dark++, l.dark_optional += optional;
    }
    printf("%s (light_min %g, train %d spp, %d threads): %d caches, %d sample lights optionally; "
           "of %d seeing a light: %d; of %d seeing none: %d\n",
           scene, (double)light_min, train_spp, threads, l.caches, l.optional, l.seeing, l.seeing_optional, l.dark,
           l.dark_optional);
  }
  iris_guiding_destroy(g);
  test_guide_scene_close(&t);
  iris_scene_destroy(sc);
  return l;
}

static void test_learned(void) {
  learned a = learn("lamp-shade", 0.1f, 5, 1), b = learn("lamp-shade", 0.1f, 5, 2);
  CHECK(a.caches > 100 && a.seeing > 20 && a.dark > 100);
  iris_check_record(a.seeing_optional == 0, __FILE__, __LINE__,
                    "lamp-shade: %d of %d caches that see the bulb sample lights optionally", a.seeing_optional,
                    a.seeing);
  iris_check_record(a.dark_optional >= 0.8 * a.dark, __FILE__, __LINE__,
                    "lamp-shade: only %d of %d caches that see no light sample lights optionally", a.dark_optional,
                    a.dark);
  CHECK(a.other_value == 0);
  CHECK(a.caches == b.caches && a.light && b.light &&
        memcmp(a.light, b.light, sizeof(float) * (size_t)a.caches) == 0);
  learned off = learn("lamp-shade", 1.0f, 5, 2), untrained = learn("lamp-shade", 0.1f, 0, 2),
          shielded = learn("door-shielded", 0.1f, 5, 2);
  CHECK(off.caches > 0 && off.optional == 0);
  CHECK(untrained.caches > 0 && untrained.optional == 0);
  CHECK(shielded.caches > 0 && shielded.optional == 0);
  free(a.light), free(b.light), free(off.light), free(untrained.light), free(shielded.light);
}

/* Per pixel: the sum and the sum of squares of the mean of RGB over spp
 * guided-nee paths of the open scene with guide g (independent sampler). */
static void estimate(const test_guide_scene *t, iris_guiding *g, int spp, uint64_t seed, double *sum, double *sq) {
  iris_integrator it = t->it;
  it.sampler = IRIS_SAMPLER_INDEPENDENT;
  it.guide = iris_guiding_sampler(g);
  iris_path_stats stats = {0};
  const int w = t->cam.width, h = t->cam.height;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0, q = 0.0;
      uint64_t pixel = (uint64_t)y * (uint64_t)w + (uint64_t)x;
      for (int k = 0; k < spp; ++k) {
        iris_sampler rng = iris_sampler_start_kind(IRIS_SAMPLER_INDEPENDENT, seed, pixel, (uint64_t)k);
        float ux, uy;
        iris_sampler_get2(&rng, IRIS_DIM_PIXEL, &ux, &uy);
        iris_vec3 L = iris_integrator_radiance(&it, iris_pinhole_ray(&t->cam, (float)x + ux, (float)y + uy), &rng,
                                               &stats);
        double v = iris_avg3(L);
        s += v, q += v * v;
      }
      sum[pixel] = s, sq[pixel] = q;
    }
}

/* z of the difference of two means from sums over n samples each. */
static double z_of(double s1, double q1, double s2, double q2, double n) {
  double m1 = s1 / n, m2 = s2 / n, v1 = (q1 / n - m1 * m1) / (n - 1.0), v2 = (q2 / n - m2 * m2) / (n - 1.0);
  double se = sqrt(fmax(v1 + v2, 1e-30));
  return (m1 - m2) / se;
}

static void test_unbiased(const char *scene, int spp) {
  iris_scene *sc = NULL;
  test_guide_scene t;
  if (!test_guide_builtin_open(scene, IRIS_METHOD_GUIDED_NEE, &sc, &t)) return;
  iris_guiding_params gp = iris_guiding_params_default();
  gp.force = true;
  iris_guiding *g = test_guide_build_in(sc, &t, gp, 3, 2, 64);
  const int w = t.cam.width, h = t.cam.height;
  const size_t n = (size_t)w * (size_t)h;
  double *s1 = calloc(n, sizeof(double)), *q1 = calloc(n, sizeof(double)), *s2 = calloc(n, sizeof(double)),
         *q2 = calloc(n, sizeof(double));
  if (CHECK(g && !g->stats.skipped && g->cache_count > 0 && s1 && q1 && s2 && q2)) {
    for (size_t i = 0; i < g->cache_count; ++i) g->caches[i].light = 1.0f;
    estimate(&t, g, spp, 11, s1, q1);
    for (size_t i = 0; i < g->cache_count; ++i) g->caches[i].light = 0.1f;
    estimate(&t, g, spp, 12, s2, q2);
    /* blocks of 12 x 12 pixels and the whole image: the sums over pixels of
     * per-pixel sums are sums over all their samples */
    const int B = 12;
    double worst = 0.0, all[4] = {0, 0, 0, 0};
    int blocks = 0;
    for (int by = 0; by < h; by += B)
      for (int bx = 0; bx < w; bx += B) {
        double a[4] = {0, 0, 0, 0}, cnt = 0.0;
        for (int y = by; y < by + B && y < h; ++y)
          for (int x = bx; x < bx + B && x < w; ++x) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            a[0] += s1[i], a[1] += q1[i], a[2] += s2[i], a[3] += q2[i];
            cnt += spp;
          }
        for (int k = 0; k < 4; ++k) all[k] += a[k];
        double z = z_of(a[0], a[1], a[2], a[3], cnt);
        if (fabs(z) > fabs(worst)) worst = z;
        blocks++;
        iris_check_record(fabs(z) < 4.0, __FILE__, __LINE__,
                          "%s block (%d, %d): light probability 0.1 against 1: z = %.2f (means %.5f, %.5f)",
                          scene, bx, by, z, a[2] / cnt, a[0] / cnt);
      }
    double z = z_of(all[0], all[1], all[2], all[3], (double)n * spp);
    printf("%s guided-nee, light probability 0.1 against 1: image means %.5f and %.5f (z %.2f), worst of "
           "%d blocks z %.2f\n",
           scene, all[2] / ((double)n * spp), all[0] / ((double)n * spp), z, blocks, worst);
    iris_check_record(fabs(z) < 4.0, __FILE__, __LINE__, "%s image: light probability 0.1 against 1: z = %.2f",
                      scene, z);
  }
  free(s1), free(q1), free(s2), free(q2);
  iris_guiding_destroy(g);
  test_guide_scene_close(&t);
  iris_scene_destroy(sc);
}

int main(void) {
  test_learned();
  test_unbiased("cornell-box", 64);
  test_unbiased("veach-mis", 512);      /* glossy plates: BSDF samples hit the large lights (MIS weights) */
  test_unbiased("furnace-diffuse", 32); /* a constant sky: rays that escape (the map's MIS weight) */
  return iris_check_summary("guiding.light_skip");
}
