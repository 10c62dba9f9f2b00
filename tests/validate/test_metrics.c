/* validate.metrics: every metric of validate/metrics.h against values worked
 * out by hand (in the comments), and the z-tests' calibration on synthetic
 * Gaussian images whose true variance is known. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/image.h"
#include "core/rng.h"
#include "validate/metrics.h"

static const char *const NAMES6[6] = {"R", "G", "B", "var.R", "var.G", "var.B"};

static void make(iris_image *img, int w, int h, int channels) {
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_image_create(img, w, h, channels, NAMES6, &err), &err);
}

static float *at(iris_image *img, int x, int y) {
  return img->data + ((size_t)y * (size_t)img->width + (size_t)x) * (size_t)img->channel_count;
}

static void set_rgb(iris_image *img, int x, int y, float r, float g, float b) {
  float *p = at(img, x, y);
  p[0] = r;
  p[1] = g;
  p[2] = b;
}

static void test_means_and_counts(void) {
  iris_image a;
  make(&a, 2, 2, 3);
  set_rgb(&a, 0, 0, 1, 2, 3);
  set_rgb(&a, 1, 0, 3, 2, 1);
  set_rgb(&a, 0, 1, 0, 0, 0);
  set_rgb(&a, 1, 1, 4, 0, NAN);
  double m[3];
  iris_metric_channel_means(&a, 0, m);
  /* R: (1+3+0+4)/4 = 2; G: 4/4 = 1; B: (3+1+0+[NaN->0])/4 = 1 */
  CHECK_NEAR(m[0], 2.0, 1e-12);
  CHECK_NEAR(m[1], 1.0, 1e-12);
  CHECK_NEAR(m[2], 1.0, 1e-12);
  uint64_t nans, infs;
  iris_metric_count_nonfinite(&a, 0, 3, &nans, &infs);
  CHECK_EQ_INT((int)nans, 1);
  CHECK_EQ_INT((int)infs, 0);
  at(&a, 0, 1)[1] = INFINITY;
  at(&a, 0, 1)[2] = -INFINITY;
  iris_metric_count_nonfinite(&a, 0, 3, &nans, &infs);
  CHECK_EQ_INT((int)infs, 2);
  iris_image_destroy(&a);

  double t[3] = {1.0, 2.0, 3.0}, r[3] = {2.0, 2.0, 2.0};
  CHECK_NEAR(iris_metric_energy_ratio(t, r), 1.0, 1e-15); /* 6 / 6 */
  double t2[3] = {1.05, 0.0, 0.0}, r2[3] = {1.0, 0.0, 0.0};
  CHECK_NEAR(iris_metric_energy_ratio(t2, r2), 1.05, 1e-12);
  double z[3] = {0, 0, 0};
  CHECK(isinf(iris_metric_energy_ratio(t2, z)));
  CHECK_NEAR(iris_metric_energy_ratio(z, z), 1.0, 0.0);
}

