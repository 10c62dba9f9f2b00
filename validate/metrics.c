/* Image metrics (validate/metrics.h); formulas in docs/validation.md. */
#include "validate/metrics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static inline float px(const iris_image *img, size_t i, int c) {
  return img->data[i * (size_t)img->channel_count + (size_t)c];
}

static inline double finite_or_zero(float v) { return isfinite(v) ? (double)v : 0.0; }

void iris_metric_count_nonfinite(const iris_image *img, int c0, int channels, uint64_t *nan_count,
                                 uint64_t *inf_count) {
  uint64_t nans = 0, infs = 0;
  size_t n = (size_t)img->width * (size_t)img->height;
  for (size_t i = 0; i < n; i++)
    for (int c = c0; c < c0 + channels; c++) {
      float v = px(img, i, c);
      if (isnan(v))
        nans++;
      else if (isinf(v))
        infs++;
    }
  if (nan_count) *nan_count = nans;
  if (inf_count) *inf_count = infs;
}

void iris_metric_channel_means(const iris_image *img, int c0, double mean[3]) {
  size_t n = (size_t)img->width * (size_t)img->height;
  for (int c = 0; c < 3; c++) {
    /* Pairwise-free but accurate enough: double accumulation of floats. */
    double s = 0.0;
    for (size_t i = 0; i < n; i++) s += finite_or_zero(px(img, i, c0 + c));
    mean[c] = n ? s / (double)n : 0.0;
  }
}

void iris_metric_mean_standard_error(const iris_image *img, int v0, double se[3]) {
  size_t n = (size_t)img->width * (size_t)img->height;
  for (int c = 0; c < 3; c++) {
    double s = 0.0;
    for (size_t i = 0; i < n; i++) s += finite_or_zero(px(img, i, v0 + c));
    se[c] = n ? sqrt(s) / (double)n : 0.0;
  }
}

double iris_metric_energy_ratio(const double test_mean[3], const double ref_mean[3]) {
  double t = test_mean[0] + test_mean[1] + test_mean[2];
  double r = ref_mean[0] + ref_mean[1] + ref_mean[2];
  if (r == 0.0) return t == 0.0 ? 1.0 : INFINITY;
  return t / r;
}

static int compare_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Mean of the per-pixel errors after dropping the floor(drop * n) largest. */
static double mean_after_drop(double *e, size_t n, double drop_fraction) {
  if (n == 0) return 0.0;
  size_t drop = (size_t)floor(drop_fraction * (double)n);
  if (drop >= n) drop = n - 1;
  if (drop > 0) qsort(e, n, sizeof *e, compare_double);
  double s = 0.0;
  for (size_t i = 0; i < n - drop; i++) s += e[i];
  return s / (double)(n - drop);
}

static double per_pixel_error(const iris_image *test, int tc0, const iris_image *ref, int rc0,
                              double eps, double drop_fraction, bool squared) {
  size_t n = (size_t)ref->width * (size_t)ref->height;
  double *e = malloc(n ? n * sizeof *e : 1);
  if (!e) return NAN;
  for (size_t i = 0; i < n; i++) {
    double s = 0.0;
    for (int c = 0; c < 3; c++) {
      double t = px(test, i, tc0 + c), r = px(ref, i, rc0 + c);
      double d = t - r;
      s += squared ? d * d / (r * r + eps) : fabs(d) / (fabs(r) + eps);
    }
    /* A non-finite pixel is the largest error there is: it is dropped first
     * when dropping, and makes the metric Inf otherwise. */
    e[i] = isfinite(s) ? s / 3.0 : INFINITY;
  }
  double m = mean_after_drop(e, n, drop_fraction);
  free(e);
  return m;
}

double iris_metric_relmse(const iris_image *test, int tc0, const iris_image *ref, int rc0,
                          double eps, double drop_fraction) {
  return per_pixel_error(test, tc0, ref, rc0, eps, drop_fraction, true);
}

double iris_metric_mape(const iris_image *test, int tc0, const iris_image *ref, int rc0,
                        double eps, double drop_fraction) {
  return per_pixel_error(test, tc0, ref, rc0, eps, drop_fraction, false);
}

