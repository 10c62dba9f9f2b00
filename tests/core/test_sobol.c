/* core.sobol: the low-discrepancy sampler (core/rng.h, core/sobol.c).
 *  - Joe-Kuo direction numbers: the first points of the 3-D Sobol sequence
 *    (Gray-code order, as published) and the (0, m, 1)-net property of every
 *    tabulated dimension.
 *  - The sobol sampler: in one stream's first 2^m samples (and in any aligned
 *    block of 2^m samples, as a pass or a partition starts at), every pair of
 *    dimensions (2k, 2k+1) is a (0, m, 2)-net: each elementary interval of
 *    area 2^-m holds exactly one point; values lie in [0, 1).
 *  - Decorrelation: the same dimension in neighbouring streams (pixels), and
 *    different pairs of one stream, are jointly uniform (2-D chi-square,
 *    p = 1e-6 threshold) - a sampler that reused the scramble would fail.
 *  - get2 equals two gets; the independent kind is unchanged in spirit. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/rng.h"

static double chi2_critical(int k) { /* Wilson-Hilferty, p = 1e-6 */
  const double z = 4.753;
  double a = 2.0 / (9.0 * k);
  double c = 1.0 - a + z * sqrt(a);
  return k * c * c * c;
}

static void test_direction_numbers(void) {
  /* Sobol (Joe-Kuo) points 0..7 in Gray-code order, dimensions 0..2. */
  static const double expect[8][3] = {{0, 0, 0},         {0.5, 0.5, 0.5},       {0.75, 0.25, 0.25},
                                      {0.25, 0.75, 0.75}, {0.375, 0.375, 0.625}, {0.875, 0.875, 0.125},
                                      {0.625, 0.125, 0.875}, {0.125, 0.625, 0.375}};
  for (uint32_t i = 0; i < 8; i++) {
    uint32_t gray = i ^ (i >> 1);
    for (uint32_t d = 0; d < 3; d++) {
      double v = iris_sobol_u32(gray, d) * 0x1p-32;
      iris_check_record(v == expect[i][d], __FILE__, __LINE__, "sobol point %u dim %u: %g, expected %g", i,
                        d, v, expect[i][d]);
    }
  }
  /* Every dimension: the first 2^m values hit every interval [k 2^-m, (k+1) 2^-m) once. */
  for (uint32_t d = 0; d < IRIS_SOBOL_DIMS; d++)
    for (int m = 1; m <= 12; m++) {
      uint32_t n = 1u << m;
      unsigned char *seen = calloc(n, 1);
      int bad = 0;
      for (uint32_t i = 0; i < n; i++) {
        uint32_t cell = iris_sobol_u32(i, d) >> (32 - m);
        if (seen[cell]++) bad++;
      }
      iris_check_record(bad == 0, __FILE__, __LINE__, "sobol dim %u is not a (0,%d,1)-net (%d repeats)", d, m, bad);
      free(seen);
    }
}

/* Is the set {(x_i, y_i)} of n = 2^m points a (0, m, 2)-net? */
static bool is_net(const float *x, const float *y, int m, char *why, size_t why_size) {
  uint32_t n = 1u << m;
  unsigned char *seen = malloc(n);
  for (int a = 0; a <= m; a++) { /* intervals of 2^-a by 2^-(m-a) */
    memset(seen, 0, n);
    for (uint32_t i = 0; i < n; i++) {
      if (!(x[i] >= 0.0f && x[i] < 1.0f && y[i] >= 0.0f && y[i] < 1.0f)) {
        snprintf(why, why_size, "value outside [0,1): %g %g", x[i], y[i]);
        free(seen);
        return false;
      }
      uint32_t cx = (uint32_t)(x[i] * (float)(1u << a)), cy = (uint32_t)(y[i] * (float)(1u << (m - a)));
      uint32_t cell = (cx << (m - a)) | cy;
      if (seen[cell]++) {
        snprintf(why, why_size, "two points in interval %u of shape 2^-%d x 2^-%d", cell, a, m - a);
        free(seen);
        return false;
      }
    }
  }
  free(seen);
  return true;
}

