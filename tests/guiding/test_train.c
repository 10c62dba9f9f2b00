/* Training passes (renderer/guiding/train.h):
 * - the selection-probability learner finds the known optimum of synthetic
 *   two-strategy integrands (zero-variance mixtures at 0.15 and 0.65, an
 *   integrand the cache strategy alone serves best, one BSDF sampling serves
 *   best), from samples drawn with another mixture;
 * - the schedule doubles and stops at the budget;
 * - the path recorder gives back the exact incident radiance of the furnace;
 * - a cache filled as training fills it samples incident radiance x cosine:
 *   its texel probabilities match the integrals of Li cos over the texels;
 * - a guide trained on a scene has learned selection probabilities, changed
 *   tables that still sum to one, and the training does not depend on the
 *   thread count (bit-identical tables and alphas for 1 and 2 threads). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/rng.h"
#include "renderer/guiding/cache.h"
#include "renderer/guiding/train.h"
#include "renderer/lights.h"
#include "renderer/texture.h"
#include "scenes/builtin.h"
#include "guide_fixture.h"

/* 1D domain [0,1]: p_b = 1, p_c = 2x; samples from (1 - a0) p_b + a0 p_c. */
static float learn(double (*h)(double), float a0, int n, uint64_t seed) {
  iris_alpha_learner l;
  memset(&l, 0, sizeof l);
  for (int i = 0; i < n; ++i) {
    double u = iris_u64_to_unit(iris_hash4(seed, (uint64_t)i, 0, 1)),
           v = iris_u64_to_unit(iris_hash4(seed, (uint64_t)i, 1, 1));
    double x = u < a0 ? sqrt(v) : v; /* inverse CDF of 2x is sqrt */
    double pb = 1.0, pc = 2.0 * x, q = (1.0 - a0) * pb + a0 * pc;
    iris_alpha_learner_add(&l, (float)h(x), (float)q, (float)pb, (float)pc);
  }
  return iris_alpha_learner_best(&l, -1.0f, 64);
}

/* The exact second moment's argmin over the grid (midpoint quadrature). */
static float exact_best(double (*h)(double)) {
  int best = 0;
  double bm = INFINITY;
  for (int j = 0; j < IRIS_ALPHA_GRID; ++j) {
    double a = iris_alpha_grid_value(j), m = 0.0;
    const int N = 200000;
    for (int i = 0; i < N; ++i) {
      double x = (i + 0.5) / N, hv = h(x);
      m += hv * hv / ((1.0 - a) + a * 2.0 * x) / N;
    }
    if (m < bm) bm = m, best = j;
  }
  return iris_alpha_grid_value(best);
}

static double h_mix15(double x) { return 3.0 * (0.85 + 0.15 * 2.0 * x); }
static double h_mix65(double x) { return 0.5 * (0.35 + 0.65 * 2.0 * x); }
static double h_peak(double x) { return x * x * x * 8.0; }           /* cache-like, sharper than p_c */
static double h_flat_low(double x) { return x < 0.5 ? 1.0 : 0.2; }  /* where p_c is small */

static void test_learner(void) {
  struct {
    double (*h)(double);
    const char *name;
  } cases[] = {{h_mix15, "mixture 0.15"}, {h_mix65, "mixture 0.65"}, {h_peak, "x^3"}, {h_flat_low, "step"}};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    float want = exact_best(cases[i].h);
    for (int a0i = 0; a0i < 2; ++a0i) {
      float a0 = a0i ? 0.7f : 0.3f;
      float got = learn(cases[i].h, a0, 40000, 7 + (uint64_t)i);
      iris_check_record(fabsf(got - want) < 1e-4f, __FILE__, __LINE__,
                        "learner on %s from a0 %.1f: %.2f, exact optimum %.2f", cases[i].name, (double)a0,
                        (double)got, (double)want);
    }
  }
  /* Zero-variance mixtures are known without quadrature. */
  CHECK(fabsf(exact_best(h_mix15) - 0.15f) < 1e-4f);
  CHECK(fabsf(exact_best(h_mix65) - 0.65f) < 1e-4f);
  /* Too few samples, or nothing but zeros: the fallback. */
  CHECK(learn(h_mix65, 0.5f, 10, 3) == -1.0f);
  iris_alpha_learner l;
  memset(&l, 0, sizeof l);
  for (int i = 0; i < 100; ++i) iris_alpha_learner_add(&l, 0.0f, 1.0f, 1.0f, 1.0f);
  CHECK(iris_alpha_learner_best(&l, 0.42f, 64) == 0.42f);
}

