/* Shared by the tests that compare renders statistically (render.unbiased,
 * render.env_unbiased, render.light_tree, render.instancing, guiding.auto,
 * guiding.unbiased_*): the Bonferroni z threshold, the mean and variance of a
 * film's block, and the z-test of two films per image and per block.
 * Header-only: the tests link the renderer, tests/common's library does not. */
#ifndef IRIS_TESTS_FILM_STATS_H
#define IRIS_TESTS_FILM_STATS_H

#include <math.h>

#include "check.h"
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

/* Two renders of one scene compared (Mitsuba test_renders.py style): per
 * channel z = (mean_a - mean_b) / sqrt(var_a + var_b), the variances those of
 * the means, over the whole image (|z| <= z_image) and over each block of a
 * bx x by grid (|z| <= z_block; bx = 0: the image only). Every test is one
 * check whose message starts with `what`. Returns the largest |z|. */
static inline double iris_test_z_compare(const iris_film *a, const iris_film *b, int bx, int by, double z_image,
                                         double z_block, const char *what) {
  const int w = a->width, h = a->height;
  double worst = 0.0;
  for (int blk = -1; blk < bx * by; blk++) {
    int x0 = 0, y0 = 0, x1 = w, y1 = h;
    if (blk >= 0) {
      x0 = (blk % bx) * w / bx, y0 = (blk / bx) * h / by;
      x1 = x0 + w / bx, y1 = y0 + h / by;
    }
    double ma[3], va[3], mb[3], vb[3];
    region(a, x0, y0, x1, y1, ma, va);
    region(b, x0, y0, x1, y1, mb, vb);
    for (int k = 0; k < 3; k++) {
      double sd = sqrt(va[k] + vb[k]);
      double z = sd > 0 ? (ma[k] - mb[k]) / sd : (ma[k] == mb[k] ? 0.0 : INFINITY);
      if (fabs(z) > worst) worst = fabs(z);
      iris_check_record(fabs(z) <= (blk < 0 ? z_image : z_block), __FILE__, __LINE__,
                        "%s, %s (%d,%d)-(%d,%d) channel %d: %.5f vs %.5f, z = %.2f", what,
                        blk < 0 ? "image" : "block", x0, y0, x1, y1, k, ma[k], mb[k], z);
    }
  }
  return worst;
}

#endif
