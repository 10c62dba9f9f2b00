/* validate.correlated: the block z-test stays honest with the sobol sampler.
 * The samples of one pixel are correlated (a scrambled net), so the per-pixel
 * sample variance over-estimates the error of the mean; the block test that
 * gates `iris validate` therefore takes each tile's variance from the spread
 * of its pixel differences (metrics.h, iris_ref_variance.spread).
 *  - Unbiased: sobol images (4 seeds) against an independent-sampler
 *    reference: the tile z-scores have variance ~1 (0.75 .. 1.33 over ~3000
 *    tile-channels; a sample-variance z would be narrower, printed) and the
 *    fraction with |z| > 2.576 is near 1% (below 2.5%); the library's block
 *    test (8x8 tiles, as iris validate) passes at alpha 0.01.
 *  - Biased: the same images x 1.03 fail the library's block test. (A
 *    self-normalised tile z is bounded by sqrt(pixels per tile): 8 for the
 *    8x8 tiles, above the Bonferroni threshold; 4x4 tiles could never fail.) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "render_run.h"
#include "renderer/render.h"
#include "scenes/builtin.h"
#include "validate/metrics.h"

#define W 64
#define H 64
#define B 4

static bool render(const iris_scene *s, iris_sampler_kind k, int spp, uint64_t seed, iris_image *out) {
  iris_render_params p = iris_test_params(W, H, spp, IRIS_METHOD_MIS, seed);
  p.sampler = k;
  return iris_test_render_image(s, &p, true, out);
}

int main(void) {
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  if (!CHECK(iris_builtin_create("cornell-box", &s, &err) == IRIS_OK)) return iris_check_summary("validate.correlated");
  iris_image ref;
  if (!CHECK(render(s, IRIS_SAMPLER_INDEPENDENT, 1024, 1000, &ref))) return iris_check_summary("validate.correlated");
  double sz = 0, sz2 = 0, so = 0, so2 = 0;
  long n = 0, over = 0;
  for (uint64_t seed = 1; seed <= 4; seed++) {
    iris_image img;
    if (!CHECK(render(s, IRIS_SAMPLER_SOBOL, 64, seed, &img))) continue;
    /* tile z-scores by both variance estimates */
    for (int ty = 0; ty < H / B; ty++)
      for (int tx = 0; tx < W / B; tx++)
        for (int c = 0; c < 3; c++) {
          double d = 0, d2 = 0, v = 0;
          for (int y = ty * B; y < (ty + 1) * B; y++)
            for (int x = tx * B; x < (tx + 1) * B; x++) {
              size_t i = (size_t)y * W + (size_t)x;
              double t = img.data[i * 6 + (size_t)c], r = ref.data[i * 6 + (size_t)c];
              d += t - r;
              d2 += (t - r) * (t - r);
              v += img.data[i * 6 + 3 + (size_t)c] + ref.data[i * 6 + 3 + (size_t)c];
            }
          if (!(d2 > 0) || !(v > 0)) continue;
          double z = d / sqrt(d2), zo = d / sqrt(v);
          sz += z, sz2 += z * z, so += zo, so2 += zo * zo;
          over += fabs(z) > 2.576;
          n++;
        }
    iris_ref_variance rv = {3, 0.0, true};
    iris_block_stats bs;
    CHECK(iris_metric_blocks(&img, 0, 3, &ref, 0, rv, IRIS_METRIC_BLOCK, 0.01, &bs, &err) == IRIS_OK);
    iris_check_record(bs.passed, __FILE__, __LINE__, "seed %llu: unbiased image fails the spread block test (max |z| %.2f > %.2f)",
                      (unsigned long long)seed, bs.max_abs_z, bs.z_crit);
    /* a 3% bias must fail it */
    for (size_t i = 0; i < (size_t)W * H; i++)
      for (int c = 0; c < 3; c++) img.data[i * 6 + (size_t)c] *= 1.03f;
    CHECK(iris_metric_blocks(&img, 0, 3, &ref, 0, rv, IRIS_METRIC_BLOCK, 0.01, &bs, &err) == IRIS_OK);
    iris_check_record(!bs.passed, __FILE__, __LINE__, "seed %llu: a 3%% bias passes the spread block test (max |z| %.2f)",
                      (unsigned long long)seed, bs.max_abs_z);
    printf("seed %llu: biased image max |z| %.2f (critical %.2f)\n", (unsigned long long)seed, bs.max_abs_z, bs.z_crit);
    iris_image_destroy(&img);
  }
  double mz = sz / n, vz = sz2 / n - mz * mz, mo = so / n, vo = so2 / n - mo * mo;
  printf("%ld tile-channels: spread z mean %.3f var %.3f, |z|>2.576 %.2f%%; variance-channel z var %.3f\n", n, mz, vz,
         100.0 * over / n, vo);
  iris_check_record(n > 2000, __FILE__, __LINE__, "only %ld tile-channels", n);
  iris_check_record(vz > 0.75 && vz < 1.33, __FILE__, __LINE__, "spread z variance %.3f is not ~1", vz);
  iris_check_record((double)over / n < 0.025, __FILE__, __LINE__, "%.2f%% of |z| > 2.576", 100.0 * over / n);
  iris_image_destroy(&ref);
  iris_scene_destroy(s);
  return iris_check_summary("validate.correlated");
}