/* The product with the cosine: a cache filled as the training passes fill it
 * (Li cos / q for directions drawn with density q, nearest splat) converges to
 * texel probabilities proportional to the integral of Li cos over each texel,
 * computed independently by uniform sampling inside each texel (exact solid
 * angles). With Li constant that is the cosine alone, which differs from the
 * solid-angle shares by far more than the tolerance near the horizon. */
static double li_field(iris_vec3 d) {
  iris_vec3 lobe = iris_normalize(iris_v3(0.5f, -0.3f, 0.6f));
  return 0.3 + 6.0 * pow(fmax(0.0, (double)iris_dot(d, lobe)), 6.0);
}

static void check_cos_product(bool constant) {
  iris_octmap map;
  if (!CHECK(iris_octmap_create(&map, 8, false, NULL) == IRIS_OK)) return;
  const uint32_t n = map.texel_count;
  float *hist = calloc(n, sizeof(float));
  double *want = calloc(n, sizeof(double)), wsum = 0.0, osum = 0.0;
  const int N = 400000;
  for (int i = 0; i < N; ++i) { /* q: uniform hemisphere, 1 / (2 pi) */
    float u0 = iris_u64_to_unit(iris_hash4(9, (uint64_t)i, 0, 2)), u1 = iris_u64_to_unit(iris_hash4(9, (uint64_t)i, 1, 2));
    float z = u0, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * IRIS_PI * u1;
    iris_vec3 d = iris_v3(r * cosf(phi), r * sinf(phi), z);
    double li = constant ? 1.0 : li_field(d);
    iris_cache_splat(&map, hist, d, (float)(li * d.z * 2.0 * IRIS_PI), IRIS_SPLAT_NEAREST);
  }
  for (uint32_t t = 0; t < n; ++t) {
    double m = 0.0;
    const int M = 4000;
    for (int k = 0; k < M; ++k) {
      iris_vec3 d = iris_octmap_sample_in_texel(&map, t, iris_u64_to_unit(iris_hash4(t, (uint64_t)k, 0, 3)),
                                                iris_u64_to_unit(iris_hash4(t, (uint64_t)k, 1, 3)),
                                                iris_u64_to_unit(iris_hash4(t, (uint64_t)k, 2, 3)));
      m += (constant ? 1.0 : li_field(d)) * fmax(0.0, (double)d.z);
    }
    want[t] = m / M * map.solid_angle[t];
    wsum += want[t];
    osum += map.solid_angle[t];
  }
  float *pdf = calloc(n, sizeof(float));
  iris_cache_alias *alias = calloc(n, sizeof(iris_cache_alias));
  if (CHECK(iris_cache_build_tables(&map, hist, 0.0f, pdf, alias))) {
    double worst = 0.0, cos_vs_omega = 0.0;
    for (uint32_t t = 0; t < n; ++t) {
      double p = pdf[t] * 2.0 / 64.0, w = want[t] / wsum;
      /* binomial-like spread of a texel's share of N samples, weighted */
      double sd = sqrt(w / N) * (constant ? 2.0 : 6.0) + 0.01 * w; /* + the quadrature's error */
      worst = fmax(worst, fabs(p - w) / sd);
      cos_vs_omega = fmax(cos_vs_omega, fabs(w - map.solid_angle[t] / osum) / sd);
    }
    printf("cos product (%s Li): worst texel %.2f sd from the integral of Li cos; %.1f sd from solid angle\n",
           constant ? "constant" : "lobe", worst, cos_vs_omega);
    iris_check_record(worst < 5.0, __FILE__, __LINE__, "trained texel probabilities vs Li cos integrals: %.2f sd", worst);
    if (constant) CHECK(cos_vs_omega > 20.0); /* the test can tell the cosine from solid angle */
  }
  free(hist);
  free(want);
  free(pdf);
  free(alias);
  iris_octmap_destroy(&map);
}