static void test_relmse_mape(void) {
  /* Four grey pixels; the reference is 1 everywhere. Per-pixel errors with
   * eps = 0.01 (every channel equal, so the channel average is that value):
   *   t = 1.1: relMSE 0.01 / 1.01,  MAPE 0.1 / 1.01
   *   t = 0.8: relMSE 0.04 / 1.01,  MAPE 0.2 / 1.01
   *   t = 1.0: 0, 0
   *   t = 3.0: relMSE 4 / 1.01,     MAPE 2 / 1.01                              */
  iris_image t, r;
  make(&t, 2, 2, 3);
  make(&r, 2, 2, 3);
  const float v[4] = {1.1f, 0.8f, 1.0f, 3.0f};
  for (int i = 0; i < 4; i++) {
    set_rgb(&t, i % 2, i / 2, v[i], v[i], v[i]);
    set_rgb(&r, i % 2, i / 2, 1, 1, 1);
  }
  double d0 = 0.1 * 0.1, d1 = 0.2 * 0.2; /* float 1.1f and 0.8f differ from 1.1/0.8 by < 1e-7 */
  CHECK_NEAR(iris_metric_relmse(&t, 0, &r, 0, 0.01, 0.0), (d0 + d1 + 0 + 4.0) / 1.01 / 4.0, 1e-6);
  CHECK_NEAR(iris_metric_mape(&t, 0, &r, 0, 0.01, 0.0), (0.1 + 0.2 + 0 + 2.0) / 1.01 / 4.0, 1e-6);
  /* drop 25%: floor(0.25 * 4) = 1 pixel, the t = 3 one; mean of the other three */
  CHECK_NEAR(iris_metric_relmse(&t, 0, &r, 0, 0.01, 0.25), (d0 + d1) / 1.01 / 3.0, 1e-6);
  CHECK_NEAR(iris_metric_mape(&t, 0, &r, 0, 0.01, 0.25), (0.1 + 0.2) / 1.01 / 3.0, 1e-6);
  /* drop 0.1% of 4 pixels = 0 pixels */
  CHECK_NEAR(iris_metric_relmse(&t, 0, &r, 0, 0.01, 0.001), (d0 + d1 + 4.0) / 1.01 / 4.0, 1e-6);
  /* a colour pixel: t = (2, 0, 0) against r = (1, 0, 0), eps 0.01:
   * (1/3) (1 / 1.01 + 0 + 0) */
  iris_image a, b;
  make(&a, 1, 1, 3);
  make(&b, 1, 1, 3);
  set_rgb(&a, 0, 0, 2, 0, 0);
  set_rgb(&b, 0, 0, 1, 0, 0);
  CHECK_NEAR(iris_metric_relmse(&a, 0, &b, 0, 0.01, 0.001), 1.0 / 1.01 / 3.0, 1e-9);
  /* and with G = 0.1 in the test only: + 0.01 / (0 + 0.01) = 1 */
  set_rgb(&a, 0, 0, 2, 0.1f, 0);
  CHECK_NEAR(iris_metric_relmse(&a, 0, &b, 0, 0.01, 0.0), (1.0 / 1.01 + 1.0) / 3.0, 1e-6);
  /* a NaN pixel makes the undropped metric infinite */
  set_rgb(&t, 0, 0, NAN, 1, 1);
  CHECK(isinf(iris_metric_relmse(&t, 0, &r, 0, 0.01, 0.0)));
  iris_image_destroy(&a);
  iris_image_destroy(&b);
  iris_image_destroy(&t);
  iris_image_destroy(&r);
}

static void test_normal(void) {
  CHECK_NEAR(iris_metric_normal_two_sided_p(1.959963984540054), 0.05, 1e-12);
  CHECK_NEAR(iris_metric_normal_two_sided_p(-3.0), 0.0026997960632601866, 1e-14);
  CHECK_NEAR(iris_metric_normal_two_sided_z(0.05), 1.959963984540054, 1e-9);
  CHECK_NEAR(iris_metric_normal_two_sided_z(0.01), 2.5758293035489004, 1e-9);
  /* Bonferroni for 0.01 / 1e6 tests: z with P(|Z| > z) = 1e-8 is 5.730729 */
  CHECK_NEAR(iris_metric_normal_two_sided_z(1e-8), 5.7307288, 1e-5);
}

