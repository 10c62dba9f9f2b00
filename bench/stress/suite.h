/* The failure-stability suite's measurements, shared by the full suite
 * (bench/stress/stress_suite.c, run by run_stress.sh) and the CI test
 * (tests/stress): render a stress scene with one method at equal time or
 * equal samples, and compare it with a reference through validate/metrics.h
 * (relMSE, largest pixel, NaN/Inf, mean-energy z-test, 8x8 block z-tests).
 * docs/stability.md gives every formula and the measured table. */
#ifndef IRIS_BENCH_STRESS_SUITE_H
#define IRIS_BENCH_STRESS_SUITE_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "core/image.h"
#include "renderer/integrator.h"
#include "scene/scene.h"
#include "validate/metrics.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_stress_params {
  int width, height; /* <= 0: the scene's */
  double seconds;    /* > 0: wall-clock budget INCLUDING setup (accel, lights, guide) */
  int spp;           /* samples per pixel when seconds <= 0 */
  uint64_t seed;
  int threads;       /* <= 0: all cores */
  int max_depth;     /* < 0: default */
  int64_t guide_photons; /* guided methods: photon paths (0: the guide's own choice) */
} iris_stress_params;

iris_stress_params iris_stress_params_default(void);

/* One render: the image (R, G, B, var.R, var.G, var.B; var = variance of the
 * pixel's mean) and what it cost. */
typedef struct iris_stress_render_out {
  iris_image image;
  int spp;
  double seconds;        /* setup + passes */
  double setup_seconds;
  uint64_t dropped;      /* samples the integrator rejected as NaN/Inf */
} iris_stress_render_out;

/* Renders `scene` with `method`. For a time budget every method first
 * renders once at 1 spp to measure its setup time (accel, lights, guide), which is then
 * taken from the budget, so every method gets the same wall-clock time
 * (except that a render gets at least 2 spp, even when the setup alone
 * fills the budget: a variance needs two samples). */
iris_status iris_stress_render(const iris_scene *scene, iris_method method,
                               const iris_stress_params *params, iris_stress_render_out *out,
                               iris_error *err);
void iris_stress_render_out_destroy(iris_stress_render_out *out);

/* A test image against a reference. */
typedef struct iris_stress_compare {
  double relmse;          /* eps 0.01, top 0.1% dropped (IRIS_METRIC_*) */
  double ref_relmse;      /* the reference's own expected relMSE (its variance / (ref^2+eps)):
                             the floor below which relMSE cannot be resolved */
  double max_value;       /* largest finite channel value */
  uint64_t nan_values, inf_values;
  double energy_test, energy_ref; /* mean of R+G+B over the image */
  double energy_ratio;    /* energy_test / energy_ref (1 when both are 0) */
  double energy_z;        /* (E_t - E_r) / sqrt(var E_t + var E_r) (0 when both variances are 0) */
  iris_block_stats blocks;   /* 8x8 tiles (IRIS_METRIC_BLOCK): reported */
  iris_block_stats regions;  /* region x region tiles: the unbiasedness gate with the energy test */
  iris_pixel_ztest pixels;   /* per pixel: reported */
  /* Region-channels beyond the regions' critical |z|, by sign: a render that
   * misses rare large samples is too DARK where it fails (low), while a single
   * rare sample that was drawn brings its own variance and rarely makes |z|
   * large; a bias can go either way. */
  int regions_low, regions_high;
  bool black_exact;       /* every value exactly 0 (meaningful for black references) */
} iris_stress_compare;

/* Edge of the coarse regions of the unbiasedness gate: 32 px, 4 x 3 regions
 * at 128 x 96. Per-pixel and 8x8 z-tests rely on each pixel's sample
 * variance, which at tens of samples per pixel misses the rare large samples
 * (a small light hit by a BSDF-sampled path) and so rejects an unbiased but
 * under-sampled render; summed over a region's ~1000 pixels the rare samples
 * do occur and the variance estimate holds (docs/stability.md, "Statistics"). */
#define IRIS_STRESS_REGION 32

/* Compares test (R, G, B at 0 and var at 3) with ref (same layout; when
 * `ref_exact`, its variance is taken as 0, e.g. the analytic black image).
 * `alpha` is the family-wise significance of each of the z-test families of
 * THIS comparison (the caller divides its level by the number of
 * comparisons); `region` is the gate's region edge (<= 0: IRIS_STRESS_REGION). */
iris_status iris_stress_compare_images(const iris_image *test, const iris_image *ref,
                                       bool ref_exact, double alpha, int region,
                                       iris_stress_compare *out, iris_error *err);
/* The unbiasedness gate: every channel's image mean and every region within
 * the Bonferroni bounds of `alpha` (as passed to the comparison). */
bool iris_stress_unbiased(const iris_stress_compare *c, double alpha);

/* Reads an EXR with R, G, B, var.R, var.G, var.B (in any order on disk) into
 * that channel order; *spp and *seconds from iris:spp / iris:render_seconds
 * (0 when absent; either may be NULL). */
iris_status iris_stress_image_read(const char *path, iris_image *out, int *spp, double *seconds,
                                   iris_error *err);
/* Writes such an image with scene/method/spp/seconds metadata and reads it
 * back: OpenEXRCore 3.1's ZIP encoder stores a chunk whose zlib output is
 * exactly as long as the raw data without marking it (OpenEXR issue #2306),
 * which the reader then takes as raw pixels; a stored reference must not be
 * silently wrong, so a file that does not read back bit for bit is an error. */
iris_status iris_stress_image_write(const char *path, const iris_image *img, const char *scene,
                                    const char *method, int spp, double seconds, iris_error *err);

/* Critical |z| of the energy test at level alpha (two-sided). */
double iris_stress_energy_zcrit(double alpha);

#ifdef __cplusplus
}
#endif
#endif