double iris_metric_normal_two_sided_p(double z) { return erfc(fabs(z) / sqrt(2.0)); }

double iris_metric_normal_two_sided_z(double p) {
  if (!(p > 0.0)) return INFINITY;
  if (p >= 1.0) return 0.0;
  double lo = 0.0, hi = 40.0; /* erfc(40 / sqrt 2) underflows to 0 */
  for (int i = 0; i < 200; i++) {
    double mid = 0.5 * (lo + hi);
    if (iris_metric_normal_two_sided_p(mid) > p)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

static bool same_size(const iris_image *a, const iris_image *b, iris_error *err) {
  if (a->width == b->width && a->height == b->height) return true;
  iris_error_set(err, IRIS_ERR_INVALID, NULL, 0, NULL,
                 "image sizes differ: %dx%d against a %dx%d reference", a->width, a->height,
                 b->width, b->height);
  return false;
}

/* Test variance of channel c at pixel i, raised to the reference-derived floor. */
static inline double test_var(const iris_image *ref, iris_ref_variance rv, double floor, double var_t,
                              size_t i, int c) {
  if (rv.rv0 >= 0 && floor > 0.0) {
    double f = floor * finite_or_zero(px(ref, i, rv.rv0 + c));
    if (f > var_t) return f;
  }
  return var_t;
}

/* Variance of the reference pixel value of channel c at pixel i. */
static inline double ref_var(const iris_image *ref, iris_ref_variance rv, double var_t, size_t i,
                             int c) {
  if (rv.rv0 >= 0) return finite_or_zero(px(ref, i, rv.rv0 + c));
  return rv.scale * var_t;
}

/* Float rounding: Cycles accumulates in float32, so two exact renderers
 * still differ by ~1e-6 relative; a variance estimate far below that (e.g. a
 * pixel of one emitter whose samples differ only in the last bits) must not
 * turn the rounding into a huge z. Added to every variance in the z-tests. */
static inline double rounding_variance(double t, double r) {
  double s = 1e-5 * (fabs(t) + fabs(r));
  return s * s;
}

/* Exact comparison for zero-variance values (e.g. an emitter seen directly). */
static inline bool nearly_equal(double t, double r) {
  return fabs(t - r) <= 1e-4 * fmax(fabs(t), fabs(r)) + 1e-7;
}

iris_status iris_metric_blocks(const iris_image *test, int tc0, int tv0, const iris_image *ref,
                               int rc0, iris_ref_variance rv, int block, double alpha,
                               iris_block_stats *out, iris_error *err) {
  return iris_metric_blocks_floored(test, tc0, tv0, ref, rc0, rv, 0.0, block, alpha, out, err);
}

iris_status iris_metric_blocks_floored(const iris_image *test, int tc0, int tv0,
                                       const iris_image *ref, int rc0, iris_ref_variance rv,
                                       double test_floor, int block, double alpha,
                                       iris_block_stats *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  if (!same_size(test, ref, err)) return IRIS_ERR_INVALID;
  if (block < 1) block = 1;
  int w = ref->width, h = ref->height;
  int tx = (w + block - 1) / block, ty = (h + block - 1) / block;
  size_t tiles = (size_t)tx * (size_t)ty;
  out->block = block;
  out->tiles_x = tx;
  out->tiles_y = ty;
  /* per tile: sums of t, r, var_t, var_r per channel (4 x 3 doubles) and pixel count */
  double *acc = calloc(tiles ? tiles * 12 : 1, sizeof *acc);
  if (!acc) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      size_t i = (size_t)y * (size_t)w + (size_t)x;
      double *a = acc + 12 * ((size_t)(y / block) * (size_t)tx + (size_t)(x / block));
      for (int c = 0; c < 3; c++) {
        a[c] += finite_or_zero(px(test, i, tc0 + c));
        a[3 + c] += finite_or_zero(px(ref, i, rc0 + c));
        if (rv.spread) {
          double d = finite_or_zero(px(test, i, tc0 + c)) - finite_or_zero(px(ref, i, rc0 + c));
          a[6 + c] += d * d;
        } else if (tv0 >= 0) {
          double vt = test_var(ref, rv, test_floor, finite_or_zero(px(test, i, tv0 + c)), i, c);
          a[6 + c] += vt;
          a[9 + c] += ref_var(ref, rv, vt, i, c);
        }
      }
    }
  double mean_energy = 0.0;
  for (size_t k = 0; k < tiles; k++) mean_energy += acc[12 * k + 3] + acc[12 * k + 4] + acc[12 * k + 5];
  mean_energy /= tiles ? (double)tiles : 1.0;
  double sum_sq = 0.0;
  for (size_t k = 0; k < tiles; k++) {
    const double *a = acc + 12 * k;
    double et = a[0] + a[1] + a[2], er = a[3] + a[4] + a[5];
    if (er <= IRIS_METRIC_BLOCK_FLOOR * mean_energy || er <= 0.0) continue;
    double d = (et - er) / er;
    out->compared++;
    sum_sq += d * d;
    if (fabs(d) > out->max_rel_dev) {
      out->max_rel_dev = fabs(d);
      out->signed_max_rel_dev = d;
      out->max_tile_x = (int)(k % (size_t)tx);
      out->max_tile_y = (int)(k / (size_t)tx);
    }
  }
  out->rms_rel_dev = out->compared ? sqrt(sum_sq / out->compared) : 0.0;
  if (tv0 >= 0 || rv.spread) {
    out->z_done = true;
    for (size_t k = 0; k < tiles; k++)
      for (int c = 0; c < 3; c++)
        if (acc[12 * k + 6 + c] + acc[12 * k + 9 + c] > 0.0) out->z_tests++;
    out->z_crit = iris_metric_normal_two_sided_z(alpha / (double)(out->z_tests ? out->z_tests : 1));
    for (size_t k = 0; k < tiles; k++) {
      const double *a = acc + 12 * k;
      for (int c = 0; c < 3; c++) {
        double v = a[6 + c] + a[9 + c]; /* n^2 cancels between numerator and denominator */
        if (v > 0.0) {
          double z = (a[c] - a[3 + c]) / sqrt(v + rounding_variance(a[c], a[3 + c]));
          if (fabs(z) > out->max_abs_z) out->max_abs_z = fabs(z);
          if (fabs(z) > out->z_crit) out->z_over++;
        } else {
          out->z_degenerate++;
          if (!nearly_equal(a[c], a[3 + c])) out->z_degenerate_fail++;
        }
      }
    }
    out->passed = out->z_over == 0;
  }
  free(acc);
  return IRIS_OK;
}

/* Test variance averaged over the 3x3 neighbourhood (edges clamped). A
 * pixel's own sample variance is correlated with its mean (skewed path
 * tracing samples: a pixel that missed the rare bright paths has both a low
 * mean and a low variance), which makes raw z-scores biased towards negative
 * values; the neighbours' variance is nearly independent of the pixel's mean
 * and the variance field is smooth (docs/validation.md, "Calibration"). */
static float *smoothed_variance(const iris_image *test, int tv0) {
  int w = test->width, h = test->height;
  float *out = malloc((size_t)w * (size_t)h * 3 * sizeof *out);
  if (!out) return NULL;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < 3; c++) {
        double s = 0.0;
        for (int dy = -1; dy <= 1; dy++)
          for (int dx = -1; dx <= 1; dx++) {
            int xx = x + dx < 0 ? 0 : x + dx >= w ? w - 1 : x + dx;
            int yy = y + dy < 0 ? 0 : y + dy >= h ? h - 1 : y + dy;
            s += finite_or_zero(px(test, (size_t)yy * (size_t)w + (size_t)xx, tv0 + c));
          }
        out[3 * ((size_t)y * (size_t)w + (size_t)x) + (size_t)c] = (float)(s / 9.0);
      }
  return out;
}

