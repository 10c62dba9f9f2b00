/* core.rng: the sampler is a pure function of (seed, stream, sample, dimension),
 * uniform on [0, 1) (chi-square over bins), and dimensions/streams/samples are
 * not visibly correlated (2-D chi-square on pairs). All inputs are fixed, so
 * the test is deterministic; the thresholds are p = 1e-6 upper quantiles. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "check.h"
#include "core/rng.h"

/* Upper quantile of chi-square with k degrees of freedom (Wilson-Hilferty),
 * z = 4.753 is the standard normal quantile for p = 1e-6. */
static double chi2_critical(int k) {
  const double z = 4.753;
  double a = 2.0 / (9.0 * k);
  double c = 1.0 - a + z * sqrt(a);
  return k * c * c * c;
}

static double chi2_stat(const long *counts, int bins, long n) {
  double e = (double)n / bins, s = 0;
  for (int i = 0; i < bins; i++) s += (counts[i] - e) * (counts[i] - e) / e;
  return s;
}

static void test_pure(void) {
  iris_sampler a = iris_sampler_start(42, 1234, 7), b = iris_sampler_start(42, 1234, 7);
  for (uint32_t d = 0; d < 64; d++) {
    float va = iris_sampler_next(&a);
    CHECK(va == iris_sampler_get(&b, d)); /* next walks the same pure function */
    CHECK(va >= 0.0f && va < 1.0f);
  }
  /* Order of evaluation does not matter: dimension 10 first or last gives the same value. */
  iris_sampler c = iris_sampler_start(42, 1234, 7);
  float d10 = iris_sampler_get(&c, 10);
  for (int i = 0; i < 10; i++) (void)iris_sampler_next(&c);
  CHECK(iris_sampler_next(&c) == d10);
  /* Each input changes the stream. */
  float base = iris_sampler_get(&a, 3);
  iris_sampler s1 = iris_sampler_start(43, 1234, 7), s2 = iris_sampler_start(42, 1235, 7),
               s3 = iris_sampler_start(42, 1234, 8);
  CHECK(iris_sampler_get(&s1, 3) != base);
  CHECK(iris_sampler_get(&s2, 3) != base);
  CHECK(iris_sampler_get(&s3, 3) != base);
  /* Extreme hash values map inside [0, 1). */
  CHECK(iris_u64_to_unit(0) == 0.0f);
  CHECK(iris_u64_to_unit(UINT64_MAX) < 1.0f);
}

static void test_uniform_1d(void) {
  enum { BINS = 128 };
  const long n = 1280000;
  long counts[BINS] = {0};
  double sum = 0;
  for (long i = 0; i < n; i++) {
    /* Walk pixels, samples and dimensions the way a renderer does. */
    iris_sampler s = iris_sampler_start(1, (uint64_t)(i / 64), (uint64_t)(i % 16));
    float u = iris_sampler_get(&s, (uint32_t)(i % 64 / 16));
    counts[(int)(u * BINS)]++;
    sum += u;
  }
  double x2 = chi2_stat(counts, BINS, n);
  iris_check_record(x2 < chi2_critical(BINS - 1), __FILE__, __LINE__,
                    "1-D uniformity: chi2 %.1f >= critical %.1f", x2, chi2_critical(BINS - 1));
  CHECK_NEAR(sum / n, 0.5, 5 * sqrt(1.0 / 12.0 / n));
}

/* 2-D chi-square over 32x32 cells of (u, v) pairs from `pair`. */
static void check_pairs(const char *what, void (*pair)(long i, float *u, float *v)) {
  enum { B = 32 };
  const long n = 1024 * 400;
  long *counts = calloc(B * B, sizeof *counts);
  double cov = 0;
  for (long i = 0; i < n; i++) {
    float u, v;
    pair(i, &u, &v);
    counts[(int)(u * B) * B + (int)(v * B)]++;
    cov += (u - 0.5) * (v - 0.5);
  }
  double x2 = chi2_stat(counts, B * B, n);
  iris_check_record(x2 < chi2_critical(B * B - 1), __FILE__, __LINE__,
                    "%s: 2-D chi2 %.1f >= critical %.1f", what, x2, chi2_critical(B * B - 1));
  /* Correlation coefficient: var(u) = 1/12, its standard error is about 1/sqrt(n). */
  double corr = cov / n * 12.0;
  iris_check_record(fabs(corr) < 6.0 / sqrt((double)n), __FILE__, __LINE__,
                    "%s: correlation %.5f", what, corr);
  free(counts);
}

static void pair_dims(long i, float *u, float *v) {
  iris_sampler s = iris_sampler_start(9, (uint64_t)i, 0);
  *u = iris_sampler_next(&s);
  *v = iris_sampler_next(&s);
}
static void pair_far_dims(long i, float *u, float *v) {
  iris_sampler s = iris_sampler_start(9, 5, (uint64_t)i);
  *u = iris_sampler_get(&s, 2);
  *v = iris_sampler_get(&s, 1000);
}
static void pair_neighbour_pixels(long i, float *u, float *v) {
  iris_sampler a = iris_sampler_start(9, (uint64_t)i, 3), b = iris_sampler_start(9, (uint64_t)i + 1, 3);
  *u = iris_sampler_get(&a, 0);
  *v = iris_sampler_get(&b, 0);
}
static void pair_next_sample(long i, float *u, float *v) {
  iris_sampler a = iris_sampler_start(9, 77, (uint64_t)i), b = iris_sampler_start(9, 77, (uint64_t)i + 1);
  *u = iris_sampler_get(&a, 4);
  *v = iris_sampler_get(&b, 4);
}
static void pair_seeds(long i, float *u, float *v) {
  iris_sampler a = iris_sampler_start(0, (uint64_t)i, 0), b = iris_sampler_start(1, (uint64_t)i, 0);
  *u = iris_sampler_get(&a, 0);
  *v = iris_sampler_get(&b, 0);
}

int main(void) {
  test_pure();
  test_uniform_1d();
  check_pairs("dimensions 0 and 1", pair_dims);
  check_pairs("dimensions 2 and 1000", pair_far_dims);
  check_pairs("neighbouring pixels", pair_neighbour_pixels);
  check_pairs("consecutive samples", pair_next_sample);
  check_pairs("seeds 0 and 1", pair_seeds);
  return TEST_SUMMARY();
}