static void test_nets(void) {
  enum { MMAX = 10 };
  static float x[1u << MMAX], y[1u << MMAX];
  char why[128];
  const uint64_t streams[3] = {0, 12345, 262143};
  const uint64_t offsets[3] = {0, 1u << MMAX, 7u << MMAX}; /* aligned blocks: later passes */
  for (int si = 0; si < 3; si++)
    for (int oi = 0; oi < 3; oi++)
      for (uint32_t pair = 0; pair < 40; pair += 3) {
        for (int m = 1; m <= MMAX; m++) {
          uint32_t n = 1u << m;
          for (uint32_t i = 0; i < n; i++) {
            iris_sampler s = iris_sampler_start_kind(IRIS_SAMPLER_SOBOL, 7, streams[si], offsets[oi] + i);
            x[i] = iris_sampler_get(&s, 2 * pair);
            y[i] = iris_sampler_get(&s, 2 * pair + 1);
            float a, b;
            iris_sampler_get2(&s, 2 * pair, &a, &b);
            if (a != x[i] || b != y[i]) {
              iris_check_record(false, __FILE__, __LINE__, "get2 differs from get");
              return;
            }
          }
          bool ok = is_net(x, y, m, why, sizeof why);
          iris_check_record(ok, __FILE__, __LINE__, "stream %llu, samples %llu.., pair %u, m %d: %s",
                            (unsigned long long)streams[si], (unsigned long long)offsets[oi], pair, m,
                            ok ? "" : why);
          if (!ok) return;
        }
      }
  /* The independent sampler is not a net (the test can tell them apart). */
  for (uint32_t i = 0; i < 256; i++) {
    iris_sampler s = iris_sampler_start_kind(IRIS_SAMPLER_INDEPENDENT, 7, 0, i);
    x[i] = iris_sampler_get(&s, 0);
    y[i] = iris_sampler_get(&s, 1);
  }
  CHECK(!is_net(x, y, 8, why, sizeof why));
}

/* 2-D chi-square of n points (a_i, b_i) on a 16 x 16 grid. */
static double chi2_grid(const float *a, const float *b, int n) {
  long counts[256] = {0};
  for (int i = 0; i < n; i++) counts[(int)(a[i] * 16) * 16 + (int)(b[i] * 16)]++;
  double e = n / 256.0, s = 0;
  for (int i = 0; i < 256; i++) s += (counts[i] - e) * (counts[i] - e) / e;
  return s;
}

static void test_decorrelation(void) {
  enum { N = 65536 };
  static float a[N], b[N];
  const double crit = chi2_critical(255);
  /* neighbouring pixels, same sample and dimension */
  for (uint32_t dim = 0; dim < 6; dim++) {
    for (int i = 0; i < N; i++) {
      iris_sampler p = iris_sampler_start_kind(IRIS_SAMPLER_SOBOL, 3, (uint64_t)i, 5);
      iris_sampler q = iris_sampler_start_kind(IRIS_SAMPLER_SOBOL, 3, (uint64_t)i + 1, 5);
      a[i] = iris_sampler_get(&p, dim);
      b[i] = iris_sampler_get(&q, dim);
    }
    double c = chi2_grid(a, b, N);
    iris_check_record(c < crit, __FILE__, __LINE__, "pixels i, i+1 correlated in dim %u: chi2 %.1f > %.1f", dim, c, crit);
  }
  /* different pairs of one stream, over its samples (and over streams) */
  const uint32_t pairs[4][2] = {{0, 2}, {1, 3}, {2, 12}, {4, 15}};
  for (int k = 0; k < 4; k++) {
    for (int i = 0; i < N; i++) {
      iris_sampler p = iris_sampler_start_kind(IRIS_SAMPLER_SOBOL, 3, 99, (uint64_t)i);
      a[i] = iris_sampler_get(&p, pairs[k][0]);
      b[i] = iris_sampler_get(&p, pairs[k][1]);
    }
    double c = chi2_grid(a, b, N);
    iris_check_record(c < crit, __FILE__, __LINE__, "dims %u and %u correlated: chi2 %.1f > %.1f", pairs[k][0],
                      pairs[k][1], c, crit);
  }
  /* seeds change everything */
  iris_sampler s0 = iris_sampler_start_kind(IRIS_SAMPLER_SOBOL, 1, 10, 3);
  iris_sampler s1 = iris_sampler_start_kind(IRIS_SAMPLER_SOBOL, 2, 10, 3);
  int same = 0;
  for (uint32_t d = 0; d < 64; d++) same += iris_sampler_get(&s0, d) == iris_sampler_get(&s1, d);
  CHECK(same < 4);
}

int main(void) {
  test_direction_numbers();
  test_nets();
  test_decorrelation();
  return iris_check_summary("core.sobol");
}