/* The path recorder's bookkeeping: on the white furnace (a convex sphere of
 * albedo 1 under a sky of radiance 1) the radiance arriving at a surface point
 * from any direction above it is exactly 1. Per recorded vertex, (L_end - L +
 * miss) / beta must be 1 for mis (light sampling took its MIS share of the sky,
 * `miss` gives it back) and for bsdf (no light sampling, miss 0), and without
 * `miss` mis must fall short (what the guide learns by default). */
static void test_recorder(void) {
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  if (!CHECK(iris_builtin_create("furnace-diffuse", &s, &err) == IRIS_OK)) return;
  iris_pinhole cam;
  iris_accel *acc = NULL;
  iris_textures tx;
  iris_lights lights;
  memset(&tx, 0, sizeof tx);
  memset(&lights, 0, sizeof lights);
  if (CHECK(iris_pinhole_setup(s, NULL, 32, 32, &cam, &err) == IRIS_OK && iris_accel_build(s, &acc, &err) == IRIS_OK &&
            iris_textures_load(s, &tx, &err) == IRIS_OK && iris_lights_build(s, acc, &tx, &lights, &err) == IRIS_OK)) {
    for (int m = 0; m < 2; ++m) {
      iris_integrator it = iris_integrator_default(s, acc, &lights, &tx);
      it.method = m == 0 ? IRIS_METHOD_MIS : IRIS_METHOD_BSDF;
      double with_miss = 0.0, without = 0.0, worst = 0.0;
      size_t n = 0;
      iris_path_record rec;
      iris_path_stats st = {0};
      for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
          for (int k = 0; k < 4; ++k) {
            iris_sampler rng = iris_sampler_start_kind(IRIS_SAMPLER_INDEPENDENT, 3, (uint64_t)(y * 32 + x), (uint64_t)k);
            float ux, uy;
            iris_sampler_get2(&rng, IRIS_DIM_PIXEL, &ux, &uy);
            iris_vec3 L = iris_integrator_radiance_record(&it, iris_pinhole_ray(&cam, (float)x + ux, (float)y + uy), &rng, &st, &rec);
            for (int v = 0; v < rec.count; ++v) {
              const iris_path_vertex *pv = &rec.v[v];
              if (!(pv->beta.x > 0.0f)) continue; /* ended by Russian roulette: brings 0 */
              double a = (L.x - pv->L.x + pv->miss.x) / pv->beta.x, b = (L.x - pv->L.x) / pv->beta.x;
              with_miss += a;
              without += b;
              worst = fmax(worst, fabs(a - 1.0));
              n++;
            }
          }
      printf("recorder, %s: %zu vertices, mean Li %.5f (without miss %.5f), worst |Li - 1| %.2g\n",
             m == 0 ? "mis" : "bsdf", n, with_miss / (double)n, without / (double)n, worst);
      CHECK(n > 1000);
      iris_check_record(worst < 1e-3, __FILE__, __LINE__, "%s: recorded incident radiance off by %g", m == 0 ? "mis" : "bsdf", worst);
      if (m == 0) CHECK(without / (double)n < 0.95);
      else CHECK(fabs(without / (double)n - 1.0) < 1e-3);
    }
  }
  iris_lights_destroy(&lights);
  iris_textures_destroy(&tx);
  iris_accel_destroy(acc);
  iris_scene_destroy(s);
}

static void test_schedule(void) {
  CHECK_EQ_INT(iris_guiding_train_budget(64), 3);
  CHECK_EQ_INT(iris_guiding_train_budget(8), 0);
  CHECK_EQ_INT(iris_guiding_train_budget(20), 1);
  CHECK_EQ_INT(iris_guiding_train_budget(1024), 51);
  int done = 0, it = 0, sizes[8];
  while (done < 10) {
    sizes[it] = iris_guiding_train_iteration_spp(it, done, 10);
    done += sizes[it++];
  }
  CHECK_EQ_INT(it, 4); /* 1 + 2 + 4 + 3 */
  CHECK_EQ_INT(sizes[0], 1);
  CHECK_EQ_INT(sizes[2], 4);
  CHECK_EQ_INT(sizes[3], 3);
}