static void test_blocks(void) {
  iris_error err;
  iris_error_clear(&err);
  /* 16 x 12 image, 8 x 8 tiles: 2 x 2 tiles, the bottom ones 8 x 4 pixels. */
  iris_image t, r;
  make(&t, 16, 12, 6);
  make(&r, 16, 12, 3);
  for (int y = 0; y < 12; y++)
    for (int x = 0; x < 16; x++) {
      set_rgb(&r, x, y, 1, 1, 1);
      set_rgb(&t, x, y, 1, 1, 1);
      float *p = at(&t, x, y);
      p[3] = p[4] = p[5] = 0.01f; /* variance of each pixel mean */
    }
  /* bottom-right tile (8 x 4 = 32 pixels): R raised by 0.1 in 16 of its pixels */
  for (int y = 8; y < 12; y++)
    for (int x = 8; x < 12; x++) at(&t, x, y)[0] = 1.1f;
  iris_ref_variance exact = {-1, 0.0, false};
  iris_block_stats bs;
  CHECK_OK(iris_metric_blocks(&t, 0, 3, &r, 0, exact, 8, 0.01, &bs, &err), &err);
  CHECK_EQ_INT(bs.tiles_x, 2);
  CHECK_EQ_INT(bs.tiles_y, 2);
  CHECK_EQ_INT(bs.compared, 4);
  /* energy: reference 32 px x 3 = 96, test 96 + 16 x 0.1 = 97.6 -> +1/60 */
  CHECK_NEAR(bs.max_rel_dev, 1.6 / 96.0, 1e-6);
  CHECK_NEAR(bs.signed_max_rel_dev, 1.6 / 96.0, 1e-6);
  CHECK_EQ_INT(bs.max_tile_x, 1);
  CHECK_EQ_INT(bs.max_tile_y, 1);
  /* z of that tile's R: 1.6 / sqrt(32 x 0.01) = 2.8284 (rounding variance
   * (1e-5 x 65.6)^2 is negligible); 12 tile-channels tested, crit for
   * 0.01 / 12 = 3.3439 */
  CHECK_EQ_INT((int)bs.z_tests, 12);
  CHECK_NEAR(bs.max_abs_z, 1.6 / sqrt(0.32), 1e-4);
  CHECK_NEAR(bs.z_crit, iris_metric_normal_two_sided_z(0.01 / 12.0), 1e-9);
  CHECK(bs.passed);
  /* raise it to 0.2 in those 16 pixels: z = 3.2 / sqrt(0.32) = 5.66 > crit */
  for (int y = 8; y < 12; y++)
    for (int x = 8; x < 12; x++) at(&t, x, y)[0] = 1.2f;
  CHECK_OK(iris_metric_blocks(&t, 0, 3, &r, 0, exact, 8, 0.01, &bs, &err), &err);
  CHECK(!bs.passed);
  CHECK_EQ_INT((int)bs.z_over, 1);
  /* the reference's variance as a scale of the test's (x 3): z = 3.2 / sqrt(4 x 0.32) = 2.83 */
  iris_ref_variance scaled = {-1, 3.0, false};
  CHECK_OK(iris_metric_blocks(&t, 0, 3, &r, 0, scaled, 8, 0.01, &bs, &err), &err);
  CHECK_NEAR(bs.max_abs_z, 3.2 / sqrt(4 * 0.32), 1e-4);
  CHECK(bs.passed);
  /* reference variance channels with a floor for the test's: a 1 x 1 image,
   * test 1.3 with estimated variance 0 (it missed the rare paths), reference
   * 1.0 with variance 0.001 at 16x the test's spp: var_t = 16 x 0.001, so
   * z = 0.3 / sqrt(0.016 + 0.001) = 2.3009 */
  {
    iris_image t1, r1;
    make(&t1, 1, 1, 6);
    make(&r1, 1, 1, 6);
    set_rgb(&t1, 0, 0, 1.3f, 1.3f, 1.3f);
    set_rgb(&r1, 0, 0, 1, 1, 1);
    for (int c = 3; c < 6; c++) r1.data[c] = 0.001f;
    iris_ref_variance with_var = {3, 0.0, false};
    CHECK_OK(iris_metric_blocks_floored(&t1, 0, 3, &r1, 0, with_var, 16.0, 8, 0.01, &bs, &err), &err);
    CHECK_NEAR(bs.max_abs_z, 0.3 / sqrt(0.017), 1e-4);
    iris_pixel_ztest p1;
    CHECK_OK(iris_metric_pixel_ztest_floored(&t1, 0, 3, &r1, 0, with_var, 16.0, 0.01, NULL, &p1, &err), &err);
    CHECK_NEAR(p1.max_abs_z, 0.3 / sqrt(0.017), 1e-4);
    /* without the floor only the reference's variance counts: 0.3 / sqrt(0.001) */
    
    CHECK_OK(iris_metric_blocks(&t1, 0, 3, &r1, 0, with_var, 8, 0.01, &bs, &err), &err);
    CHECK_NEAR(bs.max_abs_z, 0.3 / sqrt(0.001), 1e-3);
    iris_image_destroy(&t1);
    iris_image_destroy(&r1);
  }
  /* different sizes are an error */
  iris_image small;
  make(&small, 8, 8, 3);
  CHECK(iris_metric_blocks(&t, 0, 3, &small, 0, exact, 8, 0.01, &bs, NULL) == IRIS_ERR_INVALID);
  iris_pixel_ztest pz;
  CHECK(iris_metric_pixel_ztest(&t, 0, 3, &small, 0, exact, 0.01, NULL, &pz, NULL) == IRIS_ERR_INVALID);
  iris_image_destroy(&small);
  iris_image_destroy(&t);
  iris_image_destroy(&r);
}

