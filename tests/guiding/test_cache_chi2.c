/* Chi-square of cache sampling (Algorithm 2, uniform in solid angle inside the
 * texel) against the cache pdf, with the shared harness: hemisphere and
 * sphere maps, several fill patterns, nearest and bilinear splatting, and a
 * map filled as the training passes fill it (Li cos / q: radiance x cosine). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "check.h"
#include "chi2.h"
#include "core/rng.h"
#include "renderer/guiding/cache.h"

typedef struct cache_ctx {
  iris_octmap map;
  float *pdf;
  iris_cache_alias *alias;
} cache_ctx;

static bool sample_fn(void *ctx, const double u[3], double dir[3]) {
  cache_ctx *c = ctx;
  float p;
  iris_vec3 d = iris_cache_sample(&c->map, c->pdf, c->alias, (float)u[0], (float)u[1], (float)u[2], &p);
  dir[0] = d.x;
  dir[1] = d.y;
  dir[2] = d.z;
  return p > 0.0f;
}

static double pdf_fn(void *ctx, const double dir[3]) {
  cache_ctx *c = ctx;
  return iris_cache_pdf(&c->map, c->pdf, iris_v3((float)dir[0], (float)dir[1], (float)dir[2]));
}

static iris_vec3 uniform_sphere(float u0, float u1) {
  float z = 1.0f - 2.0f * u0, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * IRIS_PI * u1;
  return iris_v3(r * cosf(phi), r * sinf(phi), z);
}

#define N_TESTS 8

static void run(int res, bool sphere, int pattern, iris_splat_mode mode) {
  cache_ctx c;
  iris_octmap_create(&c.map, res, sphere, NULL);
  float *hist = calloc(c.map.texel_count, sizeof(float));
  c.pdf = calloc(c.map.texel_count, sizeof(float));
  c.alias = calloc(c.map.texel_count, sizeof(iris_cache_alias));
  iris_vec3 lobe = iris_normalize(iris_v3(-0.4f, 0.7f, 0.3f));
  for (int i = 0; i < 3000; ++i) {
    iris_sampler s = iris_sampler_start(42 + pattern, (uint64_t)i, 0);
    iris_vec3 d = uniform_sphere(iris_sampler_next(&s), iris_sampler_next(&s));
    float e = 1.0f;
    if (pattern == 0) e = powf(fmaxf(0.0f, iris_dot(d, lobe)), 30.0f); /* narrow lobe */
    if (pattern == 1) e = 0.2f + fabsf(d.z);                          /* smooth */
    if (pattern == 2) e = (d.x > 0.0f) ? 1.0f : 0.0f;                   /* half dark: floor only */
    if (pattern == 3) /* as training splats: Li cos / q, Li a lobe on a constant (q uniform) */
      e = (1.0f + 8.0f * powf(fmaxf(0.0f, iris_dot(d, lobe)), 4.0f)) * fabsf(d.z) * 4.0f * IRIS_PI;
    iris_cache_splat(&c.map, hist, d, e, mode);
  }
  CHECK(iris_cache_build_tables(&c.map, hist, 2e-4f, c.pdf, c.alias));
  chi2_domain dom = {sphere ? CHI2_SPHERE : CHI2_HEMISPHERE, 0, 0, 1234 + (uint64_t)pattern};
  clock_t t0 = clock();
  chi2_result r = chi2_run(&dom, sample_fn, pdf_fn, &c, 200000, 0.01, N_TESTS);
  iris_check_record(r.passed, __FILE__, __LINE__, "res %d sphere %d pattern %d splat %d: %s", res, sphere,
                    pattern, mode, r.message);
  CHECK_NEAR(r.pdf_integral, 1.0, 2e-3);
  printf("res %d sphere %d pattern %d splat %d: %.1f s\n", res, sphere, pattern, mode, (double)(clock() - t0) / CLOCKS_PER_SEC);
  free(hist);
  free(c.pdf);
  free(c.alias);
  iris_octmap_destroy(&c.map);
}

int main(void) {
  /* Every map kind, fill pattern and splat mode appears at least once; the
   * default layout (res 8, bilinear) on both map kinds. */
  run(8, false, 0, IRIS_SPLAT_NEAREST);
  run(8, true, 2, IRIS_SPLAT_NEAREST);
  run(8, false, 1, IRIS_SPLAT_BILINEAR);
  run(8, true, 0, IRIS_SPLAT_BILINEAR);
  run(16, false, 2, IRIS_SPLAT_BILINEAR);
  run(5, false, 0, IRIS_SPLAT_BILINEAR); /* odd resolution: texel split by both diagonals */
  run(3, true, 1, IRIS_SPLAT_NEAREST);
  run(8, false, 3, IRIS_SPLAT_BILINEAR); /* a trained cache: incident radiance x cosine */
  return TEST_SUMMARY();
}