iris_status iris_metric_pixel_ztest(const iris_image *test, int tc0, int tv0,
                                    const iris_image *ref, int rc0, iris_ref_variance rv,
                                    double alpha, float *z_image, iris_pixel_ztest *out,
                                    iris_error *err) {
  return iris_metric_pixel_ztest_floored(test, tc0, tv0, ref, rc0, rv, 0.0, alpha, z_image, out, err);
}

iris_status iris_metric_pixel_ztest_floored(const iris_image *test, int tc0, int tv0,
                                            const iris_image *ref, int rc0, iris_ref_variance rv,
                                            double test_floor, double alpha, float *z_image,
                                            iris_pixel_ztest *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  if (!same_size(test, ref, err)) return IRIS_ERR_INVALID;
  size_t n = (size_t)ref->width * (size_t)ref->height;
  if (z_image) memset(z_image, 0, n * sizeof *z_image);
  out->count_threshold = IRIS_METRIC_Z_COUNT;
  if (tv0 < 0) return IRIS_OK;
  out->done = true;
  float *vs = smoothed_variance(test, tv0);
  if (!vs) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < 3; c++) {
      double vt = test_var(ref, rv, test_floor, vs[3 * i + (size_t)c], i, c);
      if (vt + ref_var(ref, rv, vt, i, c) > 0.0) out->tests++;
    }
  out->z_crit = iris_metric_normal_two_sided_z(alpha / (double)(out->tests ? out->tests : 1));
  for (size_t i = 0; i < n; i++) {
    float zmax = 0.0f;
    for (int c = 0; c < 3; c++) {
      double t = px(test, i, tc0 + c), r = px(ref, i, rc0 + c);
      double vt = test_var(ref, rv, test_floor, vs[3 * i + (size_t)c], i, c);
      double v = vt + ref_var(ref, rv, vt, i, c);
      double z;
      if (v > 0.0) {
        z = (t - r) / sqrt(v + rounding_variance(t, r));
      } else {
        /* Zero estimated variance does not mean zero variance (a pixel whose
         * samples all hit the same emitter): counted, not tested. */
        out->degenerate++;
        if (!nearly_equal(t, r)) out->degenerate_fail++;
        continue;
      }
      if (!isfinite(t) || !isfinite(r)) z = INFINITY;
      double az = fabs(z);
      if (az > out->max_abs_z) {
        out->max_abs_z = az;
        out->max_x = (int)(i % (size_t)ref->width);
        out->max_y = (int)(i / (size_t)ref->width);
        out->max_c = c;
      }
      if (az > out->z_crit) out->over_crit++;
      if (az > out->count_threshold) out->over_count++;
      if (fabs(z) > fabsf(zmax)) zmax = (float)z;
    }
    if (z_image) z_image[i] = zmax;
  }
  free(vs);
  double p = iris_metric_normal_two_sided_p(out->count_threshold);
  double nt = (double)out->tests;
  out->expected_over = nt * p;
  out->allowed_over = out->expected_over + iris_metric_normal_two_sided_z(alpha) * sqrt(nt * p * (1.0 - p));
  out->bonferroni_passed = out->over_crit == 0;
  out->count_passed = (double)out->over_count <= out->allowed_over;
  out->passed = out->bonferroni_passed && out->count_passed;
  return IRIS_OK;
}

/* The expected relMSE of an image against the exact one, from its variance
 * channels (var.R/G/B: variance of each pixel's mean): mean over pixels of
 * (1/3) sum_c var_c / (value_c^2 + eps). Every relMSE measured against a
 * reference contains about this much of the reference's own noise. -1 when
 * the image has no variance channels. */
double iris_metric_own_relmse(const iris_image *img) {
  static const char *const names[3] = {"R", "G", "B"}, *const vnames[3] = {"var.R", "var.G", "var.B"};
  int c0[3], v0[3];
  for (int c = 0; c < 3; c++) {
    c0[c] = iris_image_channel(img, names[c]);
    v0[c] = iris_image_channel(img, vnames[c]);
    if (c0[c] < 0 || v0[c] < 0) return -1.0;
  }
  size_t n = (size_t)img->width * (size_t)img->height;
  double sum = 0.0;
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < 3; c++) {
      double r = img->data[i * (size_t)img->channel_count + (size_t)c0[c]];
      double v = img->data[i * (size_t)img->channel_count + (size_t)v0[c]];
      if (isfinite(v) && v > 0.0) sum += v / (r * r + IRIS_METRIC_EPS) / 3.0;
    }
  return n ? sum / (double)n : -1.0;
}

