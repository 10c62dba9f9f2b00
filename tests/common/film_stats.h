/* Shared by the tests that compare renders statistically (render.unbiased,
 * render.env_unbiased, guiding.unbiased_*): the Bonferroni z threshold and
 * the mean and variance of a film's block. Header-only: the tests link the
 * renderer, tests/common's library does not. */
#ifndef IRIS_TESTS_FILM_STATS_H
#define IRIS_TESTS_FILM_STATS_H

#include <math.h>

#include "renderer/film.h"

/* Two-sided normal quantile by bisection on erfc. */
static inline double z_for_alpha(double alpha) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; i++) {
    double mid = 0.5 * (lo + hi);
    if (erfc(mid / sqrt(2.0)) > alpha)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

/* Mean of the film's pixel means over [x0, x1) x [y0, y1) and its variance. */
static inline void region(const iris_film *f, int x0, int y0, int x1, int y1, double mean[3], double var[3]) {
  int n = 0;
  for (int k = 0; k < 3; k++) mean[k] = var[k] = 0.0;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++) {
      iris_vec3 m, v;
      iris_film_pixel(f, x, y, &m, &v);
      mean[0] += m.x, mean[1] += m.y, mean[2] += m.z;
      var[0] += v.x, var[1] += v.y, var[2] += v.z;
      n++;
    }
  for (int k = 0; k < 3; k++) {
    mean[k] /= n;
    var[k] /= (double)n * n;
  }
}

#endif