static iris_guiding *build(const iris_scene *s, int threads, int train_spp) {
  iris_guiding_params gp = iris_guiding_params_default();
  gp.photons = 60000;
  gp.train_spp = train_spp;
  return test_guide_build(s, IRIS_METHOD_GUIDED_NEE, gp, 5, threads, 256);
}

static void test_trained_guide(void) {
  iris_scene *s = NULL;
  iris_error err;
  if (!CHECK(iris_builtin_create("door-shielded", &s, &err) == IRIS_OK)) return;
  iris_guiding *photons_only = build(s, 2, 0), *t1 = build(s, 1, 15), *t2 = build(s, 2, 15);
  if (CHECK(photons_only && t1 && t2) && CHECK(!t1->stats.skipped) &&
      CHECK(t1->cache_count == photons_only->cache_count)) {
    CHECK_EQ_INT(t1->stats.train_spp, 15);
    CHECK_EQ_INT(t1->stats.train_iterations, 4);
    CHECK(t1->stats.train_samples > 10 * t1->cache_count);
    CHECK_EQ_INT(photons_only->stats.train_spp, 0);
    size_t learned = 0, changed = 0, lo = 0, hi = 0;
    for (size_t i = 0; i < t1->cache_count; ++i) {
      const iris_cache *c = &t1->caches[i];
      CHECK(photons_only->caches[i].alpha < 0.0f);
      if (c->alpha >= 0.0f) {
        learned++;
        lo += c->alpha < 0.5f;
        hi += c->alpha > 0.5f;
      }
      const iris_octmap *map = c->sphere ? &t1->sphere : &t1->hemi;
      double sum = 0.0;
      bool diff = false;
      for (uint32_t t = 0; t < map->texel_count; ++t) {
        /* P = pdf * 2 / res^2 */
        sum += (double)t1->pdf[c->table + t] * 2.0 / ((double)map->res * map->res);
        diff |= t1->pdf[c->table + t] != photons_only->pdf[c->table + t];
      }
      changed += diff;
      if (!iris_check_record(fabs(sum - 1.0) < 1e-4, __FILE__, __LINE__, "cache %zu: texel P sum %.6f", i, sum))
        break;
    }
    printf("door-shielded: %zu caches, %zu learned alpha (%zu < 0.5, %zu > 0.5), %zu tables changed, %llu samples\n",
           t1->cache_count, learned, lo, hi, changed, (unsigned long long)t1->stats.train_samples);
    CHECK(learned > t1->cache_count / 2);
    CHECK(changed > t1->cache_count / 2);
    CHECK(t1->photon_hist == NULL); /* freed after training */
    /* Same guide for 1 and 2 threads. */
    size_t floats = 0;
    for (size_t i = 0; i < t1->cache_count; ++i) {
      const iris_cache *c = &t1->caches[i];
      size_t end = c->table + (c->sphere ? t1->sphere.texel_count : t1->hemi.texel_count);
      floats = end > floats ? end : floats;
      CHECK(memcmp(&t1->caches[i], &t2->caches[i], sizeof *c) == 0);
    }
    CHECK(memcmp(t1->pdf, t2->pdf, floats * sizeof(float)) == 0);
    CHECK(memcmp(t1->alias, t2->alias, floats * sizeof(iris_cache_alias)) == 0);
  }
  iris_guiding_destroy(photons_only);
  iris_guiding_destroy(t1);
  iris_guiding_destroy(t2);
  iris_scene_destroy(s);
}

int main(void) {
  test_learner();
  test_schedule();
  test_recorder();
  check_cos_product(true);
  check_cos_product(false);
  test_trained_guide();
  return iris_check_summary("guiding.train");
}
