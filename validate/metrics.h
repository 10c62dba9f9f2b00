/* Image metrics for comparing a render with a reference: mean energy per
 * channel, relMSE and MAPE (with eps and a dropped top fraction, as the
 * path-guiding literature reports them), energy per block, and z-tests that use
 * the render's per-pixel variance of the mean. Shared by `iris validate` and
 * `iris bench`; every formula is written out in docs/validation.md.
 *
 * Images are iris_image; an RGB triple is named by the index c0 of its first
 * channel (R at c0, G at c0+1, B at c0+2). Variance channels (var.R/G/B, the
 * variance of each pixel's MEAN) likewise, with -1 for "none". */
#ifndef IRIS_VALIDATE_METRICS_H
#define IRIS_VALIDATE_METRICS_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "core/image.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_METRIC_EPS 0.01          /* relMSE / MAPE denominator offset */
#define IRIS_METRIC_DROP 0.001        /* fraction of largest per-pixel errors dropped */
#define IRIS_METRIC_BLOCK 8           /* block edge in pixels */
#define IRIS_METRIC_ALPHA 0.01        /* family-wise significance of the z-tests */
#define IRIS_METRIC_Z_COUNT 3.0       /* |z| threshold of the count test */
#define IRIS_METRIC_BLOCK_FLOOR 0.01  /* blocks darker than this x mean block energy are not
                                         ranked by relative deviation */

/* NaN and +-Inf values among `channels` channels starting at c0. */
void iris_metric_count_nonfinite(const iris_image *img, int c0, int channels, uint64_t *nan_count,
                                 uint64_t *inf_count);

/* Mean of each of the three channels over all pixels (non-finite values count
 * as 0 so that the mean stays finite; count them separately). */
void iris_metric_channel_means(const iris_image *img, int c0, double mean[3]);

/* Standard error of each channel's image mean from per-pixel variances of
 * the mean (pixels independent): sqrt(sum_i var_i) / n. */
void iris_metric_mean_standard_error(const iris_image *img, int v0, double se[3]);

/* Ratio of the summed channel means: (mt_R + mt_G + mt_B) / (mr_R + mr_G + mr_B);
 * 1 when both are 0, +Inf when only the reference is 0. */
double iris_metric_energy_ratio(const double test_mean[3], const double ref_mean[3]);

/* relMSE = mean over kept pixels of (1/3) sum_c (t_c - r_c)^2 / (r_c^2 + eps),
 * after dropping the floor(drop * pixels) pixels with the largest error.
 * Images must have the same size (the caller checks). */
double iris_metric_relmse(const iris_image *test, int tc0, const iris_image *ref, int rc0,
                          double eps, double drop_fraction);
/* MAPE = mean over kept pixels of (1/3) sum_c |t_c - r_c| / (|r_c| + eps), same dropping. */
double iris_metric_mape(const iris_image *test, int tc0, const iris_image *ref, int rc0,
                        double eps, double drop_fraction);

/* The expected relMSE of an image against the exact one, from its variance
 * channels var.R/G/B (variance of each pixel's mean): mean over pixels of
 * (1/3) sum_c var_c / (value_c^2 + IRIS_METRIC_EPS). A relMSE measured
 * against a reference contains about this much of the reference's own noise.
 * -1 when the image has no variance channels. */
double iris_metric_own_relmse(const iris_image *img);

/* Upper tail probability of |Z| for a standard normal Z: P(|Z| > z) = erfc(z / sqrt 2). */
double iris_metric_normal_two_sided_p(double z);
/* The z with P(|Z| > z) = p (0 < p < 1), by bisection on erfc. */
double iris_metric_normal_two_sided_z(double p);

/* Where the reference's per-pixel variance comes from in the z-tests. */
typedef struct iris_ref_variance {
  int rv0;      /* variance channels of the reference image, or -1 */
  double scale; /* when rv0 < 0: var_ref = scale * var_test (e.g. test_spp / ref_spp,
                   assuming the same per-sample variance); 0: the reference is exact */
  /* Block test only: estimate the variance of a tile's summed difference
   * from the spread of its pixel differences, sum_i (t_i - r_i)^2, instead
   * of the variance channels. That needs the pixels' errors to be independent
   * and zero-mean under the hypothesis, not the samples within a pixel, so it
   * stays honest for correlated (low-discrepancy) samples, whose per-pixel
   * sample variance over-estimates the error (docs/validation.md, "Correlated
   * samples"). */
  bool spread;
} iris_ref_variance;