/* Standard normal variate from the project's hash (Box-Muller). */
static double gauss(uint64_t seed, uint64_t i) {
  double u1 = ((double)(iris_hash4(seed, i, 1, 0) >> 11) + 0.5) * 0x1p-53;
  double u2 = ((double)(iris_hash4(seed, i, 2, 0) >> 11) + 0.5) * 0x1p-53;
  return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

static void test_pixel_ztest(void) {
  iris_error err;
  iris_error_clear(&err);
  /* A hand case: one pixel, var 0.04 everywhere (3x3 mean of a constant is
   * the constant), exact reference: z = (1.5 - 1) / 0.2 = 2.5 */
  iris_image t, r;
  make(&t, 3, 3, 6);
  make(&r, 3, 3, 3);
  for (int y = 0; y < 3; y++)
    for (int x = 0; x < 3; x++) {
      set_rgb(&t, x, y, 1, 1, 1);
      set_rgb(&r, x, y, 1, 1, 1);
      float *p = at(&t, x, y);
      p[3] = p[4] = p[5] = 0.04f;
    }
  at(&t, 1, 1)[1] = 1.5f;
  iris_ref_variance exact = {-1, 0.0, false};
  iris_pixel_ztest pz;
  float zimg[9];
  CHECK_OK(iris_metric_pixel_ztest(&t, 0, 3, &r, 0, exact, 0.01, zimg, &pz, &err), &err);
  CHECK_EQ_INT((int)pz.tests, 27);
  CHECK_NEAR(pz.max_abs_z, 2.5, 1e-4);
  CHECK_EQ_INT(pz.max_x, 1);
  CHECK_EQ_INT(pz.max_y, 1);
  CHECK_EQ_INT(pz.max_c, 1);
  CHECK_NEAR(zimg[4], 2.5, 1e-4);
  CHECK_NEAR(zimg[0], 0.0, 0.0);
  /* zero variance: not tested, but a difference is reported */
  for (int i = 0; i < 9; i++) t.data[6 * i + 3] = 0.0f;
  at(&t, 0, 0)[0] = 2.0f;
  CHECK_OK(iris_metric_pixel_ztest(&t, 0, 3, &r, 0, exact, 0.01, NULL, &pz, &err), &err);
  CHECK_EQ_INT((int)pz.degenerate, 9);
  CHECK_EQ_INT((int)pz.degenerate_fail, 1);
  CHECK_EQ_INT((int)pz.tests, 18);
  iris_image_destroy(&t);
  iris_image_destroy(&r);

  /* Calibration: 256 x 256 pixels of N(mu, sigma^2) with the true variance in
   * the var channels, against an exact reference mu. Unbiased: both tests
   * pass (the count of |z| > 3 is Binomial(196608, 0.0027), mean 531, sd 23).
   * A bias of 0.3 sigma raises P(|z| > 3) to P(Z > 2.7) + P(Z < -3.3) =
   * 0.003467 + 0.000483 = 0.00395 (777 expected, +10 sd): the count test
   * catches it although no single pixel stands out. */
  int w = 256, h = 256;
  make(&t, w, h, 6);
  make(&r, w, h, 3);
  for (int pass = 0; pass < 2; pass++) {
    double bias = pass == 0 ? 0.0 : 0.3;
    /* sigma differs per channel but not between neighbours (the test
     * smooths the variance over 3x3 pixels) */
    for (int i = 0; i < w * h; i++)
      for (int c = 0; c < 3; c++) {
        double mu = 0.5 + 0.25 * c, sigma = 0.05 * (1 + c);
        r.data[3 * i + c] = (float)mu;
        t.data[6 * i + c] = (float)(mu + sigma * (gauss(42, (uint64_t)(3 * i + c)) + bias));
        t.data[6 * i + 3 + c] = (float)(sigma * sigma);
      }
    CHECK_OK(iris_metric_pixel_ztest(&t, 0, 3, &r, 0, exact, 0.01, NULL, &pz, &err), &err);
    CHECK_EQ_INT((int)pz.tests, w * h * 3);
    CHECK_NEAR(pz.expected_over, w * h * 3 * 0.0026997960632601866, 1e-6);
    if (pass == 0) {
      CHECK(pz.bonferroni_passed);
      CHECK(pz.count_passed);
      CHECK(fabs((double)pz.over_count - pz.expected_over) < 4.0 * sqrt(pz.expected_over));
    } else {
      if (!iris_check_record(!pz.count_passed, __FILE__, __LINE__, "biased count %llu, expected %.1f, allowed %.1f",
                             (unsigned long long)pz.over_count, pz.expected_over, pz.allowed_over)) {}
    }
  }
  /* a single pixel 7 sigma off: Bonferroni fails (crit 5.46 for 196608 tests) */
  for (int i = 0; i < w * h; i++)
    for (int c = 0; c < 3; c++) t.data[6 * i + c] = r.data[3 * i + c];
  t.data[6 * 1000] += 7.0f * sqrtf(t.data[6 * 1000 + 3]);
  CHECK_OK(iris_metric_pixel_ztest(&t, 0, 3, &r, 0, exact, 0.01, NULL, &pz, &err), &err);
  CHECK(!pz.bonferroni_passed);
  CHECK_EQ_INT((int)pz.over_crit, 1);
  CHECK_NEAR(pz.max_abs_z, 7.0, 1e-3);
  iris_image_destroy(&t);
  iris_image_destroy(&r);
}

int main(void) {
  test_means_and_counts();
  test_relmse_mape();
  test_normal();
  test_blocks();
  test_pixel_ztest();
  return TEST_SUMMARY();
}