/* Optional floor for the test's variance in the z-tests (the _floored
 * variants): when rv.rv0 >= 0 and test_floor > 0, var_test is raised to at
 * least test_floor * var_ref, with test_floor = ref_spp / test_spp. At low spp
 * a test pixel that missed a rare bright path (an emitter edge covering 1% of
 * it) estimates its variance as 0; the reference's per-sample variance,
 * estimated from many more samples, corrects that. 0: no floor. */

/* Energy (sum of R+G+B) per block x block tile (edge tiles may be smaller),
 * the relative deviation (E_t - E_r) / E_r of tiles brighter than
 * IRIS_METRIC_BLOCK_FLOOR x the mean tile energy, and a per-tile, per-channel
 * z-test z = (mean_t - mean_r) / sqrt(sum var_t / n^2 + sum var_r / n^2)
 * (pixels are independent) with Bonferroni correction over all tile-channels. */
typedef struct iris_block_stats {
  int block;                   /* tile edge */
  int tiles_x, tiles_y;
  int compared;                /* tiles ranked by relative deviation */
  double max_rel_dev;          /* largest |E_t - E_r| / E_r */
  double signed_max_rel_dev;   /* the same with its sign */
  int max_tile_x, max_tile_y;  /* that tile */
  double rms_rel_dev;
  bool z_done;                 /* false when the test image has no variance */
  uint64_t z_tests;            /* tile-channels with a positive variance */
  uint64_t z_degenerate;       /* tile-channels with zero variance: compared exactly */
  uint64_t z_degenerate_fail;  /* of those, differing by more than 1e-4 relative (reported,
                                  not failed: a zero variance estimate is not zero variance) */
  double max_abs_z;
  double z_crit;               /* Bonferroni: P(|Z| > z_crit) = alpha / z_tests */
  uint64_t z_over;             /* tile-channels with |z| > z_crit */
  bool passed;                 /* z_done && z_over == 0 */
} iris_block_stats;

iris_status iris_metric_blocks(const iris_image *test, int tc0, int tv0, const iris_image *ref,
                               int rc0, iris_ref_variance rv, int block, double alpha,
                               iris_block_stats *out, iris_error *err);
iris_status iris_metric_blocks_floored(const iris_image *test, int tc0, int tv0,
                                       const iris_image *ref, int rc0, iris_ref_variance rv,
                                       double test_floor, int block, double alpha,
                                       iris_block_stats *out, iris_error *err);

/* Per-pixel, per-channel z = (t - r) / sqrt(var_t + var_r), with var_t the
 * test variance averaged over the pixel's 3x3 neighbourhood (see metrics.c,
 * smoothed_variance). Two corrections
 * for the many tests, both at family-wise level alpha:
 *  - Bonferroni: no |z| may exceed z_crit with P(|Z| > z_crit) = alpha / tests;
 *  - count: the number of |z| > IRIS_METRIC_Z_COUNT may not exceed its
 *    binomial expectation n p by more than z_crit(alpha) standard deviations
 *    (normal approximation) -- this catches a small bias spread over many
 *    pixels, which no single pixel reveals.
 * Values whose both variances are 0 are not tested (a zero variance ESTIMATE,
 * e.g. all samples on one emitter, is not a zero variance); they are counted
 * and those differing by over 1e-4 relative are reported. */
/* At low spp the skew of path-tracing samples makes these tests reject even
 * an unbiased render now and then (docs/validation.md, "Calibration"); the
 * validator therefore gates on the block test and reports this one unless
 * asked to gate on it too. */
typedef struct iris_pixel_ztest {
  bool done;                   /* false when the test image has no variance */
  uint64_t tests;
  uint64_t degenerate, degenerate_fail;
  double max_abs_z;
  int max_x, max_y, max_c;
  double z_crit;               /* Bonferroni */
  uint64_t over_crit;
  double count_threshold;      /* IRIS_METRIC_Z_COUNT */
  uint64_t over_count;         /* |z| > count_threshold */
  double expected_over;        /* tests x P(|Z| > count_threshold) */
  double allowed_over;         /* expected + z(alpha) sqrt(n p (1 - p)) */
  bool bonferroni_passed, count_passed;
  bool passed;                 /* both */
} iris_pixel_ztest;

/* z_image (may be NULL): width x height floats, the channel z of largest
 * magnitude per pixel (0 where untested), for the false-colour image. */
iris_status iris_metric_pixel_ztest(const iris_image *test, int tc0, int tv0,
                                    const iris_image *ref, int rc0, iris_ref_variance rv,
                                    double alpha, float *z_image, iris_pixel_ztest *out,
                                    iris_error *err);
iris_status iris_metric_pixel_ztest_floored(const iris_image *test, int tc0, int tv0,
                                            const iris_image *ref, int rc0, iris_ref_variance rv,
                                            double test_floor, double alpha, float *z_image,
                                            iris_pixel_ztest *out, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
